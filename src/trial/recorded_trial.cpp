#include "calligraphy/trial/recorded_trial.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/sha256.hpp"
#include "core/json_document.hpp"
#include "core/json_reader.hpp"
#include "core/schema_json.hpp"
#include "core/whole_file.hpp"
#include "trial/record_schema.hpp"
#include "trial/recorded_trial_object.hpp"
#include "trial/trial_spec_object.hpp"

#ifndef CALLIGRAPHY_VERSION
#error "CALLIGRAPHY_VERSION must be defined (from PROJECT_VERSION)"
#endif

namespace calligraphy {
namespace {

using nlohmann::json;

// The first version whose writer settings are {"key", "value"} objects; version 1 wrote "key=value" text.
constexpr int kTypedWriterSettingsVersion = 2;

// Runs `check` (a struct's validate()) and names the object at `pointer` when it refuses.
template <typename Check>
void checked(const std::string& source, const std::string& pointer, Check&& check) {
  try {
    check();
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, pointer, e.what());
  }
}

void append_bits(std::string& bytes, double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  for (int shift = 0; shift < 64; shift += 8) bytes.push_back(static_cast<char>((bits >> shift) & 0xFF));
}

// A replay that names its teacher's recording file: the record binds it by the file's SHA-256. (A teacher
// given as samples names no file.)
bool names_teacher_file(const TrialSpec& spec) noexcept {
  return spec.guidance && spec.guidance_mode == GuidanceMode::replay && !spec.teacher.empty();
}

}  // namespace

RecordedTrial recorded_trial(const TrialSpec& spec, const TrialOptions& ran, const WriterProfile* writer,
                             const Scene& scene, const std::string& teacher_sha256) {
  // read_recorded_trial refuses a replay naming its teacher's file without the file's SHA-256.
  const bool names_file = names_teacher_file(spec);
  if (names_file && teacher_sha256.empty()) {
    throw InvalidArgument("recorded_trial: the replay names its teacher's recording (spec.teacher " +
                          spec.teacher +
                          "): give that file's SHA-256 (teacher_sha256, read_recorded_teacher)");
  }
  if (!teacher_sha256.empty() && (!names_file || !is_sha256_hex(teacher_sha256))) {
    throw InvalidArgument("recorded_trial: teacher_sha256 '" + teacher_sha256 +
                          "' is not 64 lower-case hex digits of a teacher's file the replay names");
  }
  RecordedTrial recorded;
  recorded.teacher_sha256 = teacher_sha256;
  recorded.spec = spec;
  recorded.spec.json_file.clear();
  recorded.spec.csv_file.clear();
  recorded.spec.svg_file.clear();
  recorded.spec.record_file.clear();
  // Who wrote and how it was paced, as it turned out ("auto" names the device's own writer, and lock-step
  // exactly when that is the simulated writer): the same trial either way.
  recorded.spec.writer = writer != nullptr ? TrialWriter::simulated : TrialWriter::person;
  if (recorded.spec.pacing == TrialPacing::automatic)
    recorded.spec.pacing = writer != nullptr ? TrialPacing::lock_step : TrialPacing::real_time;
  recorded.force_law = ran.force;
  // The specification states the acceptance the trial ran with: a caller's force law's (a study condition's
  // quiz) replaces the one stated.
  recorded.spec.acceptance = ran.force.acceptance;
  if (auto* replay = std::get_if<ReplayGuidance>(&recorded.force_law.guidance_law))
    replay->teacher_trajectory.clear();  // the teacher is named by the specification, not copied
  recorded.safety = ran.safety;
  recorded.passivity = ran.passivity;
  if (writer != nullptr) recorded.writer = *writer;
  recorded.layout = scene.layout;
  recorded.scene_sha256 = scene_sha256(scene);
  recorded.library_version = CALLIGRAPHY_VERSION;
  return recorded;
}

