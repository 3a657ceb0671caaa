// Reading study protocols (format: docs/experiments.md).
#include "calligraphy/study/protocol.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/core/unicode.hpp"
#include "core/json_reader.hpp"
#include "core/schema_json.hpp"
#include "study/names.hpp"
#include "study/parameter_json.hpp"
#include "study/protocol_reading.hpp"
#include "trial/record_schema.hpp"

namespace calligraphy {
namespace study_detail {

using nlohmann::json;

std::vector<std::u32string> read_items(const json& value, const std::string& pointer,
                                       const std::string& source) {
  if (!value.is_array() || value.empty() || value.size() > kMaxItems) {
    json_detail::fail(source, pointer,
                      "expected a list of 1 to " + std::to_string(kMaxItems) +
                          " strings of characters, got " + json_detail::describe(value));
  }
  std::vector<std::u32string> items;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string at = json_detail::child_pointer(pointer, i);
    const std::string text = json_detail::as_string(value[i], at, source);
    std::u32string characters;
    try {
      characters = decode_utf8(text);
    } catch (const InvalidArgument& e) {
      json_detail::fail(source, at, std::string("not UTF-8: ") + e.what());
    }
    if (characters.empty() || characters.size() > kMaxCharactersPerItem) {
      json_detail::fail(source, at,
                        "expected 1 to " + std::to_string(kMaxCharactersPerItem) + " characters, got " +
                            std::to_string(characters.size()));
    }
    for (const char32_t c : characters) {
      if (c <= U' ' || c == 0x3000)
        json_detail::fail(source, at, "a space or control character cannot be written");
    }
    items.push_back(characters);
  }
  return items;
}

// The name of a condition the protocol defines, or an error naming `pointer`.
std::string condition_name(const json& value, const std::string& pointer, const std::string& source,
                           const std::vector<StudyCondition>& conditions) {
  const std::string name = json_detail::as_string(value, pointer, source);
  std::string names;
  for (const StudyCondition& c : conditions) {
    if (c.name == name) return name;
    names += (names.empty() ? "" : ", ") + c.name;
  }
  json_detail::fail(source, pointer, "no condition is called \"" + name + "\" (defined: " + names + ")");
}

}  // namespace study_detail

