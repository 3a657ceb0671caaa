#include "calligraphy/trial/trial_spec.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <nlohmann/json.hpp>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "core/json_reader.hpp"
#include "core/rate_text.hpp"
#include "core/schema_json.hpp"
#include "trial/record_schema.hpp"
#include "trial/trial_spec_object.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;

// The range of a guidance law's or the force law's parameter held by the specification: the law's table
// entry, the one definition of that range.
template <typename Law>
ParameterRange law_range(double Law::*member) {
  return parameter_field(member).range;
}

constexpr double kLargest = std::numeric_limits<double>::max();

const std::vector<SchemaField>& writer_setting_fields() {
  static const std::vector<SchemaField> fields{
      string_field<&WriterSetting::key>(
          "key", {.doc = "a field of the simulated writer's profile (docs/writer.md)"}),
      number_field<&WriterSetting::value>("value", {.low = -kLargest, .high = kLargest},
                                          {.doc = "its value, in the field's unit and range"}),
  };
  return fields;
}

// The stroke acceptance's fields as fields of the specification (TrialSpec::acceptance), one per entry of
// StrokeAcceptance's table, in its order: the key, unit, range and doc are the table's (the one definition; a
// field added to the table is a field of the specification), the option the key dashed with a length's "_m"
// dropped (as --assist-band); the miss counts are integers. Version 6 of a trial record is the first whose
// specification states them; an older record's are the acceptance it ran with (its force law's,
// recorded_trial.cpp).
std::vector<SchemaField> acceptance_fields() {
  static std::deque<std::string> options;  // owns the texts the fields' views point into
  std::vector<SchemaField> out;
  const auto entries = ParameterTable<StrokeAcceptance>::fields();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string_view name = entries[i].name;
    const bool length = entries[i].unit == std::string_view("m") && name.ends_with("_m");
    std::string option = "--";
    option.append(length ? name.substr(0, name.size() - 2) : name);
    std::replace(option.begin(), option.end(), '_', '-');
    options.push_back(std::move(option));
    SchemaField f{.name = name, .kind = FieldKind::number, .unit = entries[i].unit, .doc = entries[i].doc};
    f.range = entries[i].range;
    f.table_slot = i;
    f.option = options.back();
    f.option_value_name = length ? "M" : name.ends_with("_misses") ? "N" : "X";
    f.get_number = [](const SchemaField& self, const void* o, std::size_t) -> double {
      return static_cast<const TrialSpec*>(o)->acceptance.*
             (ParameterTable<StrokeAcceptance>::fields()[self.table_slot].member);
    };
    f.set_number = [](const SchemaField& self, void* o, std::size_t, double v) {
      static_cast<TrialSpec*>(o)->acceptance.*
          (ParameterTable<StrokeAcceptance>::fields()[self.table_slot].member) = v;
    };
    if (entries[i].whole_number) make_whole_number_kind(f);  // the miss counts
    // The specification states the acceptance since version 6 of a record; later fields since their own.
    out.push_back(since(std::max(6, trial_detail::acceptance_field_version(f.name)), f));
  }
  return out;
}

// `fields` with the acceptance's after the trial's time limit, before its outputs.
std::vector<SchemaField> with_acceptance_fields(std::vector<SchemaField> fields) {
  const std::vector<SchemaField> acceptance = acceptance_fields();
  const auto outputs = std::find_if(fields.begin(), fields.end(),
                                    [](const SchemaField& field) { return field.name == "json_file"; });
  fields.insert(outputs, acceptance.begin(), acceptance.end());
  return fields;
}