namespace {

// The bytes of the placed characters' models: code points, typical stroke IDs, attraction factors and the
// elements' control points [m], as bit patterns.
std::string model_bytes(const Scene& scene, bool with_medians) {
  std::string bytes;
  for (const PlacedCharacter& c : scene.characters) {
    append_bits(bytes, static_cast<double>(c.code_point));
    for (const PlacedStroke& s : c.strokes) {
      append_bits(bytes, static_cast<double>(s.typical_id));
      for (double a : s.attraction_factors) append_bits(bytes, a);
      for (const StrokeElement& e : s.elements) {
        append_bits(bytes, static_cast<double>(e.degree));
        for (int i = 0; i < e.point_count(); ++i) {
          append_bits(bytes, e.control[static_cast<std::size_t>(i)].x());
          append_bits(bytes, e.control[static_cast<std::size_t>(i)].y());
        }
      }
      if (!with_medians) continue;
      // The median too: progress is measured along it (its point count first, 0 for none, so that
      // characters without medians differ from those with them).
      append_bits(bytes, static_cast<double>(s.median_m.size()));
      for (const Vec2& p : s.median_m) {
        append_bits(bytes, p.x());
        append_bits(bytes, p.y());
      }
    }
  }
  return bytes;
}

}  // namespace

std::string scene_sha256(const Scene& scene) { return sha256_hex(model_bytes(scene, true)); }

std::string scene_models_sha256(const Scene& scene) { return sha256_hex(model_bytes(scene, false)); }

bool scene_is_recorded_one(const Scene& scene, const std::string& recorded_sha256) {
  return recorded_sha256 == scene_sha256(scene) || recorded_sha256 == scene_models_sha256(scene);
}

namespace trial_detail {

nlohmann::json simulated_device_object(const SimulatedDeviceParameters& p) {
  return schema_detail::to_json(SchemaOf<SimulatedDeviceParameters>::get(), &p);
}

nlohmann::json recorded_trial_object(const RecordedTrial& r) {
  RecordDocument document;
  document.format = kRecordedTrialFormat;
  document.version = kRecordedTrialVersion;
  document.trial = r.spec;
  document.force_law = r.force_law;
  document.safety = r.safety;
  document.passivity = r.passivity;
  document.writer = r.writer;
  document.simulated_device = r.simulated_device;
  document.scene = {r.layout, r.scene_sha256};
  document.library_version = r.library_version;
  document.teacher_sha256 = r.teacher_sha256;
  return schema_detail::to_json(recorded_trial_schema(), &document);
}

}  // namespace trial_detail

const Schema& recorded_trial_schema() { return SchemaOf<trial_detail::RecordDocument>::get(); }

std::string recorded_trial_json_schema_text() {
  nlohmann::ordered_json root = nlohmann::ordered_json::parse(
      json_schema_text(recorded_trial_schema(), "https://calligraphy.invalid/schema/record.json",
                       "calligraphy trial record (its \"specification\" object)", true));
  // A writer setting may be the text version 1 wrote, which the reader reads as --writer-param does; since
  // version 2 only the object.
  nlohmann::ordered_json& settings = root["$defs"]["TrialSpec"]["properties"]["writer_parameters"];
  const nlohmann::ordered_json as_text = {
      {"type", "string"},
      {"pattern", std::string(kWriterSettingTextPattern)},
      {"description", "a setting as version 1 wrote it, \"key=value\" (--writer-param's form)"}};
  settings["items"] = {{"anyOf", nlohmann::ordered_json::array({settings["items"], as_text})}};
  root["allOf"].push_back(
      {{"if",
        {{"properties", {{"version", {{"minimum", kTypedWriterSettingsVersion}}}}},
         {"required", {"version"}}}},
       {"then",
        {{"properties",
          {{"trial", {{"properties", {{"writer_parameters", {{"items", {{"type", "object"}}}}}}}}}}}}}});
  return root.dump(2) + "\n";
}

std::string recorded_trial_json(const RecordedTrial& r) {
  return json_text(trial_detail::recorded_trial_object(r), 2) + "\n";
}

