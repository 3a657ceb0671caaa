#include "calligraphy/trial/trial_spec.hpp"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/scene.hpp"
#include "core/json_reader.hpp"
#include "trial/trial_spec_object.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;

// A guidance law's parameter's help: its mode, then the law's table entry (doc, unit and range), so that
// the help states the range the check applies.
template <typename Law>
std::string law_help(std::string_view mode, double Law::*member) {
  return std::string(mode) + ": " + parameter_field(member).description();
}

// The fields in both forms. The keys are the JSON names; the options those of `calligraphy trial`. Built
// once, on first use: four helps come from the guidance laws' tables.
const auto& fields_in_order() {
  static const std::string gain_help = law_help("fading", &FadingGuidance::gain);
  static const std::string band_help = law_help("assist-as-needed", &AssistAsNeededGuidance::band_m);
  static const std::string amplification_help =
      law_help("error-amplification", &ErrorAmplificationGuidance::gain);
  static const std::string speed_help = law_help("timing", &TimingGuidance::speed_m_s);
  static const std::array fields{
      TrialSpecField{"characters", "CHARS", "CHARS", "the characters to write, left to right (UTF-8)"},
      TrialSpecField{"device", "--device", "NAME", "the device, by its name in `calligraphy devices`"},
      TrialSpecField{"guidance", "--guidance", "on|off", "guiding force towards the stroke"},
      TrialSpecField{
          "guidance_mode", "--guidance-mode",
          "fixed|fading|replay|assist-as-needed|error-amplification|timing",
          "how the guidance acts: the paper's fixture, faded by --guidance-gain, replaying --teacher, "
          "only beyond --assist-band, pushing off the stroke (--amplification-gain), or pulling "
          "along it at --timing-speed"},
      TrialSpecField{"guidance_gain", "--guidance-gain", "G", gain_help},
      TrialSpecField{"assist_band_m", "--assist-band", "M", band_help},
      TrialSpecField{"amplification_gain", "--amplification-gain", "G", amplification_help},
      TrialSpecField{"timing_speed_m_s", "--timing-speed", "M/S", speed_help},
      TrialSpecField{"teacher", "--teacher", "FILE",
                     "replay: the teacher's recording of CHARS (made with --record)"},
      TrialSpecField{"writer", "--writer", "auto|person|simulated",
                     "who writes: the simulated writer (on the simulated and emulated devices it moves) or a "
                     "person (on a hardware device); auto: the device's own"},
      TrialSpecField{"writer_profile", "--writer-profile", "novice|skilled|foreign",
                     "the simulated writer's profile (docs/writer.md)"},
      TrialSpecField{"writer_parameters", "--writer-param", "KEY=VALUE",
                     "set a field of the simulated writer's profile (repeatable; keys: docs/writer.md)",
                     true},
      TrialSpecField{"seed", "--seed", "N", "seed of the simulated writer (a 64-bit integer)"},
      TrialSpecField{"rate_hz", "--rate", "HZ",
                     "servo rate [Hz], in [100, 100000] (real time: at most 10000)"},
      TrialSpecField{"pacing", "--pacing", "auto|lock-step|real-time",
                     "auto: lock-step for devices a simulated writer moves, real time for any other"},
      TrialSpecField{"realtime", "--realtime", "enforce|ignore",
                     "real-time pacing: fail unless SCHED_FIFO, CPU pinning and locked memory are obtained "
                     "(enforce)"},
      TrialSpecField{"watchdog_s", "--watchdog-ms", "MS",
                     "real-time pacing: end the trial when the device holds one force longer than this [ms], "
                     "0..60000; 0: off (JSON: watchdog_s in s)"},
      TrialSpecField{"max_duration_s", "--max-duration", "S", "the trial ends after this much time [s]"},
      TrialSpecField{"json_file", "--json", "FILE", "write the metrics as JSON ('-': standard output)"},
      TrialSpecField{"csv_file", "--csv", "FILE",
                     "write the trace (t,x,y,z,fx,fy,fz,state,stroke,element; s, m, N) as CSV ('-': standard "
                     "output)"},
      TrialSpecField{"svg_file", "--svg", "FILE",
                     "draw the reference and the pen trace as SVG ('-': standard output)"},
      TrialSpecField{
          "record_file", "--record", "FILE",
          "write the trial as a teacher's recording for --guidance-mode replay (a trial that wrote "
          "every stroke in order)"},
  };
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

double parse_number(std::string_view key, std::string_view text) {
  const std::optional<double> value = parse_finite_double(text);
  if (!value) refuse(key, "'" + std::string(text) + "' is not a finite number");
  return *value;
}

std::uint64_t parse_unsigned(std::string_view key, std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    refuse(key, "'" + std::string(text) + "' is not an integer in 0..18446744073709551615");
  }
  return value;
}