// The fields in both forms, in the order the forms list them: the JSON key, the option of `calligraphy
// trial`, the unit, the range and the doc. Built once, on first use: ranges come from the laws' tables.
const std::vector<SchemaField>& spec_fields() {
  static const std::vector<SchemaField> fields = with_acceptance_fields({
      string_field<&TrialSpec::characters>("characters",
                                           {.doc = "the characters to write, left to right (UTF-8)",
                                            .option = "CHARS",
                                            .option_value_name = "CHARS"}),
      string_field<&TrialSpec::device>("device", {.doc = "the device, by its name in `calligraphy devices`",
                                                  .option = "--device",
                                                  .option_value_name = "NAME"}),
      boolean_field<&TrialSpec::guidance>(
          "guidance", {.doc = "guiding force towards the stroke", .option = "--guidance"}),
      enum_field<&TrialSpec::guidance_mode>(
          "guidance_mode",
          {.doc =
               "how the guidance acts: the paper's fixture, faded by --guidance-gain, replaying --teacher, "
               "only beyond --assist-band, pushing off the stroke (--amplification-gain), or pulling along "
               "it at --timing-speed",
           .option = "--guidance-mode"}),
      // Version 3 of a trial record (calligraphy/trial/recorded_trial.hpp) is the first to state it.
      since(3,
            number_field<&TrialSpec::guidance_stiffness_n_per_m>(
                "guidance_stiffness_n_per_m", law_range(&ForceLawParameters::guidance_stiffness_n_per_m),
                {.unit = "N/m",
                 .doc =
                     "K_et, the guidance stiffness per unit attraction factor; when not given, capped at the "
                     "device's stable maximum",
                 .option = "--guidance-stiffness",
                 .option_value_name = "N/M",
                 .source = "Wang, Zhang & Yao 2006, eq. (8)"})),
      number_field<&TrialSpec::guidance_gain>(
          "guidance_gain", law_range(&FadingGuidance::gain),
          {.doc = "fading: the guidance's gain", .option = "--guidance-gain", .option_value_name = "G"}),
      number_field<&TrialSpec::assist_band_m>(
          "assist_band_m", law_range(&AssistAsNeededGuidance::band_m),
          {.unit = "m",
           .doc = "assist-as-needed: half-width of the band in which the writer corrects alone",
           .option = "--assist-band",
           .option_value_name = "M"}),
      number_field<&TrialSpec::amplification_gain>(
          "amplification_gain", law_range(&ErrorAmplificationGuidance::gain),
          {.doc = "error-amplification: the repulsive stiffness's share of K_et",
           .option = "--amplification-gain",
           .option_value_name = "G"}),
      number_field<&TrialSpec::timing_speed_m_s>("timing_speed_m_s", law_range(&TimingGuidance::speed_m_s),
                                                 {.unit = "m/s",
                                                  .doc = "timing: the target's mean speed along each stroke",
                                                  .option = "--timing-speed",
                                                  .option_value_name = "M/S"}),
      string_field<&TrialSpec::teacher>(
          "teacher", {.doc = "replay: the teacher's recording of the characters (made with --record)",
                      .option = "--teacher",
                      .option_value_name = "FILE"}),
      enum_field<&TrialSpec::writer>(
          "writer",
          {.doc = "who writes: the simulated writer (on the simulated and emulated devices it moves) "
                  "or a person (on a hardware device); auto: the device's own",
           .option = "--writer"}),
      string_field<&TrialSpec::writer_profile>(
          "writer_profile",
          {.doc = "the simulated writer's profile: novice, skilled or foreign (docs/writer.md)",
           .option = "--writer-profile",
           .option_value_name = "NAME"}),
      object_list_field<&TrialSpec::writer_parameters>(
          "writer_parameters",
          {.doc = "settings of the simulated writer's profile, applied in turn (keys: docs/writer.md)",
           .option = "--writer-param",
           .option_value_name = "KEY=VALUE"}),
      unsigned_field<&TrialSpec::seed>(
          "seed", {.doc = "seed of the simulated writer", .option = "--seed", .option_value_name = "N"}),
      number_field<&TrialSpec::rate_hz>("rate_hz", {.low = kMinServoRateHz, .high = kMaxServoRateHz},
                                        {.unit = "Hz",
                                         .doc = "servo rate (real-time pacing: at most 10000 Hz)",
                                         .option = "--rate",
                                         .option_value_name = "HZ"}),
      enum_field<&TrialSpec::pacing>("pacing",
                                     {.doc = "how the trial's ticks are paced", .option = "--pacing"}),
      enum_field<&TrialSpec::realtime>(
          "realtime", {.doc = "real-time pacing: fail unless SCHED_FIFO, CPU pinning and locked memory are "
                              "obtained (enforce)",
                       .option = "--realtime"}),
      option_in_whole(
          "ms", 1000.0,
          number_field<&TrialSpec::watchdog_s>(
              "watchdog_s", {.low = 0.0, .high = kMaxStallTimeoutS},
              {.unit = "s",
               .doc = "real-time pacing: end the trial when the device holds one force longer than this, "
                      "in whole milliseconds; 0: off",
               .option = "--watchdog-ms",
               .option_value_name = "MS"})),
      number_field<&TrialSpec::max_duration_s>(
          "max_duration_s", {.low = 0.0, .high = kMaxTrialDurationS, .low_open = true},
          {.unit = "s",
           .doc =
               "the trial ends after max_duration_s x rate_hz servo ticks (late real-time ticks make it last "
               "longer by the clock); at most 10^7 ticks",
           .option = "--max-duration",
           .option_value_name = "S"}),
      string_field<&TrialSpec::json_file>(
          "json_file", {.doc = "write the metrics as JSON", .option = "--json", .option_value_name = "FILE"}),
      string_field<&TrialSpec::csv_file>(
          "csv_file", {.doc = "write the trace (t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten; "
                              "s, m, N) as CSV",
                       .option = "--csv",
                       .option_value_name = "FILE"}),
      string_field<&TrialSpec::svg_file>("svg_file", {.doc = "draw the reference and the pen trace as SVG",
                                                      .option = "--svg",
                                                      .option_value_name = "FILE"}),
      string_field<&TrialSpec::record_file>(
          "record_file",
          {.doc = "write the trial as a teacher's recording for --guidance-mode replay (a trial "
                  "that wrote every stroke in order)",
           .option = "--record",
           .option_value_name = "FILE"}),
  });
  return fields;
}