namespace trial_detail {

namespace {

// The versions a record's specification may have, as its errors name them ("1 to 9").
std::string versions_read_text() {
  return std::to_string(kOldestRecordedTrialVersion) + " to " + std::to_string(kRecordedTrialVersion);
}

}  // namespace

RecordedTrial read_recorded_document(const json& document, const std::string& source) {
  std::string at;  // the specification object's pointer in the document
  const json* object = &document;
  const bool is_specification =
      document.is_object() && document.contains("format") && document["format"] == kRecordedTrialFormat;
  if (document.is_object() && document.contains("specification")) {
    at = "/specification";
    object = &document["specification"];
  } else if (!is_specification) {
    const bool has_format =
        document.is_object() && document.contains("format") && document["format"].is_string();
    json_detail::fail(
        source, "/",
        "no trial specification" +
            (has_format ? " (format '" + document["format"].get<std::string>() + "')" : std::string()) +
            ": a record written before records held one (\"specification\"), or not a trial record");
  }
  if (object->is_null())
    json_detail::fail(source, at.empty() ? "/" : at, "the record holds no specification");
  json_detail::ObjectReader reader(*object, at, source);
  const std::string format = reader.string("format");
  if (format != kRecordedTrialFormat) {
    json_detail::fail(source, reader.pointer("format"),
                      "format '" + format + "' is not '" + std::string(kRecordedTrialFormat) + "'");
  }
  const std::string versions_read = versions_read_text();
  std::int64_t version = 0;
  try {
    version = reader.integer("version", 0, std::numeric_limits<std::int64_t>::max());
  } catch (const DataError&) {
    if (!object->is_object() || !object->contains("version")) throw;  // missing: named as such
    // Text, null, a fraction, a negative or a 65-bit number is no version: say which this library reads.
    json_detail::fail(source, reader.pointer("version"),
                      "expected a version this library reads (" + versions_read + "), got " +
                          json_detail::describe((*object)["version"]));
  }
  if (version < kOldestRecordedTrialVersion || version > kRecordedTrialVersion) {
    json_detail::fail(
        source, reader.pointer("version"),
        "version " + std::to_string(version) + " is not one this library reads (" + versions_read + ")");
  }
  // Every part is required, read by the record's one schema (record_schema.hpp): a value out of its field's
  // range, null, an unknown key or a missing part is refused naming its pointer; a field added in a later
  // version than the record's takes its default, and the record says which (RecordedTrial::defaulted).
  // Only a record whose writer settings are "key=value" text (version 1) is read from a typed copy: a study's
  // readers read every record's specification, and copying it is as dear as reading it.
  const auto text_settings = [](const json& part) {
    const auto trial = part.find("trial");
    if (trial == part.end() || !trial->is_object()) return false;
    const auto settings = trial->find("writer_parameters");
    return settings != trial->end() && settings->is_array() &&
           std::any_of(settings->begin(), settings->end(), [](const json& item) { return item.is_string(); });
  };
  json typed;
  if (version < kTypedWriterSettingsVersion && object->is_object() && text_settings(*object)) {
    typed = *object;
    trial_detail::type_writer_settings(typed["trial"], reader.pointer("trial"), source);
  }
  const json& normalized = typed.is_null() ? *object : typed;
  trial_detail::RecordDocument parts;
  SchemaReadResult read;
  schema_detail::from_json(recorded_trial_schema(), &parts, normalized, at, source,
                           {.require_all = true, .version = static_cast<int>(version)}, read);
  RecordedTrial r;
  r.spec = std::move(parts.trial);
  try {
    // A replay whose teacher was given as samples (a session's, kept in its folder) names no file.
    r.spec.validate(r.spec.teacher.empty() ? TeacherSource::samples : TeacherSource::file);
  } catch (const InvalidTrialSpecField& e) {
    json_detail::fail(source, json_detail::child_pointer(reader.pointer("trial"), e.key()), e.what());
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, reader.pointer("trial"), e.what());
  }
  r.force_law = std::move(parts.force_law);
  const StrokeAcceptance law_as_read = r.force_law.acceptance;
  const StrokeAcceptance spec_as_read = r.spec.acceptance;
  // Before version 4 a stroke's tolerances did not grow with its length or scale with the character, and
  // no stroke was credited as assisted: an older record runs again as it ran.
  if (version < 4) r.force_law.acceptance.use_fixed_tolerances();
  // Before version 5 either end of a stroke could be left unwritten by no more than its shortfall or
  // displacement: no floor of the end gap.
  if (version < 5) r.force_law.acceptance.use_version_4_end_gaps();
  // Before version 7 no path centred on a dot was written by covering less of it than the shortfall allows:
  // the rule is off, as it ran.
  if (version < 7) {
    r.force_law.acceptance.use_version_6_coverage();
    r.spec.acceptance.use_version_6_coverage();
  }
  // Before version 8 a refused pen-down was a miss only when lifted in WS: one that never came near the
  // stroke's start was no miss, as it ran.
  if (version < 8) {
    r.force_law.acceptance.use_version_7_misses();
    r.spec.acceptance.use_version_7_misses();
  }
  // A field those rules set takes the version's value, not its default and not another value the record
  // gives: each is listed with the value it takes (RecordedTrial::version_rules), never as defaulted. Before
  // version 6 the specification's acceptance is the force law's (below), so only the force law's are listed.
  const auto list_rules = [&](const std::string& at_acceptance, const StrokeAcceptance& as_read,
                              const StrokeAcceptance& runs) {
    for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields()) {
      if (as_read.*field.member == runs.*field.member) continue;
      std::string pointer = json_detail::child_pointer(at_acceptance, std::string(field.name));
      const bool left_out = std::erase(read.defaulted, pointer) > 0;
      r.version_rules.push_back(
          {.pointer = std::move(pointer),
           .taken = runs.*field.member,
           .given = left_out ? std::nullopt : std::optional<double>(as_read.*field.member),
           .version = static_cast<int>(version)});
    }
  };
  list_rules(json_detail::child_pointer(reader.pointer("force_law"), "acceptance"), law_as_read,
             r.force_law.acceptance);
  if (version >= 6) list_rules(reader.pointer("trial"), spec_as_read, r.spec.acceptance);
  // Since version 6 the specification states the acceptance its force law ran with: a field that differs
  // (a record edited in one place) leaves no way to tell which ran, so it is refused at the specification's
  // field, naming the force law's.
  if (version >= 6) {
    for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields()) {
      const double stated = r.spec.acceptance.*field.member + 0.0;  // -0 is said as 0
      const double ran = r.force_law.acceptance.*field.member + 0.0;
      if (stated == ran) continue;
      const std::string law_pointer = json_detail::child_pointer(
          json_detail::child_pointer(reader.pointer("force_law"), "acceptance"), std::string(field.name));
      json_detail::fail(source, json_detail::child_pointer(reader.pointer("trial"), std::string(field.name)),
                        shortest_decimal(stated) + ", but the force law's acceptance states " +
                            shortest_decimal(ran) + " (" + law_pointer +
                            "): a record states the acceptance its trial ran with in both, the same");
    }
  }
  // Before version 6 the specification did not state the acceptance: it is the one the force law ran with,
  // not a default (its fields are not listed as defaulted).
  if (version < 6) {
    r.spec.acceptance = r.force_law.acceptance;
    const std::string trial = reader.pointer("trial");
    std::erase_if(read.defaulted, [&](const std::string& pointer) {
      for (const ParameterField<StrokeAcceptance>& field : ParameterTable<StrokeAcceptance>::fields()) {
        std::string stated = trial;
        stated.append("/").append(field.name);
        if (pointer == stated) return true;
      }
      return false;
    });
  }
  checked(source, reader.pointer("force_law"), [&] {
    // A replay's teacher is not in the record (the run is given it, and checks it then): its law's own
    // values are checked here with a stand-in trajectory of two samples.
    ForceLawParameters check = r.force_law;
    if (auto* replay = std::get_if<ReplayGuidance>(&check.guidance_law))
      replay->teacher_trajectory = {TeacherSample{0.0, Vec3::Zero()}, TeacherSample{1.0, Vec3::Zero()}};
    check.validate();
    if (r.force_law.guidance != r.spec.guidance ||
        (r.spec.guidance && mode_of(r.force_law.guidance_law) != r.spec.guidance_mode)) {
      throw InvalidArgument(
          "its guidance is not the specification's (/trial/guidance, /trial/guidance_mode)");
    }
  });
  // The guidance mode's own value is stated in the specification and in the force law's guidance_law, which
  // the renderer ran: a record edited in one place leaves no way to tell which ran, so it is refused at the
  // specification's field, naming the force law's (a value the record leaves out is the law's, not stated).
  if (r.spec.guidance) {
    const auto same = [&](const char* field, double stated, const char* law_field, double ran) {
      const std::string stated_at = json_detail::child_pointer(reader.pointer("trial"), field);
      if (stated + 0.0 == ran + 0.0 ||
          std::find(read.defaulted.begin(), read.defaulted.end(), stated_at) != read.defaulted.end())
        return;
      const std::string law_pointer = json_detail::child_pointer(
          json_detail::child_pointer(reader.pointer("force_law"), "guidance_law"), law_field);
      json_detail::fail(source, stated_at,
                        shortest_decimal(stated) + ", but the force law's guidance states " +
                            shortest_decimal(ran) + " (" + law_pointer +
                            "): a record states the value its trial ran with in both, the same");
    };
    if (const auto* fading = std::get_if<FadingGuidance>(&r.force_law.guidance_law))
      same("guidance_gain", r.spec.guidance_gain, "gain", fading->gain);
    if (const auto* band = std::get_if<AssistAsNeededGuidance>(&r.force_law.guidance_law))
      same("assist_band_m", r.spec.assist_band_m, "band_m", band->band_m);
    if (const auto* amplified = std::get_if<ErrorAmplificationGuidance>(&r.force_law.guidance_law))
      same("amplification_gain", r.spec.amplification_gain, "gain", amplified->gain);
    if (const auto* timing = std::get_if<TimingGuidance>(&r.force_law.guidance_law))
      same("timing_speed_m_s", r.spec.timing_speed_m_s, "speed_m_s", timing->speed_m_s);
  }
  r.safety = parts.safety;
  r.passivity = parts.passivity;
  r.writer = std::move(parts.writer);
  r.simulated_device = std::move(parts.simulated_device);
  r.layout = parts.scene.layout;
  r.scene_sha256 = std::move(parts.scene.sha256);
  r.library_version = std::move(parts.library_version);
  if (!parts.teacher_sha256.empty() && !is_sha256_hex(parts.teacher_sha256)) {
    json_detail::fail(source, reader.pointer("teacher_sha256"),
                      "expected 64 lower-case hex digits (a SHA-256) or \"\"");
  }
  if (!parts.teacher_sha256.empty() && !(r.spec.guidance && r.spec.guidance_mode == GuidanceMode::replay))
    json_detail::fail(source, reader.pointer("teacher_sha256"),
                      "names a teacher, but the trial is not a replay");
  // Since version 4 a replay that names its teacher's file states that file's SHA-256: without it the record
  // would re-run on whatever file has the name.
  if (version >= 4 && parts.teacher_sha256.empty() && names_teacher_file(r.spec)) {
    json_detail::fail(source, reader.pointer("teacher_sha256"),
                      "\"\", but the replay names its teacher's recording (/trial/teacher " + r.spec.teacher +
                          "): a record of version 4 or later states that file's SHA-256");
  }
  r.teacher_sha256 = std::move(parts.teacher_sha256);
  // A whole record states what its run gave beside its specification: kept for the re-run to compare.
  if (!at.empty()) {
    const auto keep = [&](std::string_view name) {
      const auto value = document.find(std::string(name));
      if (value != document.end()) r.recorded_outcome.emplace_back(std::string(name), value->dump());
    };
    keep("end_reason");
    for (const MetricInfo& info : metric_table()) {
      if (info.at(metric_level_run)) keep(info.name);
    }
  }
  // The parts a trial's builder takes only for some trials are refused here, as content of the record at
  // their pointer, before a device is looked up: a simulated writer's profile on a person's trial, and the
  // physics of a simulated device on another device.
  if (r.writer && r.spec.writer == TrialWriter::person)
    json_detail::fail(source, reader.pointer("trial") + "/writer",
                      "'person', but the record holds a simulated writer's profile (/writer, null for a "
                      "person)");
  if (!r.writer && r.spec.writer == TrialWriter::simulated)
    json_detail::fail(source, reader.pointer("writer"),
                      "null, but the trial's writer is 'simulated' (/trial/writer): a simulated writer's "
                      "record holds the profile it wrote with");
  // The settings are the writer's own keys, as --writer-param and Python take them: the re-run writes with
  // the recorded profile (/writer) and never applies them, so an unknown key would otherwise pass unread.
  for (std::size_t i = 0; i < r.spec.writer_parameters.size(); ++i) {
    try {
      (void)writer_parameter(*r.writer, r.spec.writer_parameters[i].key);
    } catch (const InvalidArgument& e) {
      json_detail::fail(source,
                        json_detail::child_pointer(
                            json_detail::child_pointer(reader.pointer("trial"), "writer_parameters"), i),
                        e.what());
    }
  }
  if (r.simulated_device && r.spec.device != "simulated") {
    std::string message = "simulated device physics for the device '";
    message.append(r.spec.device).append("' (/trial/device; only for 'simulated'); expected null");
    json_detail::fail(source, reader.pointer("simulated_device"), message);
  }
  r.defaulted = std::move(read.defaulted);
  return r;
}

