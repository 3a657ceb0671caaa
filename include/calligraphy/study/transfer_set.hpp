#pragma once
/// \file transfer_set.hpp
/// Characters for a transfer test chosen by typical-stroke coverage: characters not trained whose every
/// stroke is a typical stroke (paper section 3.1) the training wrote, so that the test asks for the trained
/// strokes in new combinations (transfer in the sense of Schmidt & Lee, Motor Control and Learning, ch. 9).
#include <functional>
#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/study/protocol.hpp"

namespace calligraphy {

/// `count` characters from `candidates` (in order of preference): of those not in `trained` whose typical
/// strokes all occur in `trained` (by `typical_ids`, one ID per stroke), greedily the one that covers the
/// most trained typical strokes the chosen ones do not cover yet, ties to the one with more strokes, then
/// to the earlier candidate. Throws InvalidArgument stating how many candidates qualify when fewer than
/// `count` do, and what `typical_ids` throws.
[[nodiscard]] std::u32string choose_transfer_characters(
    const std::u32string& trained, const std::u32string& candidates, std::size_t count,
    const std::function<std::vector<int>(char32_t)>& typical_ids);

/// Fills the items of every phase of `protocol` with a `TransferChoice` not resolved yet: one item per
/// character of `choose_transfer_characters(protocol.trained_characters(), ...)`, typical strokes read from
/// the models `load` gives. Deterministic, so every subject of a study gets the same set. Throws
/// InvalidArgument naming the phase ("/phases/4 (transfer): ...") as `choose_transfer_characters`, and
/// what `load` throws (CharacterNotFound, DataError).
void resolve_transfer_choices(StudyProtocol& protocol, const std::function<Character(char32_t)>& load);

}  // namespace calligraphy