std::string number_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

const char* to_string(RealtimeMode mode) noexcept {
  return mode == RealtimeMode::enforce ? "enforce" : "ignore";
}

// A guidance law's parameter held by the specification, checked by the law's own table entry (one
// definition of each range), the error naming both the specification's field and the law's.
template <typename Law>
void check_law_parameter(std::string_view key, double Law::*member, double value) {
  try {
    check_parameter(member, value);
  } catch (const InvalidArgument& e) {
    refuse(key, e.what());
  }
}

template <typename Enum, std::size_t N>
Enum parse_choice(std::string_view key, std::string_view text, const std::array<Enum, N>& choices) {
  std::string spellings;
  for (const Enum choice : choices) {
    if (text == to_string(choice)) return choice;
    spellings += (spellings.empty() ? "'" : ", '") + std::string(to_string(choice)) + "'";
  }
  refuse(key, "'" + std::string(text) + "' is not one of " + spellings);
}

}  // namespace

double default_watchdog_s(bool hardware_device) noexcept {
  return hardware_device ? TrialSpec{}.watchdog_s : 0.0;
}

const char* to_string(TrialWriter writer) noexcept {
  switch (writer) {
    case TrialWriter::person:
      return "person";
    case TrialWriter::simulated:
      return "simulated";
    case TrialWriter::automatic:
      break;
  }
  return "auto";
}

namespace {

// The numeric fields by key: the JSON form reads and writes them as JSON numbers (no text in between), the
// command line parses their text; validate() checks their ranges either way.
constexpr std::array<std::pair<std::string_view, double TrialSpec::*>, 6> kNumberFields{{
    {"guidance_gain", &TrialSpec::guidance_gain},
    {"assist_band_m", &TrialSpec::assist_band_m},
    {"amplification_gain", &TrialSpec::amplification_gain},
    {"timing_speed_m_s", &TrialSpec::timing_speed_m_s},
    {"rate_hz", &TrialSpec::rate_hz},
    {"max_duration_s", &TrialSpec::max_duration_s},
}};

double TrialSpec::*number_member(std::string_view key) {
  for (const auto& [name, member] : kNumberFields) {
    if (name == key) return member;
  }
  return nullptr;
}

}  // namespace

std::span<const TrialSpecField> trial_spec_fields() { return fields_in_order(); }