// The public view of the fields (key, option, value name, help), made from the schema.
const std::vector<TrialSpecField>& fields_in_order() {
  static const std::vector<TrialSpecField> fields = [] {
    static std::vector<std::string> helps;  // owns the texts the views point into
    static std::vector<std::string> value_names;
    const auto& schema_fields = spec_fields();
    helps.reserve(schema_fields.size());
    value_names.reserve(schema_fields.size());
    std::vector<TrialSpecField> out;
    for (const SchemaField& field : schema_fields) {
      std::string help = field.description();
      if (!field.option_unit.empty()) help += " (the option in " + std::string(field.option_unit) + ")";
      helps.push_back(std::move(help));
      value_names.push_back(field.option_value_name.empty() ? field.range_text()
                                                            : std::string(field.option_value_name));
      out.push_back(TrialSpecField{field.name, field.option, value_names.back(), helps.back(),
                                   field.kind == FieldKind::object_list});
    }
    return out;
  }();
  return fields;
}

const TrialSpecField& field_named(std::string_view name) {
  for (const TrialSpecField& field : fields_in_order()) {
    if (name == field.key || name == field.option) return field;
  }
  std::string names;
  for (const TrialSpecField& field : fields_in_order())
    names += (names.empty() ? "" : ", ") + std::string(field.key);
  throw InvalidArgument("trial specification: no field '" + std::string(name) + "'; fields: " + names);
}

// "guidance_mode (--guidance-mode)": how an error names a field in either form.
std::string field_label(std::string_view key) {
  const TrialSpecField& field = field_named(key);
  return std::string(field.key) + " (" + std::string(field.option) + ")";
}

[[noreturn]] void refuse(std::string_view key, const std::string& message) {
  throw InvalidArgument(field_label(key) + ": " + message);
}

// TrialSpec::validate's refusals carry the field's key, so that a record's reader names its JSON pointer.
[[noreturn]] void refuse_field(std::string_view key, const std::string& message) {
  throw InvalidTrialSpecField(std::string(key), field_label(key) + ": " + message);
}

std::string number_text(double value) { return shortest_decimal(value); }

