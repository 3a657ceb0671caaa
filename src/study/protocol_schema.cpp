// The schemas of a protocol's parts (schema.hpp): each range is the trial's, the force law's or the guidance
// law's own where the protocol's value becomes one of theirs, so that a protocol a trial would refuse is
// refused when it is read, naming its file and JSON pointer.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "study/protocol_reading.hpp"
#include "trial/record_schema.hpp"

namespace calligraphy {

namespace {

// TrialSpec's range of rate_hz up to the real-time loop's highest rate: a protocol's trials may be written
// by a person, in real time. The one deliberate difference from the specification's range.
ParameterRange protocol_rate_range() noexcept {
  ParameterRange range = SchemaOf<TrialSpec>::get().field("rate_hz")->range;
  if (kMaxRealTimeServoRateHz < range.high) {
    range.high = kMaxRealTimeServoRateHz;
    range.high_open = false;
  }
  return range;
}

}  // namespace

const Schema& SchemaOf<ProtocolTrialSettings>::get() {
  using T = ProtocolTrialSettings;
  // TrialSpec's range of the same value: a session's trials are TrialSpecs.
  static const std::array fields{
      number_field<&T::max_duration_s>("max_duration_s",
                                       SchemaOf<TrialSpec>::get().field("max_duration_s")->range,
                                       {.unit = "s", .doc = "every trial ends after this much device time"}),
      number_field<&T::rate_hz>("rate_hz", protocol_rate_range(),
                                {.unit = "Hz", .doc = "servo rate of every trial (real-time range)"}),
  };
  static const Schema schema{.name = "ProtocolTrialSettings",
                             .doc = "settings of every trial of the study",
                             .fields = fields,
                             .defaults = default_of<T>};
  return schema;
}

const Schema& SchemaOf<BreakRules>::get() {
  using B = BreakRules;
  static const std::array fields{
      number_field<&B::between_blocks_s>("between_blocks_s", {.low = 0.0, .high = 86400.0},
                                         {.unit = "s", .doc = "rest before every block after the first"}),
      integer_field<&B::every_trials>("every_trials", 0, 100000,
                                      {.doc = "a rest of duration_s after every this many trials; 0: none"}),
      number_field<&B::duration_s>("duration_s", {.low = 0.0, .high = 86400.0},
                                   {.unit = "s", .doc = "the rest taken every every_trials trials"}),
  };
  static const Schema schema{.name = "BreakRules",
                             .doc = "rests between trials (taken by a person; a simulated writer logs them)",
                             .fields = fields,
                             .defaults = default_of<B>};
  return schema;
}

const Schema& SchemaOf<ProtocolPhase>::get() {
  using P = ProtocolPhase;
  static const std::array fields{
      enum_field<&P::kind>("phase", {.doc = "the phase of a motor-learning study"}),
      enum_field<&P::assignment>("assignment", {.doc = "how the conditions are given to subjects"}),
      integer_field<&P::repetitions>("repetitions", 1, study_detail::kMaxRepetitions,
                                     {.doc = "times each item is written in each condition"}),
      integer_field<&P::session>("session", 1, static_cast<std::int64_t>(study_detail::kMaxPhases),
                                 {.doc = "1-based: the sitting the phase is written in"}),
      number_field<&P::delay_s>(
          "delay_s", {.low = 0.0, .high = study_detail::kMaxDelay_s},
          {.unit = "s", .doc = "the phase starts at least this long after the previous one ended"}),
  };
  static const Schema schema{.name = "ProtocolPhase",
                             .doc = "a phase's settings besides its conditions and items",
                             .fields = fields,
                             .defaults = default_of<P>};
  return schema;
}

const Schema& SchemaOf<StudyCondition>::get() {
  using C = StudyCondition;
  // "mode" is no member: the spelling of the condition's display, law and schedule (condition_mode), and
  // read, the condition of that spelling with its parameters' defaults (condition_from_mode; the name and
  // teachers kept).
  static const std::array fields{[] {
    SchemaField f{.name = "mode", .kind = FieldKind::enumeration, .doc = "what the writer gets"};
    f.spellings = [] { return enum_spellings<ConditionMode>(); };
    f.enum_name = EnumTable<ConditionMode>::name;
    f.get_choice = [](const void* o) -> std::size_t {
      const ConditionMode mode = condition_mode(*static_cast<const C*>(o));
      for (std::size_t i = 0; i < EnumTable<ConditionMode>::entries.size(); ++i) {
        if (EnumTable<ConditionMode>::entries[i].value == mode) return i;
      }
      return 0;
    };
    f.set_choice = [](void* o, std::size_t i) {
      C& condition = *static_cast<C*>(o);
      C made = condition_from_mode(EnumTable<ConditionMode>::entries[i].value);
      made.name = std::move(condition.name);
      made.teachers = std::move(condition.teachers);
      condition = std::move(made);
    };
    return f;
  }()};
  static const Schema schema{
      .name = "StudyCondition", .doc = "a feedback condition", .fields = fields, .defaults = default_of<C>};
  return schema;
}

const Schema& protocol_order_schema() {
  using S = StudyProtocol;
  static const std::array fields{
      enum_field<&S::condition_order>("conditions", {.doc = "order of the condition blocks per subject"}),
      enum_field<&S::item_order>("characters", {.doc = "order of the strings within each round"}),
      unsigned_field<&S::seed>("seed", {.doc = "seeds the random orders (with the subject id)"}),
  };
  static const Schema schema{
      .name = "ProtocolOrder", .doc = "orders", .fields = fields, .defaults = default_of<S>};
  return schema;
}

ParameterRange protocol_max_lead_range() noexcept {
  ParameterRange range = parameter_field(&ReplayGuidance::max_lead_m).range;
  const double radius = ForceLawParameters{}.constraint_radius_m;
  if (radius < range.high) {
    range.high = radius;
    range.high_open = false;
  }
  return range;
}

namespace {

using nlohmann::ordered_json;

// A number field of the JSON Schema: the range as minimum / maximum, exclusive where open.
ordered_json number_schema(const ParameterRange& range, std::string_view unit, std::string_view doc) {
  ordered_json out = {{"type", "number"}};
  std::string text(doc);
  if (!unit.empty()) text.append(" [").append(unit).append("]");
  out["description"] = text;
  if (std::isfinite(range.low)) out[range.low_open ? "exclusiveMinimum" : "minimum"] = range.low;
  if (std::isfinite(range.high)) out[range.high_open ? "exclusiveMaximum" : "maximum"] = range.high;
  return out;
}

ordered_json integer_schema(std::int64_t low, std::int64_t high, std::string_view doc) {
  return {{"type", "integer"}, {"description", std::string(doc)}, {"minimum", low}, {"maximum", high}};
}

ordered_json label_schema(std::size_t longest, std::string_view doc) {
  return {{"type", "string"},
          {"description", std::string(doc)},
          {"pattern", "^[A-Za-z0-9_-]{1," + std::to_string(longest) + "}$"}};
}

ordered_json object_schema(ordered_json properties, std::string_view doc) {
  return {{"type", "object"},
          {"description", std::string(doc)},
          {"properties", std::move(properties)},
          {"additionalProperties", false}};
}

// Field `key` of `schema` as a JSON Schema property (range, spellings, default from the one table).
ordered_json schema_property(const Schema& schema, std::string_view key) {
  return schema_detail::field_json_schema(*schema.field(key), schema.defaults());
}

ordered_json ref(std::string_view name) { return {{"$ref", "#/$defs/" + std::string(name)}}; }

// The strings a phase writes: each 1 to kMaxCharactersPerItem characters (code points, as JSON Schema
// counts).
ordered_json items_schema(std::string_view doc) {
  return {
      {"type", "array"},
      {"description", std::string(doc)},
      {"minItems", 1},
      {"maxItems", study_detail::kMaxItems},
      {"items", {{"type", "string"}, {"minLength", 1}, {"maxLength", study_detail::kMaxCharactersPerItem}}}};
}

// A schema's JSON Schema body (its $defs moved into `defs`).
ordered_json described(const Schema& schema, ordered_json& defs) {
  ordered_json body = ordered_json::parse(json_schema_text(schema, "x", "x", false));
  if (body.contains("$defs")) {
    for (auto& [key, value] : body["$defs"].items()) defs[key] = value;
  }
  for (const char* key : {"$schema", "$id", "title", "$defs"}) body.erase(key);
  return body;
}

template <typename S>
void put_table_field(ordered_json& properties, std::string_view key, double S::*member,
                     const ParameterRange* narrowed = nullptr) {
  const ParameterField<S>& field = parameter_field(member);
  std::string doc =
      std::string(ParameterTable<S>::name) + "." + std::string(field.name) + ": " + std::string(field.doc);
  properties[std::string(key)] = number_schema(narrowed ? *narrowed : field.range, field.unit, doc);
}

// The "parameters" a condition of each guidance mode takes (study_detail::mode_parameters, as the reader
// reads them): each key its law's or rule's table range.
ordered_json guidance_parameters(ConditionMode mode) {
  ordered_json p = ordered_json::object();
  for (const study_detail::ModeParameter& parameter : study_detail::mode_parameters(mode)) {
    std::string doc(parameter.table);
    doc.append(".").append(parameter.field).append(": ").append(parameter.doc);
    p[std::string(parameter.key)] = number_schema(parameter.range, parameter.unit, doc);
  }
  return p;
}

ordered_json condition_schema() {
  ordered_json properties = ordered_json::object();
  properties["name"] = label_schema(study_detail::kMaxLabelLength,
                                    "unique label of the condition, used in file names and reports");
  properties["mode"] = schema_property(SchemaOf<StudyCondition>::get(), "mode");
  properties["mode"].erase("default");  // required
  put_table_field(properties, "guidance_stiffness_n_per_m", &ForceLawParameters::guidance_stiffness_n_per_m);
  properties["guidance_stiffness_n_per_m"]["description"] =
      "K_et, the guidance stiffness (paper eq. 8), modes that render guidance only [N/m]";
  properties["parameters"] = {{"type", "object"}, {"description", "the guidance mode's parameters"}};
  properties["teachers"] = {
      {"type", "object"},
      {"description", "replay: a teacher's recording file by item, relative to the protocol"},
      {"additionalProperties", {{"type", "string"}, {"minLength", 1}}}};
  properties["quiz"] = ref("QuizOptions");
  ordered_json out = object_schema(std::move(properties), "a feedback condition");
  out["required"] = ordered_json::array({"name", "mode"});
  // Per mode: the parameters it takes, each with its table's range.
  ordered_json rules = ordered_json::array();
  for (const ConditionMode mode : study_detail::kConditionModes) {
    const StudyCondition condition = condition_from_mode(mode);  // as the reader makes it
    ordered_json then = ordered_json::object();
    if (!study_detail::mode_parameters(mode).empty()) {
      then["properties"]["parameters"] = object_schema(guidance_parameters(mode), "");
      then["properties"]["parameters"].erase("description");
    } else {
      then["not"] = {{"required", {"parameters"}}};
    }
    if (!condition.guidance) {
      then["properties"]["guidance_stiffness_n_per_m"] = false;
    }
    if (!replays_teacher(condition)) then["properties"]["teachers"] = false;
    if (!condition.quiz) then["properties"]["quiz"] = false;
    rules.push_back({{"if", {{"properties", {{"mode", {{"const", to_string(mode)}}}}}}}, {"then", then}});
  }
  out["allOf"] = rules;
  return out;
}

// A field of the stroke acceptance's one schema (SchemaOf<StrokeAcceptance>, as the reader reads it)
// described by `doc`: its table's range, a miss count over the whole numbers of it.
ordered_json acceptance_property(const SchemaField& field, std::string_view doc) {
  if (field.kind != FieldKind::integer) return number_schema(field.range, field.unit, doc);
  std::string text(doc);
  if (!field.unit.empty()) text.append(" [").append(field.unit).append("]");
  return {{"type", "integer"},
          {"description", text},
          {"minimum", field.integer_low},
          {"maximum", field.integer_high}};
}

ordered_json quiz_schema() {
  const Schema& acceptance_schema = SchemaOf<StrokeAcceptance>::get();
  ordered_json acceptance = ordered_json::object();
  for (const SchemaField& field : acceptance_schema.fields) {
    std::string doc(acceptance_schema.name);
    doc.append(".").append(field.name).append(": ").append(field.doc);
    acceptance[std::string(field.name)] = acceptance_property(field, doc);
  }
  ordered_json properties = ordered_json::object();
  properties["acceptance"] =
      object_schema(std::move(acceptance), "the stroke matcher's tolerances (docs/stroke-acceptance.md)");
  // An override of the acceptance's, read as its field.
  properties["hint_after_misses"] = acceptance_property(
      *acceptance_schema.field("hint_after_misses"),
      "a hint after this many misses on one stroke, and each further one; 0: never; overrides "
      "acceptance.hint_after_misses (default: the acceptance's)");
  properties["accept_backwards"] = {
      {"type", "boolean"}, {"description", "a stroke written from its end to its start is accepted"}};
  return object_schema(std::move(properties), "how a quiz judges strokes");
}

ordered_json phase_schema() {
  const Schema& settings = SchemaOf<ProtocolPhase>::get();
  ordered_json properties = ordered_json::object();
  properties["phase"] = schema_property(settings, "phase");
  properties["phase"].erase("default");  // required
  properties["condition"] = label_schema(study_detail::kMaxLabelLength, "the one condition of the phase");
  properties["conditions"] = {{"type", "array"},
                              {"description", "the conditions of the phase, in listed order"},
                              {"minItems", 1},
                              {"uniqueItems", true},
                              {"items", label_schema(study_detail::kMaxLabelLength, "a condition's name")}};
  properties["assignment"] = schema_property(settings, "assignment");
  ordered_json choice = object_schema(
      {{"choose", integer_schema(1, static_cast<std::int64_t>(study_detail::kMaxItems), "characters chosen")},
       {"from", items_schema("single characters to choose from, in order of preference")}},
      "characters chosen when a session is made");
  choice["required"] = ordered_json::array({"choose", "from"});  // as the reader requires both
  properties["characters"] = {
      {"description", "the strings written, or (transfer) a choice by typical-stroke coverage"},
      {"oneOf", {items_schema("each string written in one trial"), std::move(choice)}}};
  properties["sets"] = {{"type", "array"},
                        {"description", "names of item sets whose items the phase writes"},
                        {"minItems", 1},
                        {"items", label_schema(study_detail::kMaxLabelLength, "an item set's name")}};
  for (const char* key : {"repetitions", "session", "delay_s"})
    properties[key] = schema_property(settings, key);
  ordered_json out = object_schema(std::move(properties), "a phase of the study");
  out["required"] = ordered_json::array({"phase"});
  return out;
}

}  // namespace

std::string protocol_json_schema_text() {
  ordered_json defs = ordered_json::object();
  defs["ProtocolTrialSettings"] = described(SchemaOf<ProtocolTrialSettings>::get(), defs);
  defs["BreakRules"] = described(SchemaOf<BreakRules>::get(), defs);
  defs["QuizOptions"] = quiz_schema();
  defs["StudyCondition"] = condition_schema();
  defs["ProtocolPhase"] = phase_schema();
  defs["ItemSet"] = object_schema(
      {{"name", label_schema(study_detail::kMaxLabelLength, "unique name of the set")},
       {"characters", items_schema("the set's items")},
       {"transfer_of",
        label_schema(study_detail::kMaxLabelLength, "the trained set whose transfer items these are")}},
      "a named set of items");
  defs["ItemSet"]["required"] = ordered_json::array({"name", "characters"});

  ordered_json properties = ordered_json::object();
  properties["format"] = {{"const", "calligraphy-study-protocol"}};
  properties["version"] = integer_schema(1, 1, "the format's version");
  properties["name"] =
      label_schema(study_detail::kMaxProtocolNameLength, "the protocol's name; names session folders");
  properties["description"] = {{"type", "string"}};
  properties["conditions"] = {{"type", "array"},
                              {"minItems", 1},
                              {"maxItems", study_detail::kMaxConditions},
                              {"items", ref("StudyCondition")}};
  properties["phases"] = {{"type", "array"},
                          {"minItems", 1},
                          {"maxItems", study_detail::kMaxPhases},
                          {"items", ref("ProtocolPhase")}};
  properties["item_sets"] = {{"type", "array"},
                             {"minItems", 1},
                             {"maxItems", study_detail::kMaxItemSets},
                             {"items", ref("ItemSet")}};
  properties["practice"] =
      object_schema({{"characters", items_schema("the familiarisation block's strings")},
                     {"condition", label_schema(study_detail::kMaxLabelLength, "the practice condition")},
                     {"repetitions", schema_property(SchemaOf<ProtocolPhase>::get(), "repetitions")}},
                    "the paper's familiarisation block, written first");
  properties["practice"]["required"] = ordered_json::array({"characters", "condition"});
  properties["test"] =
      object_schema({{"characters", items_schema("each string written in one trial")},
                     {"conditions",
                      {{"type", "array"},
                       {"minItems", 1},
                       {"uniqueItems", true},
                       {"items", label_schema(study_detail::kMaxLabelLength, "a condition")}}},
                     {"repetitions", schema_property(SchemaOf<ProtocolPhase>::get(), "repetitions")}},
                    "the paper's test blocks");
  properties["test"]["required"] = ordered_json::array({"characters", "conditions", "repetitions"});
  properties["order"] = described(protocol_order_schema(), defs);
  properties["breaks"] = ref("BreakRules");
  properties["trial"] = ref("ProtocolTrialSettings");

  ordered_json root = ordered_json::object();
  root["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  root["$id"] = "https://calligraphy.invalid/schema/protocol.json";
  root["title"] = "calligraphy study protocol (docs/experiments.md)";
  root["type"] = "object";
  root["properties"] = properties;
  root["additionalProperties"] = false;
  root["required"] = ordered_json::array({"name", "conditions"});
  // The paper's "practice" and "test", or "phases": one of them.
  ordered_json paper = ordered_json::object();
  paper["required"] = ordered_json::array({"test"});
  paper["not"]["required"] = ordered_json::array({"phases"});
  ordered_json phased = ordered_json::object();
  phased["required"] = ordered_json::array({"phases"});
  ordered_json either = ordered_json::array();
  either.push_back({{"required", {"test"}}});
  either.push_back({{"required", {"practice"}}});
  phased["not"]["anyOf"] = either;
  root["oneOf"] = ordered_json::array({paper, phased});
  root["$defs"] = defs;
  return root.dump(2) + "\n";
}

std::string protocol_schema_markdown() {
  return "### trial\n\n" + schema_markdown(SchemaOf<ProtocolTrialSettings>::get()) + "\n### breaks\n\n" +
         schema_markdown(SchemaOf<BreakRules>::get());
}

}  // namespace calligraphy