namespace {

using nlohmann::json;
using study_detail::condition_name;
using study_detail::read_items;
using study_detail::read_member;
using study_detail::table_number_or;
using study_detail::take_table_number;

constexpr const char* kFormat = "calligraphy-study-protocol";

// "acceptance": the stroke matcher's tolerances by name, read through the acceptance's one schema
// (SchemaOf<StrokeAcceptance>, record_schema.hpp: the keys a trial record writes, each field's range, the
// miss counts whole numbers); a key left out keeps its default.
StrokeAcceptance read_acceptance(const json& value, const std::string& pointer, const std::string& source) {
  StrokeAcceptance a;
  SchemaReadResult unused;
  schema_detail::from_json(SchemaOf<StrokeAcceptance>::get(), &a, value, pointer, source, {}, unused);
  return a;
}

// A condition's and a quiz's keys are optional, but a key given as null is refused naming it
// (docs/experiments.md, "Protocol files"): null is no value, and leaving the key out is how its default is
// asked for.
void refuse_null_members(const json& value, const std::string& pointer, const std::string& source) {
  if (!value.is_object()) return;  // the reader names the wrong type
  for (const auto& item : value.items()) {
    if (item.value().is_null()) {
      json_detail::fail(source, json_detail::child_pointer(pointer, item.key()),
                        "null is not a value (leave the key out for its default)");
    }
  }
}

QuizOptions read_quiz(const json& value, const std::string& pointer, const std::string& source) {
  json_detail::ObjectReader reader(value, pointer, source);
  QuizOptions quiz;
  if (reader.has("leniency")) {
    json_detail::fail(source, reader.pointer("leniency"),
                      "replaced by \"acceptance\": the quiz judges with the stroke matcher's tolerances "
                      "(corridor_m, mean_deviation_m, ...; docs/stroke-acceptance.md)");
  }
  refuse_null_members(value, pointer, source);
  if (const json* acceptance = reader.optional("acceptance")) {
    quiz.acceptance = read_acceptance(*acceptance, reader.pointer("acceptance"), source);
  }
  // Overrides the acceptance's, read as the acceptance's own field (SchemaOf<StrokeAcceptance>).
  if (reader.optional("hint_after_misses") != nullptr) {
    StrokeAcceptance hint;
    read_member(reader, SchemaOf<StrokeAcceptance>::get(), "hint_after_misses", &hint);
    quiz.hint_after_misses = static_cast<int>(hint.hint_after_misses);
  }
  quiz.accept_backwards = reader.boolean_or("accept_backwards", quiz.accept_backwards);
  reader.finish();
  return quiz;
}

// The documented parameters of the guidance modes (docs/experiments.md), each checked against its guidance
// law's or rule's table (study_detail::mode_parameters); an unknown key or a value out of range is an error
// naming its pointer.
std::map<std::string, double> read_guidance_parameters(const json& parameters, const std::string& pointer,
                                                       const std::string& source, ConditionMode mode) {
  json_detail::ObjectReader reader(parameters, pointer, source);
  std::map<std::string, double> values;
  for (const study_detail::ModeParameter& parameter : study_detail::mode_parameters(mode)) {
    const std::string key(parameter.key);
    if (!reader.has(key)) continue;
    const double value =
        reader.number(key, -std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
    if (!parameter.range.contains(value))
      json_detail::fail(source, reader.pointer(key), study_detail::parameter_range_message(parameter, value));
    values[key] = value;
  }
  // A rule across the keys: the assist-as-needed band's bounds in order.
  const StudyCondition condition = condition_from_mode(mode, values);
  if (const auto& schedule = condition.guidance->schedule;
      schedule && schedule->assist_rule.max_band_m < schedule->assist_rule.min_band_m) {
    json_detail::fail(source, reader.pointer("max_band_m"), "expected a band at least min_band_m");
  }
  reader.finish();  // any other key: an error naming it
  return values;
}

// "teachers": {"<item>": "path"}: keys are items (checked against the protocol's items later).
std::map<std::u32string, std::string> read_teachers(const json& value, const std::string& pointer,
                                                    const std::string& source) {
  if (!value.is_object()) {
    json_detail::fail(source, pointer,
                      "expected an object of items and recording files, got " + json_detail::describe(value));
  }
  std::map<std::u32string, std::string> teachers;
  for (const auto& item : value.items()) {
    const std::string at = json_detail::child_pointer(pointer, item.key());
    std::u32string characters;
    try {
      characters = decode_utf8(item.key());
    } catch (const InvalidArgument& e) {
      json_detail::fail(source, at, std::string("not UTF-8: ") + e.what());
    }
    const std::string path = json_detail::as_string(item.value(), at, source);
    if (path.empty())
      json_detail::fail(source, at, "expected the path of a teacher's recording, got an empty string");
    teachers[characters] = path;
  }
  return teachers;
}

// Every item a replay condition names a teacher for is one the protocol writes.
void check_teacher_items(const StudyProtocol& protocol, const std::string& source) {
  for (std::size_t i = 0; i < protocol.conditions.size(); ++i) {
    for (const auto& teacher : protocol.conditions[i].teachers) {
      const std::u32string& item = teacher.first;
      const bool written =
          std::any_of(protocol.phases.begin(), protocol.phases.end(), [&](const ProtocolPhase& p) {
            return std::find(p.items.begin(), p.items.end(), item) != p.items.end();
          });
      if (written) continue;
      const std::string text = encode_utf8(item);
      json_detail::fail(
          source,
          json_detail::child_pointer(
              json_detail::child_pointer(json_detail::child_pointer("/conditions", i), "teachers"), text),
          "\"" + text + "\" is not an item of the protocol (the characters of its phases)");
    }
  }
}

StudyCondition read_condition(const json& value, const std::string& pointer, const std::string& source) {
  json_detail::ObjectReader reader(value, pointer, source);
  StudyCondition condition;
  condition.name = reader.string("name");
  if (!study_detail::is_label(condition.name, study_detail::kMaxLabelLength)) {
    json_detail::fail(
        source, reader.pointer("name"),
        "expected 1 to 32 letters, digits, '_' or '-', got " + study_detail::in_quotes(condition.name));
  }
  // The mode's condition with the parameters' defaults (SchemaOf<StudyCondition>: condition_from_mode).
  read_member(reader, SchemaOf<StudyCondition>::get(), "mode", &condition, true);
  refuse_null_members(value, pointer, source);  // after name and mode, which name their own types
  const ConditionMode mode = condition_mode(condition);
  std::optional<double> stiffness_n_per_m;
  if (reader.optional("guidance_stiffness_n_per_m") != nullptr) {
    if (!condition.guidance) {
      json_detail::fail(source, reader.pointer("guidance_stiffness_n_per_m"),
                        std::string("mode \"") + to_string(mode) + "\" renders no guidance");
    }
    // The force law's range (ParameterTable<ForceLawParameters>), which the trial checks.
    stiffness_n_per_m = table_number_or(reader, "guidance_stiffness_n_per_m", 0.0,
                                        &ForceLawParameters::guidance_stiffness_n_per_m);
  }
  if (const json* parameters = reader.optional("parameters")) {
    const std::string at = reader.pointer("parameters");
    if (study_detail::mode_parameters(mode).empty()) {
      json_detail::fail(source, at, std::string("mode \"") + to_string(mode) + "\" takes no parameters");
    }
    std::string name = std::move(condition.name);
    condition = condition_from_mode(mode, read_guidance_parameters(*parameters, at, source, mode));
    condition.name = std::move(name);
  }
  if (condition.guidance) condition.guidance->stiffness_n_per_m = stiffness_n_per_m;
  if (const json* teachers = reader.optional("teachers")) {
    if (!replays_teacher(condition)) {
      json_detail::fail(source, reader.pointer("teachers"), "only the mode \"replay\" takes teachers");
    }
    condition.teachers = read_teachers(*teachers, reader.pointer("teachers"), source);
  }
  if (const json* quiz = reader.optional("quiz")) {
    if (!condition.quiz) {
      json_detail::fail(source, reader.pointer("quiz"), "only the mode \"quiz\" takes quiz options");
    }
    condition.quiz = read_quiz(*quiz, reader.pointer("quiz"), source);
  }
  reader.finish();
  return condition;
}

void read_order(json_detail::ObjectReader& reader, StudyProtocol& protocol) {
  const json* value = reader.optional("order");
  if (!value) return;
  // Through its schema (protocol_order_schema: the enumerations' one spelling each).
  json_detail::ObjectReader order(*value, reader.pointer("order"), reader.source());
  // The seed: every value of a std::uint64_t, also in exponent form when exact (1e3), as the schema reads it.
  for (const char* key : {"conditions", "characters", "seed"})
    study_detail::read_member(order, protocol_order_schema(), key, &protocol);
  order.finish();
}

// "breaks" and "trial" are read through their schemas (protocol_schema.cpp): unknown keys, null, wrong types
// and values out of range refused with the JSON pointer.
void read_breaks(json_detail::ObjectReader& reader, StudyProtocol& protocol) {
  const json* value = reader.optional("breaks");
  if (!value) return;
  SchemaReadResult unused;
  schema_detail::from_json(SchemaOf<BreakRules>::get(), &protocol.breaks, *value, reader.pointer("breaks"),
                           reader.source(), {}, unused);
  if (protocol.breaks.every_trials > 0 && !value->contains("duration_s")) {
    json_detail::fail(reader.source(), json_detail::child_pointer(reader.pointer("breaks"), "duration_s"),
                      "missing: every_trials needs a duration_s");
  }
}

void read_trial_settings(json_detail::ObjectReader& reader, StudyProtocol& protocol) {
  const json* value = reader.optional("trial");
  if (!value) return;
  const std::string at = reader.pointer("trial");
  SchemaReadResult unused;
  schema_detail::from_json(SchemaOf<ProtocolTrialSettings>::get(), &protocol.trial, *value, at,
                           reader.source(), {}, unused);
  // Checked here, so that a session is refused before its folder is made, naming the protocol's fields
  // rather than the trial runner's options.
  if (exceeds_trial_ticks(protocol.trial.max_duration_s, protocol.trial.rate_hz)) {
    const double ticks = protocol.trial.max_duration_s * protocol.trial.rate_hz;
    std::ostringstream message;
    message << protocol.trial.max_duration_s << " s at " << protocol.trial.rate_hz << " Hz ("
            << json_detail::child_pointer(at, "rate_hz") << ") is " << std::llround(ticks)
            << " servo ticks a trial, more than the 10000000 a trial may have (its trace is held in memory): "
               "lower max_duration_s or rate_hz";
    json_detail::fail(reader.source(), json_detail::child_pointer(at, "max_duration_s"), message.str());
  }
}

// The paper's format: an optional "practice" block, then "test" blocks of every condition (section 7.1).
void read_paper_phases(json_detail::ObjectReader& root, StudyProtocol& protocol) {
  const std::string& source = root.source();
  if (const json* practice = root.optional("practice")) {
    json_detail::ObjectReader reader(*practice, "/practice", source);
    ProtocolPhase phase;
    phase.pointer = "/practice";
    phase.kind = StudyPhase::practice;
    phase.items = read_items(reader.required("characters"), reader.pointer("characters"), source);
    phase.conditions = {condition_name(reader.required("condition"), reader.pointer("condition"), source,
                                       protocol.conditions)};
    read_member(reader, SchemaOf<ProtocolPhase>::get(), "repetitions", &phase);
    reader.finish();
    protocol.phases.push_back(std::move(phase));
  }
  json_detail::ObjectReader test(root.required("test"), "/test", source);
  ProtocolPhase phase;
  phase.pointer = "/test";
  phase.kind = StudyPhase::test;
  phase.items = read_items(test.required("characters"), test.pointer("characters"), source);
  const json& tested = test.required("conditions");
  if (!tested.is_array() || tested.empty()) {
    json_detail::fail(source, "/test/conditions",
                      "expected a list of condition names, got " + json_detail::describe(tested));
  }
  for (std::size_t i = 0; i < tested.size(); ++i) {
    const std::string at = json_detail::child_pointer("/test/conditions", i);
    std::string name = condition_name(tested[i], at, source, protocol.conditions);
    if (std::find(phase.conditions.begin(), phase.conditions.end(), name) != phase.conditions.end()) {
      json_detail::fail(source, at, "the condition \"" + name + "\" is listed twice");
    }
    phase.conditions.push_back(std::move(name));
  }
  read_member(test, SchemaOf<ProtocolPhase>::get(), "repetitions", &phase, true);
  test.finish();
  if (protocol.condition_order == ConditionOrder::abba && phase.repetitions % 2 != 0) {
    json_detail::fail(
        source, "/test/repetitions",
        "order \"abba\" splits each condition's repetitions over two blocks: expected an even number, got " +
            std::to_string(phase.repetitions));
  }
  protocol.phases.push_back(std::move(phase));
}

}  // namespace

// The spellings are the enumerations' tables' (protocol.hpp): each a string literal, so null-terminated.
const char* to_string(StudyPhase phase) noexcept { return enum_spelling(phase).data(); }

const char* to_string(ConditionAssignment assignment) noexcept { return enum_spelling(assignment).data(); }

const char* to_string(ConditionMode mode) noexcept { return enum_spelling(mode).data(); }

std::span<const ConditionMode> condition_modes() noexcept { return study_detail::kConditionModes; }

bool renders_guidance(ConditionMode mode) noexcept {
  return mode != ConditionMode::vision && mode != ConditionMode::quiz;
}

const char* to_string(ConditionOrder order) noexcept { return enum_spelling(order).data(); }

const char* to_string(ItemOrder order) noexcept { return enum_spelling(order).data(); }

const StudyCondition& StudyProtocol::condition(std::string_view wanted) const {
  for (const StudyCondition& c : conditions) {
    if (c.name == wanted) return c;
  }
  throw InvalidArgument("protocol '" + name + "' has no condition '" + std::string(wanted) + "'");
}

namespace {

StudyProtocol read_protocol_document(std::string_view json_text, const std::string& source) {
  const json document = json_detail::parse_json(json_text, source);
  // A key at the root given null is refused as a condition's is: its schema takes no null, and leaving the
  // key out is how its default is asked for.
  refuse_null_members(document, "", source);
  json_detail::ObjectReader root(document, "", source);
  StudyProtocol protocol;
  const std::string format = root.string_or("format", kFormat);
  if (format != kFormat) {
    json_detail::fail(source, "/format", std::string("expected \"") + kFormat + "\", got \"" + format + "\"");
  }
  root.integer_or("version", 1, 1, 1);
  protocol.name = root.string("name");
  if (!study_detail::is_label(protocol.name, study_detail::kMaxProtocolNameLength)) {
    json_detail::fail(
        source, "/name",
        "expected 1 to 64 letters, digits, '_' or '-', got " + study_detail::in_quotes(protocol.name));
  }
  protocol.description = root.string_or("description", "");

  const json& conditions = root.required("conditions");
  if (!conditions.is_array() || conditions.empty() || conditions.size() > study_detail::kMaxConditions) {
    json_detail::fail(source, "/conditions",
                      "expected a list of 1 to " + std::to_string(study_detail::kMaxConditions) +
                          " conditions, got " + json_detail::describe(conditions));
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    StudyCondition condition =
        read_condition(conditions[i], json_detail::child_pointer("/conditions", i), source);
    if (!names.insert(condition.name).second) {
      json_detail::fail(source,
                        json_detail::child_pointer(json_detail::child_pointer("/conditions", i), "name"),
                        "the condition \"" + condition.name + "\" is defined twice");
    }
    protocol.conditions.push_back(std::move(condition));
  }

  read_order(root, protocol);
  // Before the phases, which name the sets.
  if (const json* sets = root.optional("item_sets")) {
    study_detail::read_item_sets(*sets, "/item_sets", source, protocol);
  }
  const bool paper_format = root.has("test") || root.has("practice");
  if (paper_format && root.has("phases")) {
    json_detail::fail(
        source, "/phases",
        "a protocol gives either \"phases\" or the paper's \"practice\" and \"test\", not both");
  }
  if (paper_format) {
    read_paper_phases(root, protocol);
  } else {
    study_detail::read_phases(root.required("phases"), "/phases", source, protocol);
  }
  check_teacher_items(protocol, source);
  read_breaks(root, protocol);
  read_trial_settings(root, protocol);
  root.finish();

  const std::uint64_t planned = planned_trial_count(protocol);
  if (planned > kMaxPlannedTrials) {
    json_detail::fail(source, paper_format ? "/test" : "/phases",
                      thousands(planned) + " trials planned in one session, more than the limit of " +
                          thousands(kMaxPlannedTrials) + " trials per session");
  }
  return protocol;
}

}  // namespace

StudyProtocol parse_study_protocol(std::string_view json_text, const std::string& source) {
  // Every refusal of the text names the source and the JSON pointer (json_detail::fail): the protocol's
  // content, a usage error, not a failure to read a file.
  try {
    return read_protocol_document(json_text, source);
  } catch (const ProtocolError&) {
    throw;
  } catch (const DataError& e) {
    throw ProtocolError(e.what());
  }
}

std::uint64_t planned_trial_count(const StudyProtocol& protocol) noexcept {
  // Each factor is at most 1,000 (strings, repetitions) or 26 (conditions), and phases at most 20: no
  // overflow. Nothing is allocated (a map of the sessions' counts threw std::bad_alloc out of this noexcept
  // function when the memory was used up, which ends the process): each session's phases are summed from its
  // first phase, at most 20 x 20 steps.
  const std::vector<ProtocolPhase>& phases = protocol.phases;
  const auto trials = [](const ProtocolPhase& phase) {
    // Between subjects a subject writes one condition; in a crossover each set is written in one.
    const std::uint64_t conditions =
        phase.assignment == ConditionAssignment::within_subjects ? phase.conditions.size() : std::uint64_t{1};
    return static_cast<std::uint64_t>(phase.item_count()) * conditions *
           static_cast<std::uint64_t>(std::max(phase.repetitions, 0));
  };
  std::uint64_t largest = 0;
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const int session = phases[i].session;
    const auto first = std::find_if(phases.begin(), phases.begin() + static_cast<std::ptrdiff_t>(i),
                                    [session](const ProtocolPhase& p) { return p.session == session; });
    if (first != phases.begin() + static_cast<std::ptrdiff_t>(i)) continue;  // summed at its first phase
    std::uint64_t count = 0;
    for (std::size_t j = i; j < phases.size(); ++j) {
      if (phases[j].session == session) count += trials(phases[j]);
    }
    largest = std::max(largest, count);
  }
  return largest;
}

