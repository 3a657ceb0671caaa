#pragma once
// Readers shared by the protocol's parts (protocol.cpp, protocol_phases.cpp). Internal.
#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/study/protocol.hpp"
#include "core/json_reader.hpp"
#include "core/schema_json.hpp"

namespace calligraphy::study_detail {

inline constexpr std::size_t kMaxItems = 1000;
inline constexpr std::size_t kMaxCharactersPerItem = 16;
inline constexpr std::int64_t kMaxRepetitions = 1000;
inline constexpr std::size_t kMaxPhases = 20;
inline constexpr std::size_t kMaxLabelLength = 32;         ///< a condition's or an item set's name
inline constexpr std::size_t kMaxProtocolNameLength = 64;  ///< a protocol's name (it names folders)
inline constexpr std::size_t kMaxConditions = 26;
// As many sets as conditions may be compared in one crossover: the conditions' limit.
inline constexpr std::size_t kMaxItemSets = kMaxConditions;
// A delay longer than a year is a typo, not a design.
inline constexpr double kMaxDelay_s = 366.0 * 86400.0;
/// Every value of enumeration `E`, in its table's order (EnumTable, protocol.hpp: the one list).
template <typename E>
inline constexpr auto kEnumValues = [] {
  std::array<E, EnumTable<E>::entries.size()> out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = EnumTable<E>::entries[i].value;
  return out;
}();
inline constexpr const auto& kAssignments = kEnumValues<ConditionAssignment>;
inline constexpr const auto& kConditionOrders = kEnumValues<ConditionOrder>;
inline constexpr const auto& kItemOrders = kEnumValues<ItemOrder>;
/// Every phase, in the order the docs list them.
inline constexpr const auto& kStudyPhases = kEnumValues<StudyPhase>;
/// Every condition mode, in declaration order (condition_modes()).
inline constexpr const auto& kConditionModes = kEnumValues<ConditionMode>;

/// One key a condition mode takes in its "parameters" (docs/experiments.md): the field of a guidance law's
/// or rule's table it is, and where its value goes in the condition's guidance.
struct ModeParameter {
  std::string_view key;    ///< the protocol's name ("start_gain")
  std::string_view table;  ///< the table's name ("FadingGuidance")
  std::string_view field;  ///< the field's name in it ("gain")
  std::string_view unit;
  std::string_view doc;
  ParameterRange range;    ///< the table's, or narrowed by `bound`
  std::string_view bound;  ///< what narrows the range, for messages ("" when nothing does)
  void (*apply)(ConditionGuidance& guidance, double value);  ///< sets it in `condition_from_mode`'s guidance
};

/// The keys `mode` takes, in the order the documentation lists them; none for vision, quiz and haptic.
/// With `condition_from_mode` the one place a mode's parameters are defined (study_condition.cpp).
std::span<const ModeParameter> mode_parameters(ConditionMode mode);

/// "expected a number RANGE (Table.field), got VALUE": a parameter's value out of its range.
std::string parameter_range_message(const ModeParameter& parameter, double value);

/// `value` among `values` by their `to_string` names; DataError naming `pointer` and listing the names for
/// anything else.
template <typename Enum, std::size_t N>
Enum choice_of(const nlohmann::json& value, const std::string& pointer, const std::string& source,
               const std::array<Enum, N>& values) {
  const std::string text = json_detail::as_string(value, pointer, source);
  std::string names;
  for (const Enum candidate : values) {
    if (text == to_string(candidate)) return candidate;
    names += (names.empty() ? "" : ", ") + std::string(to_string(candidate));
  }
  json_detail::fail(source, pointer, "expected one of " + names + "; got \"" + text + "\"");
}

/// Member `key` as `choice_of`; `fallback` when it is missing.
template <typename Enum, std::size_t N>
Enum choice(json_detail::ObjectReader& reader, const std::string& key, const std::array<Enum, N>& values,
            Enum fallback) {
  const nlohmann::json* value = reader.optional(key);
  return value ? choice_of(*value, reader.pointer(key), reader.source(), values) : fallback;
}

/// Member `key` as `choice_of`; DataError naming it when it is missing.
template <typename Enum, std::size_t N>
Enum choice(json_detail::ObjectReader& reader, const std::string& key, const std::array<Enum, N>& values) {
  return choice_of(reader.required(key), reader.pointer(key), reader.source(), values);
}

/// Member `key` of the object `reader` reads, through the field of that name of `schema` into `object`:
/// its type, range or spellings as the schema checks them (schema_detail::read_field), the error naming the
/// member's pointer. Missing or null: `object` keeps its value; with `required`, missing is an error.
inline void read_member(json_detail::ObjectReader& reader, const Schema& schema, const std::string& key,
                        void* object, bool required = false) {
  const SchemaField* field = schema.field(key);
  // A key given null is refused naming it (docs/experiments.md, "Protocol files"): null is no value, and
  // leaving the key out is how its default is asked for.
  if (!required && reader.is_null(key)) {  // a required key's null is named by its type below
    json_detail::fail(reader.source(), reader.pointer(key),
                      "null is not a value (leave the key out for its default)");
  }
  const nlohmann::json* value = required ? &reader.required(key) : reader.optional(key);
  if (field == nullptr || value == nullptr) return;
  schema_detail::read_field(schema, *field, object, *value, reader.pointer(key), reader.source());
}

/// `text` as a JSON string, for messages ("\"x\" is trained"): a quote, a backslash or a control character
/// is escaped as the protocol file spells it (`"V\u0000"`), so that a NUL cannot cut the message short;
/// not `quoted`, which argument-dependent lookup would confuse with std::quoted.
inline std::string in_quotes(const std::string& text) {
  return nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// A list of 1 to kMaxItems strings of 1 to kMaxCharactersPerItem characters each, none a space or control
/// character; DataError naming the pointer of the one at fault.
std::vector<std::u32string> read_items(const nlohmann::json& value, const std::string& pointer,
                                       const std::string& source);

/// The name of one of `conditions`, or DataError naming `pointer` and listing the defined names.
std::string condition_name(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                           const std::vector<StudyCondition>& conditions);

/// The "item_sets" list of a protocol (format: docs/experiments.md), into `protocol.item_sets`: names unique
/// labels, no character in two sets, `transfer_of` naming another set that is no transfer set itself.
void read_item_sets(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                    StudyProtocol& protocol);

/// A phase's "sets" (`pointer`): names of `protocol.item_sets`, none twice, into `phase.sets`, with the sets'
/// items concatenated in `phase.items` and each one's set in `phase.item_sets`.
void read_phase_sets(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                     const StudyProtocol& protocol, ProtocolPhase& phase);

/// The JSON pointer the protocol file gives item `index` of `phase` by: in the phase's "characters", or in
/// its item set's "characters" ("/item_sets/1/characters/0") when the phase gives "sets".
std::string item_pointer(const StudyProtocol& protocol, const ProtocolPhase& phase, std::size_t index);

/// With a crossover phase: refuses another training phase on an item of a set the crossover trains (or of
/// its transfer set), naming the item's pointer, and attributes every item of a test phase that lists its
/// characters to the one set holding all of them (`phase.item_sets`), refusing, by its pointer, an item of
/// no set or of two, and a transfer test chosen by coverage. Practice phases are left as they are.
void check_crossover_items(StudyProtocol& protocol, const std::string& source);

/// The "phases" list of a protocol (format: docs/experiments.md), checked for order and sense; appended
/// to `protocol.phases`. `protocol.conditions`, `protocol.item_sets` and the order must be read already.
void read_phases(const nlohmann::json& value, const std::string& pointer, const std::string& source,
                 StudyProtocol& protocol);

}  // namespace calligraphy::study_detail