json parse_record_text(std::string_view text, const std::string& source) {
  try {
    return json_detail::parse_json(text, source);
  } catch (const json_detail::NumberOverflow& e) {
    // Only the specification's own: a study record's top-level version reads other numbers.
    if (e.pointer() != "/specification/version") throw;
    json_detail::fail(
        source, e.pointer(),
        "version " + e.literal() + " is not one this library reads (" + versions_read_text() + ")");
  }
}

}  // namespace trial_detail

RecordedTrial read_recorded_trial(std::string_view text, const std::string& source) {
  return trial_detail::read_recorded_document(trial_detail::parse_record_text(text, source), source);
}

RecordedTrial read_recorded_trial_file(const std::string& path) {
  const std::string text = read_regular_file(path, kMaxRecordedTrialBytes);
  // Read whole: what is refused now is the record's content, the input the command was given.
  try {
    return trial_detail::read_recorded_document(trial_detail::parse_record_text(text, path), path);
  } catch (const InputError&) {
    throw;
  } catch (const DataError& e) {
    throw InputError(e.what());
  }
}

TeacherFile read_recorded_teacher(const RecordedTrial& recorded, const std::filesystem::path& path) {
  const std::string bytes = read_regular_file(path, kMaxTeacherRecordingBytes);
  const std::string sha256 = sha256_hex(bytes);
  if (!recorded.teacher_sha256.empty() && sha256 != recorded.teacher_sha256) {
    throw DataError(path.string() + ": SHA-256 " + sha256 +
                    ", but the replay ran on a teacher's recording of SHA-256 " + recorded.teacher_sha256 +
                    " (the record's teacher_sha256): give the recording it ran on (--teacher)");
  }
  return {parse_teacher_recording(bytes, path.string()), sha256};
}