void set_trial_spec_field(TrialSpec& spec, std::string_view name, std::string_view text) {
  const std::string_view key = field_named(name).key;
  if (key == "characters") {
    spec.characters = text;
  } else if (key == "device") {
    spec.device = text;
  } else if (key == "guidance") {
    if (text != "on" && text != "off") refuse(key, "'" + std::string(text) + "' is not one of 'on', 'off'");
    spec.guidance = text == "on";
  } else if (key == "guidance_mode") {
    spec.guidance_mode = parse_choice(
        key, text,
        std::array{GuidanceMode::fixed, GuidanceMode::fading, GuidanceMode::replay,
                   GuidanceMode::assist_as_needed, GuidanceMode::error_amplification, GuidanceMode::timing});
  } else if (double TrialSpec::*number = number_member(key)) {
    spec.*number = parse_number(key, text);
  } else if (key == "teacher") {
    spec.teacher = text;
  } else if (key == "writer") {
    spec.writer = parse_choice(
        key, text, std::array{TrialWriter::automatic, TrialWriter::person, TrialWriter::simulated});
  } else if (key == "writer_profile") {
    spec.writer_profile = text;
  } else if (key == "writer_parameters") {
    try {
      spec.writer_parameters.push_back(parse_writer_setting(text));
    } catch (const InvalidArgument& e) {
      refuse(key, e.what());
    }
  } else if (key == "seed") {
    spec.seed = parse_unsigned(key, text);
  } else if (key == "pacing") {
    spec.pacing = parse_choice(
        key, text, std::array{TrialPacing::automatic, TrialPacing::lock_step, TrialPacing::real_time});
  } else if (key == "realtime") {
    spec.realtime = parse_choice(key, text, std::array{RealtimeMode::enforce, RealtimeMode::ignore});
  } else if (key == "watchdog_s") {
    // Whole milliseconds on the command line, as the servo loop's stall bound has always been given there.
    const std::uint64_t ms = parse_unsigned(key, text);
    if (ms > 60000) refuse(key, "'" + std::string(text) + "' ms is outside 0..60000");
    spec.watchdog_s = static_cast<double>(ms) / 1000.0;
  } else if (key == "json_file") {
    spec.json_file = text;
  } else if (key == "csv_file") {
    spec.csv_file = text;
  } else if (key == "svg_file") {
    spec.svg_file = text;
  } else if (key == "record_file") {
    spec.record_file = text;
  }
}

std::vector<std::string> trial_spec_field_text(const TrialSpec& spec, std::string_view name) {
  const std::string_view key = field_named(name).key;
  if (key == "characters") return {spec.characters};
  if (key == "device") return {spec.device};
  if (key == "guidance") return {spec.guidance ? "on" : "off"};
  if (key == "guidance_mode") return {to_string(spec.guidance_mode)};
  if (key == "guidance_gain") return {number_text(spec.guidance_gain)};
  if (key == "assist_band_m") return {number_text(spec.assist_band_m)};
  if (key == "amplification_gain") return {number_text(spec.amplification_gain)};
  if (key == "timing_speed_m_s") return {number_text(spec.timing_speed_m_s)};
  if (key == "teacher") return {spec.teacher};
  if (key == "writer") return {to_string(spec.writer)};
  if (key == "writer_profile") return {spec.writer_profile};
  if (key == "writer_parameters") {
    std::vector<std::string> texts;
    for (const WriterSetting& setting : spec.writer_parameters) texts.push_back(writer_setting_text(setting));
    return texts;
  }
  if (key == "seed") return {std::to_string(spec.seed)};
  if (key == "rate_hz") return {number_text(spec.rate_hz)};
  if (key == "pacing") return {to_string(spec.pacing)};
  if (key == "realtime") return {to_string(spec.realtime)};
  if (key == "watchdog_s") return {std::to_string(std::llround(spec.watchdog_s * 1000.0))};
  if (key == "max_duration_s") return {number_text(spec.max_duration_s)};
  if (key == "json_file") return {spec.json_file};
  if (key == "csv_file") return {spec.csv_file};
  if (key == "svg_file") return {spec.svg_file};
  return {spec.record_file};
}