// The fields that only one guidance setting reads: stated with another (a value nothing would read), they are
// a mistake. `validate` knows a field as stated when it is not at its default; a front-end that knows what
// was given (the command line) asks `refuse_inapplicable_fields` of every field given, default or not.
struct ConditionalField {
  std::string_view name;
  bool (*stated)(const TrialSpec&);   // not at its default
  bool (*applies)(const TrialSpec&);  // read by this specification's guidance
  const char* when;                   // what it applies to, for the error
};
constexpr bool replaying(const TrialSpec& s) { return s.guidance_mode == GuidanceMode::replay; }
const ConditionalField kConditionalFields[] = {
    {"guidance_stiffness_n_per_m",
     [](const TrialSpec& s) {
       return s.guidance_stiffness_n_per_m != TrialSpec{}.guidance_stiffness_n_per_m;
     },
     [](const TrialSpec& s) { return s.guidance; }, "applies to guidance on (guidance is off)"},
    {"guidance_gain", [](const TrialSpec& s) { return s.guidance_gain != TrialSpec{}.guidance_gain; },
     [](const TrialSpec& s) { return s.guidance_mode == GuidanceMode::fading; },
     "applies to guidance mode 'fading' only"},
    {"assist_band_m", [](const TrialSpec& s) { return s.assist_band_m != TrialSpec{}.assist_band_m; },
     [](const TrialSpec& s) { return s.guidance_mode == GuidanceMode::assist_as_needed; },
     "applies to guidance mode 'assist-as-needed' only"},
    {"amplification_gain",
     [](const TrialSpec& s) { return s.amplification_gain != TrialSpec{}.amplification_gain; },
     [](const TrialSpec& s) { return s.guidance_mode == GuidanceMode::error_amplification; },
     "applies to guidance mode 'error-amplification' only"},
    {"timing_speed_m_s",
     [](const TrialSpec& s) { return s.timing_speed_m_s != TrialSpec{}.timing_speed_m_s; },
     [](const TrialSpec& s) { return s.guidance_mode == GuidanceMode::timing; },
     "applies to guidance mode 'timing' only"},
    {"teacher", [](const TrialSpec& s) { return !s.teacher.empty(); }, replaying,
     "applies to guidance mode 'replay' only"},
};

}  // namespace

void refuse_inapplicable_fields(const TrialSpec& spec, const std::vector<std::string>& given) {
  for (const ConditionalField& field : kConditionalFields) {
    if (std::find(given.begin(), given.end(), field.name) != given.end() && !field.applies(spec))
      refuse(field.name, std::string(field.when) + " (given explicitly, at any value)");
  }
}

const Schema& SchemaOf<WriterSetting>::get() {
  static const Schema schema{.name = "WriterSetting",
                             .doc = "one setting of the simulated writer's profile",
                             .fields = writer_setting_fields(),
                             .defaults = default_of<WriterSetting>};
  return schema;
}

const Schema& SchemaOf<TrialSpec>::get() {
  static const Schema schema{
      .name = "TrialSpec",
      .doc =
          "one trial: what to write, on which device, with which guidance, pacing, writer and outputs; "
          "lengths in m, times in s, rates in Hz, stiffnesses in N/m",
      .fields = spec_fields(),
      .defaults = default_of<TrialSpec>,
      // Its rules between fields are TrialSpec::validate, which needs to know where a replay's teacher comes
      // from: the readers run it after the fields are read.
      .check_rules = nullptr};
  return schema;
}

double default_watchdog_s(bool hardware_device) noexcept {
  return hardware_device ? TrialSpec{}.watchdog_s : 0.0;
}

const char* to_string(TrialWriter writer) noexcept { return enum_spelling(writer).data(); }

std::span<const TrialSpecField> trial_spec_fields() { return fields_in_order(); }

void set_trial_spec_field(TrialSpec& spec, std::string_view name, std::string_view text) {
  const SchemaField& field = *SchemaOf<TrialSpec>::get().field(field_named(name).key);
  try {
    if (field.kind == FieldKind::object_list) {  // a writer's setting, "key=value"
      spec.writer_parameters.push_back(parse_writer_setting(text));
    } else {
      set_field_from_text(field, &spec, text);
    }
  } catch (const InvalidArgument& e) {
    refuse(field.name, e.what());
  }
}