TeacherFile read_record_named_teacher(const RecordedTrial& recorded, std::string_view source,
                                      std::string_view give) {
  const std::filesystem::path path = recorded.spec.teacher;
  std::error_code error;
  // Not there as `read_recorded_teacher` would find it (a dangling link included): say whose file it is.
  if (const auto status = std::filesystem::status(path, error); error || !std::filesystem::exists(status)) {
    throw DataError(std::string(source) + ": the replay's teacher " + path.string() +
                    (recorded.teacher_kept_by_session
                         ? " (the copy its session kept beside the record's folder)"
                         : " (as --teacher was given when it ran; a relative name is read from the working "
                           "folder)") +
                    ": no such file; give " + std::string(give) + ", the teacher's recording it ran on");
  }
  return read_recorded_teacher(recorded, path);
}

Checked<WholeTrial> recorded_whole_trial(const RecordedTrial& recorded, const Checked<TrialSpec>& spec) {
  // The record's force law is given whole: the device's figures fit no default stiffness of it.
  return build_whole_trial(spec, DeviceInfo{},
                           {.force_law = recorded.force_law,
                            .safety = recorded.safety,
                            .passivity = recorded.passivity,
                            .writer = recorded.writer,
                            .simulated_device = recorded.simulated_device});
}

TrialRun rerun_trial(const RecordedTrial& recorded, const Checked<TrialSpec>& spec, const Scene& scene,
                     TrialRunInputs inputs) {
  if (!scene_is_recorded_one(scene, recorded.scene_sha256)) {
    const std::string here = scene_sha256(scene);
    throw InvalidArgument(
        "the characters placed here are not the recorded ones (scene SHA-256 " + here.substr(0, 12) +
        "... against the record's " + recorded.scene_sha256.substr(0, 12) +
        "...): other character data (another --data or --store; in Python, library=) or another layout");
  }
  if (recorded.writer && inputs.hand_maker == nullptr) {
    throw InvalidArgument(
        "the simulated writer wrote this record: give its hand maker, sim's recorded_writing(recorded) "
        "(calligraphy/sim/simulated_writing.hpp), as TrialRunInputs::hand_maker");
  }
  // The record's physics make the device it ran on (the runner's, over any device `inputs` gives).
  if (recorded.simulated_device) inputs.device = nullptr;
  return run_whole_trial(recorded_whole_trial(recorded, spec), scene, inputs);
}

}  // namespace calligraphy