int StudyProtocol::session_count() const noexcept {
  int sessions = 1;
  for (const ProtocolPhase& phase : phases) sessions = std::max(sessions, phase.session);
  return sessions;
}

std::u32string StudyProtocol::trained_characters() const {
  const bool any_training = std::any_of(
      phases.begin(), phases.end(), [](const ProtocolPhase& p) { return p.kind == StudyPhase::training; });
  std::u32string trained;
  for (const ProtocolPhase& phase : phases) {
    if (any_training && phase.kind != StudyPhase::training) continue;
    for (const std::u32string& item : phase.items) {
      for (const char32_t c : item) {
        if (trained.find(c) == std::u32string::npos) trained.push_back(c);
      }
    }
  }
  return trained;
}

std::string thousands(std::uint64_t count) {
  const std::string digits = std::to_string(count);
  std::string out;  // built by appends (GCC 12 warns on insert into a string: -Wrestrict)
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out.push_back(',');
    out.push_back(digits[i]);
  }
  return out;
}

LoadedProtocol protocol_from_text(std::string text, const std::filesystem::path& path) {
  LoadedProtocol loaded;
  loaded.protocol = parse_study_protocol(text, path.string());
  loaded.sha256 = sha256_hex(text);
  loaded.text = std::move(text);
  loaded.path = path;
  return loaded;
}