void TrialSpec::validate(TeacherSource teacher_from) const {
  std::u32string decoded;
  try {
    decoded = decode_utf8(characters);
  } catch (const Error& e) {
    refuse("characters", e.what());
  }
  if (decoded.empty()) refuse("characters", "no character to write");
  try {
    check_scene_size(decoded.size(), "characters");
  } catch (const InvalidArgument& e) {
    refuse("characters", e.what());
  }
  if (device.empty()) refuse("device", "no device named");
  if (!guidance && guidance_mode != GuidanceMode::fixed) {
    refuse("guidance_mode", std::string("'") + calligraphy::to_string(guidance_mode) +
                                "' needs guidance on (guidance is off)");
  }
  check_law_parameter("guidance_gain", &FadingGuidance::gain, guidance_gain);
  if (guidance_gain != 1.0 && guidance_mode != GuidanceMode::fading) {
    refuse("guidance_gain", "applies to guidance mode 'fading' only");
  }
  // Each mode's own parameter: in its law's range, and given only with its mode (a value nothing reads is
  // a mistake).
  const TrialSpec defaults;
  check_law_parameter("assist_band_m", &AssistAsNeededGuidance::band_m, assist_band_m);
  if (assist_band_m != defaults.assist_band_m && guidance_mode != GuidanceMode::assist_as_needed) {
    refuse("assist_band_m", "applies to guidance mode 'assist-as-needed' only");
  }
  check_law_parameter("amplification_gain", &ErrorAmplificationGuidance::gain, amplification_gain);
  if (amplification_gain != defaults.amplification_gain &&
      guidance_mode != GuidanceMode::error_amplification) {
    refuse("amplification_gain", "applies to guidance mode 'error-amplification' only");
  }
  check_law_parameter("timing_speed_m_s", &TimingGuidance::speed_m_s, timing_speed_m_s);
  if (timing_speed_m_s != defaults.timing_speed_m_s && guidance_mode != GuidanceMode::timing) {
    refuse("timing_speed_m_s", "applies to guidance mode 'timing' only");
  }
  if (guidance_mode == GuidanceMode::replay && teacher.empty() && teacher_from == TeacherSource::file) {
    refuse("teacher", "required with guidance mode 'replay' (a recording made with --record)");
  }
  if (!teacher.empty() && teacher_from == TeacherSource::samples) {
    refuse("teacher", "the teacher is given as samples; the file would not be read");
  }
  if (!teacher.empty() && guidance_mode != GuidanceMode::replay) {
    refuse("teacher", "applies to guidance mode 'replay' only");
  }
  if (writer == TrialWriter::person && writer_profile != TrialSpec{}.writer_profile) {
    refuse("writer_profile", "applies to the simulated writer, not to a person (writer 'person')");
  }
  if (writer == TrialWriter::person && !writer_parameters.empty()) {
    refuse("writer_parameters", "apply to the simulated writer, not to a person (writer 'person')");
  }
  // The profile's name and its settings' keys and ranges are the simulated writer's to check (sim's
  // writer_profile_of, when it is made); here, only what any writer needs.
  if (writer_profile.empty()) refuse("writer_profile", "no profile named");
  for (const WriterSetting& setting : writer_parameters) {
    if (setting.key.empty() || !std::isfinite(setting.value))
      refuse("writer_parameters", "'" + writer_setting_text(setting) + "' is not a key and a finite number");
  }
  const bool real_time = pacing == TrialPacing::real_time;
  if (!servo_rate_allowed(rate_hz, real_time)) {
    refuse("rate_hz", number_text(rate_hz) + " Hz is outside " + servo_rate_range_text(real_time) +
                          (real_time ? " (real-time pacing)" : ""));
  }
  if (!(watchdog_s >= 0.0 && watchdog_s <= 60.0) ||
      watchdog_s != static_cast<double>(std::llround(watchdog_s * 1000.0)) / 1000.0) {
    refuse("watchdog_s", number_text(watchdog_s) + " s is not a whole number of milliseconds in [0, 60] s");
  }
  if (pacing == TrialPacing::lock_step && watchdog_s != TrialSpec{}.watchdog_s) {
    refuse("watchdog_s", "applies to real-time pacing only (lock-step has no wall clock to bound)");
  }
  if (!(max_duration_s > 0.0 && max_duration_s <= 86400.0)) {
    refuse("max_duration_s", number_text(max_duration_s) + " is outside (0, 86400]");
  }
  // A trace longer than this would not fit a trial's memory (one sample per tick).
  if (rate_hz * max_duration_s > kMaxTrialTicks) {
    refuse("max_duration_s", number_text(max_duration_s) + " s at " + number_text(rate_hz) +
                                 " Hz is more than 10^7 servo ticks");
  }
  // Outputs on one file are the front-end's to find (after resolving links: the CLI's file plan).
  if (record_file == "-")
    refuse("record_file", "a teacher's recording goes to a file, not to standard output");
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

Checked<TrialSpec> trial_spec_from_object(const json& document, const std::string& at_pointer,
                                          const std::string& source, TeacherSource teacher_from) {
  json_detail::ObjectReader reader(document, at_pointer, source);
  TrialSpec spec;
  for (const TrialSpecField& field : fields_in_order()) {
    const std::string key(field.key);
    const json* value = reader.optional(key);
    if (value == nullptr) continue;
    const std::string pointer = reader.pointer(key);
    // Numbers, booleans and the seed are taken as the JSON values they are; text fields go through the one
    // parser of the text forms (choices checked there).
    const auto set = [&](const json& item, const std::string& at) {
      const auto expect = [&](bool ok, const char* what) {
        if (!ok)
          json_detail::fail(source, at,
                            std::string("expected ") + what + ", got " + json_detail::describe(item));
      };
      if (key == "guidance") {
        expect(item.is_boolean(), "true or false");
        spec.guidance = item.get<bool>();
      } else if (key == "seed") {
        expect(item.is_number_unsigned(), "an integer >= 0");
        spec.seed = item.get<std::uint64_t>();
      } else if (key == "watchdog_s") {
        expect(item.is_number(), "a number");
        const double s = item.get<double>();
        if (!(s >= 0.0 && s <= 60.0) || std::abs(s * 1000.0 - std::round(s * 1000.0)) > 1e-6) {
          json_detail::fail(source, at, "expected a whole number of milliseconds in [0, 60] s");
        }
        spec.watchdog_s = s;
      } else if (double TrialSpec::*number = number_member(key)) {
        expect(item.is_number(), "a number");
        spec.*number = item.get<double>();
      } else if (key == "writer_parameters" && item.is_object()) {  // {"key": name, "value": number}
        json_detail::ObjectReader setting(item, at, source);
        constexpr double kLargest = std::numeric_limits<double>::max();
        spec.writer_parameters.push_back(
            WriterSetting{setting.string("key"), setting.number("value", -kLargest, kLargest)});
        setting.finish();
      } else {  // text fields, and a setting written as "key=value" (records before settings were typed)
        try {
          set_trial_spec_field(spec, key, json_detail::as_string(item, at, source));
        } catch (const InvalidArgument& e) {
          json_detail::fail(source, at, e.what());
        }
      }
    };
    if (field.repeated) {
      if (!value->is_array())
        json_detail::fail(source, pointer, "expected an array, got " + json_detail::describe(*value));
      for (std::size_t i = 0; i < value->size(); ++i)
        set((*value)[i], json_detail::child_pointer(pointer, i));
    } else {
      set(*value, pointer);
    }
  }
  reader.finish();
  return Checked<TrialSpec>::check(std::move(spec), teacher_from);
}

}  // namespace trial_detail

Checked<TrialSpec> trial_spec_from_json(std::string_view text, const std::string& source,
                                        TeacherSource teacher_from) {
  return trial_detail::trial_spec_from_object(json_detail::parse_json(text, source), "", source,
                                              teacher_from);
}

std::string trial_spec_json(const TrialSpec& spec) {
  nlohmann::ordered_json document = nlohmann::ordered_json::object();  // in field order
  for (const TrialSpecField& field : fields_in_order()) {
    const std::string key(field.key);
    if (key == "guidance") {
      document[key] = spec.guidance;
    } else if (key == "seed") {
      document[key] = spec.seed;
    } else if (key == "watchdog_s") {
      document[key] = spec.watchdog_s;
    } else if (double TrialSpec::*number = number_member(key)) {
      document[key] = spec.*number;
    } else if (field.repeated) {  // the writer's settings, numbers as numbers
      document[key] = nlohmann::ordered_json::array();
      for (const WriterSetting& setting : spec.writer_parameters)
        document[key].push_back({{"key", setting.key}, {"value", setting.value}});
    } else {
      document[key] = trial_spec_field_text(spec, key).front();
    }
  }
  return document.dump(2) + "\n";
}

}  // namespace calligraphy