std::vector<std::string> trial_spec_field_text(const TrialSpec& spec, std::string_view name) {
  const SchemaField& field = *SchemaOf<TrialSpec>::get().field(field_named(name).key);
  if (field.kind != FieldKind::object_list) return {field_text(field, &spec)};
  std::vector<std::string> texts;
  for (const WriterSetting& setting : spec.writer_parameters) texts.push_back(writer_setting_text(setting));
  return texts;
}

void TrialSpec::validate(TeacherSource teacher_from) const {
  std::u32string decoded;
  try {
    decoded = decode_utf8(characters);
  } catch (const Error& e) {
    refuse_field("characters", e.what());
  }
  if (decoded.empty()) refuse_field("characters", "no character to write");
  if (decoded.size() > kMaxSceneCharacters) {
    refuse_field("characters", std::to_string(decoded.size()) + " characters, more than a scene's limit of " +
                                   std::to_string(kMaxSceneCharacters));
  }
  if (device.empty()) refuse_field("device", "no device named");
  // Every field in its range (the schema's, from the laws' tables), the error naming both its forms.
  const Schema& schema = SchemaOf<TrialSpec>::get();
  for (const SchemaField& field : schema.fields) {
    try {
      check_field(schema, field, this);
    } catch (const InvalidArgument& e) {
      refuse_field(field.name, e.what());
    }
  }
  // The acceptance's rules beyond its fields' ranges (a miss count is a whole number), named by the field.
  try {
    acceptance.validate();
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    for (const ParameterField<StrokeAcceptance>& entry : ParameterTable<StrokeAcceptance>::fields()) {
      std::string named = ".";
      named.append(entry.name).append(" ");
      if (what.find(named) != std::string::npos) refuse_field(entry.name, what);
    }
    throw InvalidArgument(std::string("trial specification: ").append(what));
  }
  if (!guidance && guidance_mode != GuidanceMode::fixed) {
    refuse_field("guidance_mode", std::string("'") + calligraphy::to_string(guidance_mode) +
                                      "' needs guidance on (guidance is off)");
  }
  // Each mode's own parameter: in its law's range, and stated only with its mode (a value nothing reads is
  // a mistake). The teacher is checked below, where it comes from matters.
  for (const ConditionalField& field : kConditionalFields) {
    if (field.name != "teacher" && field.stated(*this) && !field.applies(*this))
      refuse_field(field.name, field.when);
  }
  if (guidance_mode == GuidanceMode::replay && teacher.empty() && teacher_from == TeacherSource::file) {
    refuse_field("teacher", "required with guidance mode 'replay' (a recording made with --record)");
  }
  if (!teacher.empty() && teacher_from == TeacherSource::samples) {
    refuse_field("teacher", "the teacher is given as samples; the file would not be read");
  }
  if (!teacher.empty() && guidance_mode != GuidanceMode::replay) {
    refuse_field("teacher", "applies to guidance mode 'replay' only");
  }
  if (writer == TrialWriter::person && writer_profile != TrialSpec{}.writer_profile) {
    refuse_field("writer_profile", "applies to the simulated writer, not to a person (writer 'person')");
  }
  if (writer == TrialWriter::person && !writer_parameters.empty()) {
    refuse_field("writer_parameters", "apply to the simulated writer, not to a person (writer 'person')");
  }
  // The profile is one of the known ones (`writer_profile`, the one list the options and Python take), so a
  // record naming another is refused as the option is, not run under a name no writer has. Its settings' keys
  // and ranges are the simulated writer's to check (sim's writer_profile_of, when it is made).
  if (writer_profile.empty()) refuse_field("writer_profile", "no profile named");
  try {
    (void)calligraphy::writer_profile(writer_profile);
  } catch (const InvalidArgument& error) {
    refuse_field("writer_profile", error.what());
  }
  for (const WriterSetting& setting : writer_parameters) {
    if (setting.key.empty() || !std::isfinite(setting.value))
      refuse_field("writer_parameters",
                   "'" + writer_setting_text(setting) + "' is not a key and a finite number");
  }
  const bool real_time = pacing == TrialPacing::real_time;
  if (!servo_rate_allowed(rate_hz, real_time)) {
    refuse_field("rate_hz", detail::rate_text(rate_hz) + " is outside " + servo_rate_range_text(real_time) +
                                (real_time ? " (real-time pacing)" : ""));
  }
  if (watchdog_s != static_cast<double>(std::llround(watchdog_s * 1000.0)) / 1000.0)
    refuse_field("watchdog_s", number_text(watchdog_s) + " s is not a whole number of milliseconds");
  if (pacing == TrialPacing::lock_step && watchdog_s != TrialSpec{}.watchdog_s) {
    refuse_field("watchdog_s", "applies to real-time pacing only (lock-step has no wall clock to bound)");
  }
  // A trace longer than this would not fit a trial's memory (one sample per tick).
  if (exceeds_trial_ticks(max_duration_s, rate_hz)) {
    refuse_field("max_duration_s", number_text(max_duration_s) + " s at " + field_label("rate_hz") + " " +
                                       detail::rate_text(rate_hz) + " is more than 10^7 servo ticks");
  }
  // Outputs on one file are the front-end's to find (after resolving links: the CLI's file plan).
  if (record_file == "-")
    refuse_field("record_file", "a teacher's recording goes to a file, not to standard output");
}

