#pragma once
// A study protocol checked against the character source before anything runs or is written: every
// character it names can be written, and its transfer choices are made (once, the same for every subject).
#include "calligraphy/study/protocol.hpp"
#include "cli/library_options.hpp"

namespace calligraphy::cli {

/// Every character the protocol names is looked up (read and modelled): one the library lacks is a
/// DataError naming the protocol file, the string's JSON pointer and the character.
void require_characters(const LoadedProtocol& loaded, const CharacterSource& source);

/// `loaded` with its transfer choices resolved (`resolve_transfer_choices`) from `source`; a choice that
/// cannot be made is a DataError naming the protocol file.
[[nodiscard]] LoadedProtocol resolved_protocol(const LoadedProtocol& loaded, const CharacterSource& source);

}  // namespace calligraphy::cli
