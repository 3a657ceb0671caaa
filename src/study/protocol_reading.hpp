#pragma once
// Readers shared by the protocol's parts (protocol.cpp, protocol_phases.cpp). Internal.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/study/protocol.hpp"
#include "study/json_reader.hpp"

namespace calligraphy::study_detail {

inline constexpr std::size_t kMaxItems = 1000;
inline constexpr std::size_t kMaxCharactersPerItem = 16;
inline constexpr std::int64_t kMaxRepetitions = 1000;

/// A list of 1 to kMaxItems strings of 1 to kMaxCharactersPerItem characters each, none a space or control
/// character; DataError naming the pointer of the one at fault.
std::vector<std::u32string> read_items(const nlohmann::json& value, const std::string& pointer,
                                       const std::string& source);

/// The name of one of `conditions`, or DataError naming `pointer` and listing the defined names.
std::string condition_name(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                           const std::vector<StudyCondition>& conditions);

/// The "phases" list of a protocol (format: docs/experiments.md), checked for order and sense; appended
/// to `protocol.phases`. `protocol.conditions` and the order must be read already.
void read_phases(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                 StudyProtocol& protocol);

}  // namespace calligraphy::study_detail