Checked<TrialSpec> trial_spec_from_args(std::span<const std::string> args) {
  TrialSpec spec;
  std::size_t i = 0;
  if (i < args.size() && !args[i].starts_with("--")) set_trial_spec_field(spec, "characters", args[i++]);
  for (; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (!word.starts_with("--") || word == "CHARS") {
      throw InvalidArgument("trial specification: '" + word + "' at word " + std::to_string(i + 1) +
                            " is not an option (CHARS comes first, then --option value)");
    }
    (void)field_named(word);  // an unknown option is named before its value is looked for
    if (i + 1 >= args.size()) throw InvalidArgument("trial specification: " + word + ": needs a value");
    set_trial_spec_field(spec, word, args[++i]);
  }
  return Checked<TrialSpec>::check(std::move(spec));
}

std::vector<std::string> trial_spec_args(const TrialSpec& spec) {
  const TrialSpec defaults;
  std::vector<std::string> args{spec.characters};
  for (const TrialSpecField& field : fields_in_order()) {
    if (field.key == "characters") continue;
    const std::vector<std::string> values = trial_spec_field_text(spec, field.key);
    if (values == trial_spec_field_text(defaults, field.key)) continue;
    for (const std::string& value : values) {
      args.emplace_back(field.option);
      args.push_back(value);
    }
  }
  return args;
}

namespace trial_detail {

void type_writer_settings(json& trial, const std::string& pointer, const std::string& source) {
  if (!trial.is_object()) return;
  const auto settings = trial.find("writer_parameters");
  if (settings == trial.end() || !settings->is_array()) return;
  for (std::size_t i = 0; i < settings->size(); ++i) {
    json& item = (*settings)[i];
    if (!item.is_string()) continue;
    try {
      const WriterSetting setting = parse_writer_setting(item.get<std::string>());
      item = {{"key", setting.key}, {"value", setting.value}};
    } catch (const InvalidArgument& e) {
      json_detail::fail(
          source, json_detail::child_pointer(json_detail::child_pointer(pointer, "writer_parameters"), i),
          e.what());
    }
  }
}

Checked<TrialSpec> trial_spec_from_object(const json& document, const std::string& at_pointer,
                                          const std::string& source, TeacherSource teacher_from,
                                          const SchemaReadOptions& options) {
  json object = document;
  type_writer_settings(object, at_pointer, source);
  TrialSpec spec;
  SchemaReadResult read;
  schema_detail::from_json(SchemaOf<TrialSpec>::get(), &spec, object, at_pointer, source, options, read);
  return Checked<TrialSpec>::check(std::move(spec), teacher_from);
}

}  // namespace trial_detail

Checked<TrialSpec> trial_spec_from_json(std::string_view text, const std::string& source,
                                        TeacherSource teacher_from) {
  return trial_detail::trial_spec_from_object(json_detail::parse_json(text, source), "", source,
                                              teacher_from);
}

std::string trial_spec_json(const TrialSpec& spec) { return schema_json(spec); }

}  // namespace calligraphy