namespace {

// An item listed twice in one list would be written twice as the first repetition of its condition
// (`repetition` counts the writings of a string in a condition); `repetitions` writes it again. Checked for a
// protocol file a run is planned from, not for the protocol copy of a session folder made before the check.
void refuse_repeated_items(const StudyProtocol& protocol, const std::string& source) {
  const auto check = [&](const std::vector<std::u32string>& items, const std::string& characters) {
    for (std::size_t k = 1; k < items.size(); ++k) {
      for (std::size_t first = 0; first < k; ++first) {
        if (items[first] != items[k]) continue;
        json_detail::fail(source, json_detail::child_pointer(characters, k),
                          "\"" + encode_utf8(items[k]) + "\" is listed twice (also at " +
                              json_detail::child_pointer(characters, first) +
                              "): give it once and write it again with \"repetitions\"");
      }
    }
  };
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.sets.empty()) check(phase.items, json_detail::child_pointer(phase.pointer, "characters"));
  }
  for (std::size_t i = 0; i < protocol.item_sets.size(); ++i) {
    check(protocol.item_sets[i].items,
          json_detail::child_pointer(json_detail::child_pointer("/item_sets", i), "characters"));
  }
}

}  // namespace

LoadedProtocol load_study_protocol(const std::filesystem::path& path) {
  LoadedProtocol loaded =
      protocol_from_text(study_detail::read_small_file(path, kMaxProtocolBytes, "study protocol"), path);
  try {
    refuse_repeated_items(loaded.protocol, path.string());
  } catch (const DataError& e) {  // the protocol's content, refused as the parser refuses it
    throw ProtocolError(e.what());
  }
  return loaded;
}

}  // namespace calligraphy
