#include "cli/study_inputs.hpp"

#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/transfer_set.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy::cli {

// Every character the protocol names is looked up (read and modelled) before any folder is made or trial
// run: one the library lacks is a ProtocolError (a usage error) naming the protocol file, the string's JSON
// pointer and the character, not a failure in the middle of a study; a library that cannot be read is a
// DataError naming the same.
void require_characters(const LoadedProtocol& loaded, const CharacterSource& source) {
  std::set<char32_t> checked;
  const auto check = [&](const std::vector<std::u32string>& items, const std::string& pointer) {
    for (std::size_t i = 0; i < items.size(); ++i) {
      for (const char32_t c : items[i]) {
        if (!checked.insert(c).second) continue;
        try {
          (void)source.load(c);
        } catch (const Error& e) {
          char code[16];
          std::snprintf(code, sizeof code, "U+%04X", static_cast<unsigned>(c));
          const std::string message = loaded.path.string() + ": " + pointer + "/" + std::to_string(i) +
                                      ": the character " + encode_utf8(c) + " (" + code +
                                      ") cannot be written: " + e.what() + "; nothing was run or written";
          if (dynamic_cast<const CharacterNotFound*>(&e) != nullptr) throw ProtocolError(message);
          throw DataError(message);
        }
      }
    }
  };
  const StudyProtocol& protocol = loaded.protocol;
  // A phase's sets' items are named where the set lists them.
  for (std::size_t i = 0; i < protocol.item_sets.size(); ++i) {
    check(protocol.item_sets[i].items, "/item_sets/" + std::to_string(i) + "/characters");
  }
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.choice) {
      check(phase.choice->candidates, phase.pointer + "/characters/from");
    } else if (phase.sets.empty()) {
      check(phase.items, phase.pointer + "/characters");
    }
  }
}

LoadedProtocol resolved_protocol(const LoadedProtocol& loaded, const CharacterSource& source) {
  LoadedProtocol resolved = loaded;
  try {
    resolve_transfer_choices(resolved.protocol, [&source](char32_t c) { return source.load(c); });
  } catch (const InvalidArgument& e) {  // the protocol's transfer choice cannot be made: its content
    throw ProtocolError(loaded.path.string() + ": " + e.what());
  }
  return resolved;
}

}  // namespace calligraphy::cli
