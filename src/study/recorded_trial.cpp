#include "calligraphy/study/recorded_trial.hpp"

#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "core/json_reader.hpp"
#include "core/whole_file.hpp"
#include "study/parameter_json.hpp"
#include "study/recorded_trial_object.hpp"
#include "study/saved_sessions.hpp"
#include "study/trial_record.hpp"
#include "trial/trial_spec_object.hpp"

namespace calligraphy {
namespace {

using nlohmann::json;

// The nearest-point search has no parameter table of its own (it lives below the force law); its methods by
// name.
constexpr std::array<std::pair<const char*, NearestPointMethod>, 3> kNearestMethods{{
    {"exact", NearestPointMethod::exact},
    {"newton", NearestPointMethod::newton},
    {"subdivision", NearestPointMethod::subdivision},
}};

constexpr double kLargest = std::numeric_limits<double>::max();

json guidance_law_json(const GuidanceLaw& law) {
  json out = {{"mode", to_string(mode_of(law))}};
  std::visit([&out](const auto& alternative) { study_detail::put_parameters(out, alternative); }, law);
  return out;
}

GuidanceLaw read_guidance_law(json_detail::ObjectReader reader) {
  const std::string name = reader.string("mode");
  const std::optional<GuidanceMode> mode = guidance_mode_from_string(name);
  if (!mode)
    json_detail::fail(reader.source(), reader.pointer("mode"), "unknown guidance mode '" + name + "'");
  GuidanceLaw law = default_guidance_law(*mode);
  std::visit([&reader](auto& alternative) { study_detail::take_parameters(reader, alternative); }, law);
  reader.finish();
  return law;
}

json force_law_json(const ForceLawParameters& f) {
  json out = json::object();
  study_detail::put_parameters(out, f);
  out["guidance"] = f.guidance;
  out["guidance_law"] = guidance_law_json(f.guidance_law);
  out["acceptance"] = study_detail::acceptance_json(f.acceptance);
  const char* method = "exact";
  for (const auto& [name, value] : kNearestMethods) {
    if (value == f.nearest.method) method = name;
  }
  out["nearest"] = {{"method", method},
                    {"tolerance", f.nearest.tolerance},
                    {"newton_starts", f.nearest.newton_starts},
                    {"newton_iterations", f.nearest.newton_iterations}};
  return out;
}

ForceLawParameters read_force_law(json_detail::ObjectReader reader) {
  ForceLawParameters f;
  study_detail::take_parameters(reader, f);
  const json* guidance = &reader.required("guidance");
  if (!guidance->is_boolean()) {
    json_detail::fail(reader.source(), reader.pointer("guidance"),
                      "expected true or false, got " + json_detail::describe(*guidance));
  }
  f.guidance = guidance->get<bool>();
  f.guidance_law = read_guidance_law(json_detail::ObjectReader(
      reader.required("guidance_law"), reader.pointer("guidance_law"), reader.source()));
  json_detail::ObjectReader acceptance(reader.required("acceptance"), reader.pointer("acceptance"),
                                       reader.source());
  study_detail::take_parameters(acceptance, f.acceptance);
  acceptance.finish();
  json_detail::ObjectReader nearest(reader.required("nearest"), reader.pointer("nearest"), reader.source());
  const std::string method = nearest.string("method");
  bool known = false;
  for (const auto& [name, value] : kNearestMethods) {
    if (method == name) {
      f.nearest.method = value;
      known = true;
    }
  }
  if (!known)
    json_detail::fail(reader.source(), nearest.pointer("method"), "unknown method '" + method + "'");
  f.nearest.tolerance = nearest.number("tolerance", -kLargest, kLargest);
  f.nearest.newton_starts = static_cast<int>(nearest.integer("newton_starts", 1, 1000));
  f.nearest.newton_iterations = static_cast<int>(nearest.integer("newton_iterations", 1, 1000));
  nearest.finish();
  reader.finish();
  return f;
}

json writer_json(const WriterProfile& w) {
  json out = {{"name", w.name}};
  for (const std::string& key : writer_parameter_names()) out[key] = writer_parameter(w, key);
  return out;
}

WriterProfile read_writer(json_detail::ObjectReader reader) {
  WriterProfile w;
  w.name = reader.string("name");
  for (const std::string& key : writer_parameter_names()) {
    const double value = reader.number(key, -kLargest, kLargest);
    try {
      set_writer_parameter(w, key, value);  // the profile's own ranges (per field)
    } catch (const InvalidArgument& e) {
      json_detail::fail(reader.source(), reader.pointer(key), e.what());
    }
  }
  reader.finish();
  return w;
}

json vec3_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

Vec3 read_vec3(json_detail::ObjectReader& reader, const std::string& key) {
  const json& value = reader.required(key);
  if (!value.is_array() || value.size() != 3)
    json_detail::fail(reader.source(), reader.pointer(key), "expected [x, y, z] in metres");
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    v[static_cast<Eigen::Index>(i)] = json_detail::as_number(
        value[i], json_detail::child_pointer(reader.pointer(key), i), reader.source(), -kLargest, kLargest);
  }
  return v;
}

SimulatedDeviceParameters read_simulated_device(json_detail::ObjectReader reader) {
  SimulatedDeviceParameters p;
  p.moving_mass_kg = reader.number("moving_mass_kg", -kLargest, kLargest);
  p.damping_n_s_per_m = reader.number("damping_n_s_per_m", -kLargest, kLargest);
  p.encoder_resolution_m = reader.number("encoder_resolution_m", -kLargest, kLargest);
  p.velocity_cutoff_hz = reader.number("velocity_cutoff_hz", -kLargest, kLargest);
  p.physics_substeps = static_cast<int>(
      reader.integer("physics_substeps", std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  p.physics_rate_hz = reader.number("physics_rate_hz", -kLargest, kLargest);
  p.initial_position_m = read_vec3(reader, "initial_position_m");
  reader.finish();
  return p;
}

json layout_json(const SceneLayout& l) {
  return {{"character_size_m", l.character_size_m},
          {"spacing_m", l.spacing_m},
          {"centre_m", {l.centre_m.x(), l.centre_m.y()}},
          {"paper_z_m", l.paper_z_m},
          {"box_margin_m", l.box_margin_m},
          {"start_radius_m", l.start_radius_m}};
}

SceneLayout read_layout(json_detail::ObjectReader reader) {
  SceneLayout l;
  l.character_size_m = reader.number("character_size_m", 0.0, kLargest);
  l.spacing_m = reader.number("spacing_m", 0.0, kLargest);
  const json& centre = reader.required("centre_m");
  if (!centre.is_array() || centre.size() != 2) {
    json_detail::fail(reader.source(), reader.pointer("centre_m"), "expected [x, y] in metres");
  }
  for (std::size_t i = 0; i < 2; ++i) {
    l.centre_m[static_cast<Eigen::Index>(i)] =
        json_detail::as_number(centre[i], json_detail::child_pointer(reader.pointer("centre_m"), i),
                               reader.source(), -kLargest, kLargest);
  }
  l.paper_z_m = reader.number("paper_z_m", -kLargest, kLargest);
  l.box_margin_m = reader.number("box_margin_m", 0.0, kLargest);
  l.start_radius_m = reader.number("start_radius_m", 0.0, kLargest);
  reader.finish();
  return l;
}

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

}  // namespace

RecordedTrial recorded_trial(const TrialSpec& spec, const TrialRun& run, const SimulatedWriting& writing,
                             const Scene& scene) {
  return recorded_trial(spec, run.options, run.simulated_writer ? &writing.profile() : nullptr, scene);
}

RecordedTrial recorded_trial(const TrialSpec& spec, const TrialOptions& ran, const WriterProfile* writer,
                             const Scene& scene) {
  RecordedTrial recorded;
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
  if (auto* replay = std::get_if<ReplayGuidance>(&recorded.force_law.guidance_law))
    replay->teacher_trajectory.clear();  // the teacher is named by the specification, not copied
  recorded.safety = ran.safety;
  recorded.passivity = ran.passivity;
  if (writer != nullptr) recorded.writer = *writer;
  recorded.layout = scene.layout;
  recorded.scene_sha256 = scene_sha256(scene);
  recorded.library_version = library_build().version;
  return recorded;
}

std::string scene_sha256(const Scene& scene) {
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
    }
  }
  return sha256_hex(bytes);
}

namespace study_detail {

nlohmann::json simulated_device_object(const SimulatedDeviceParameters& p) {
  return {{"moving_mass_kg", p.moving_mass_kg},
          {"damping_n_s_per_m", p.damping_n_s_per_m},
          {"encoder_resolution_m", p.encoder_resolution_m},
          {"velocity_cutoff_hz", p.velocity_cutoff_hz},
          {"physics_substeps", p.physics_substeps},
          {"physics_rate_hz", p.physics_rate_hz},
          {"initial_position_m", vec3_json(p.initial_position_m)}};
}

nlohmann::json recorded_trial_object(const RecordedTrial& r) {
  json out = {
      {"format", kRecordedTrialFormat},
      {"version", kRecordedTrialVersion},
      {"trial", json::parse(trial_spec_json(r.spec))},
      {"force_law", force_law_json(r.force_law)},
      {"passivity", {{"enabled", r.passivity.enabled}}},
      {"writer", r.writer ? writer_json(*r.writer) : json(nullptr)},
      {"simulated_device", r.simulated_device ? simulated_device_object(*r.simulated_device) : json(nullptr)},
      {"scene", {{"layout", layout_json(r.layout)}, {"sha256", r.scene_sha256}}},
      {"library_version", r.library_version}};
  json safety = json::object();
  study_detail::put_parameters(safety, r.safety);
  out["safety"] = safety;
  study_detail::put_parameters(out["passivity"], r.passivity);
  return out;
}

}  // namespace study_detail

std::string recorded_trial_json(const RecordedTrial& r) {
  return study_detail::recorded_trial_object(r).dump(2) + "\n";
}

namespace {

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
  const std::int64_t version = reader.integer("version", 0, std::numeric_limits<std::int64_t>::max());
  if (version < kOldestRecordedTrialVersion || version > kRecordedTrialVersion) {
    json_detail::fail(source, reader.pointer("version"),
                      "version " + std::to_string(version) + " is not one this library reads (" +
                          std::to_string(kOldestRecordedTrialVersion) + " to " +
                          std::to_string(kRecordedTrialVersion) + ")");
  }
  RecordedTrial r;
  // The specification's own reader checks its fields (trial_spec.hpp); its pointers are prefixed here.
  const json& trial = reader.required("trial");
  try {
    // A replay whose teacher was given as samples (a session's, kept in its folder) names no file.
    const bool teacher_named = trial.is_object() && trial.contains("teacher") &&
                               trial["teacher"].is_string() && !trial["teacher"].get<std::string>().empty();
    r.spec = *trial_detail::trial_spec_from_object(
        trial, reader.pointer("trial"), source, teacher_named ? TeacherSource::file : TeacherSource::samples);
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, reader.pointer("trial"), e.what());
  }
  r.force_law = read_force_law(
      json_detail::ObjectReader(reader.required("force_law"), reader.pointer("force_law"), source));
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
  {
    json_detail::ObjectReader safety(reader.required("safety"), reader.pointer("safety"), source);
    study_detail::take_parameters(safety, r.safety);
    safety.finish();
    checked(source, reader.pointer("safety"), [&] { r.safety.validate(); });
  }
  {
    json_detail::ObjectReader passivity(reader.required("passivity"), reader.pointer("passivity"), source);
    r.passivity.enabled = passivity.boolean_or("enabled", false);
    study_detail::take_parameters(passivity, r.passivity);
    passivity.finish();
    checked(source, reader.pointer("passivity"), [&] { r.passivity.validate(); });
  }
  if (const json* writer = reader.optional("writer"))
    r.writer = read_writer(json_detail::ObjectReader(*writer, reader.pointer("writer"), source));
  if (const json* device = reader.optional("simulated_device")) {
    r.simulated_device =
        read_simulated_device(json_detail::ObjectReader(*device, reader.pointer("simulated_device"), source));
    checked(source, reader.pointer("simulated_device"), [&] { r.simulated_device->validate(); });
  }
  json_detail::ObjectReader scene(reader.required("scene"), reader.pointer("scene"), source);
  r.layout =
      read_layout(json_detail::ObjectReader(scene.required("layout"), scene.pointer("layout"), source));
  r.scene_sha256 = scene.string("sha256");
  scene.finish();
  r.library_version = reader.string_or("library_version", "");
  reader.finish();
  return r;
}

}  // namespace

RecordedTrial read_recorded_trial(std::string_view text, const std::string& source) {
  return read_recorded_document(json_detail::parse_json(text, source), source);
}

RecordedTrial read_recorded_trial_file(const std::string& path) {
  const json document = json_detail::parse_json(read_regular_file(path, study_detail::kMaxRecordBytes), path);
  RecordedTrial recorded = read_recorded_document(document, path);
  if (recorded.spec.guidance && recorded.spec.guidance_mode == GuidanceMode::replay &&
      recorded.spec.teacher.empty()) {
    // A session's replay ran on the teacher kept in its folder (trials/ is beside teachers/): the record
    // names the file and its SHA-256 under /guidance/teacher (trial_guidance.hpp); taken when it is still the
    // same.
    const json* teacher = document.contains("guidance") && document["guidance"].is_object() &&
                                  document["guidance"].contains("teacher") &&
                                  document["guidance"]["teacher"].is_object()
                              ? &document["guidance"]["teacher"]
                              : nullptr;
    if (teacher != nullptr && (*teacher)["file"].is_string() && (*teacher)["sha256"].is_string()) {
      const std::filesystem::path file =
          std::filesystem::path(path).parent_path().parent_path() / (*teacher)["file"].get<std::string>();
      std::error_code error;
      if (std::filesystem::is_regular_file(file, error) &&
          sha256_hex(read_regular_file(file, study_detail::kMaxRecordBytes)) ==
              (*teacher)["sha256"].get<std::string>())
        recorded.spec.teacher = file.string();
    }
  }
  return recorded;
}

SimulatedWriting recorded_writing(const RecordedTrial& recorded) {
  return SimulatedWriting(recorded.spec, recorded.writer);
}

TrialRun rerun_trial(const RecordedTrial& recorded, const Checked<TrialSpec>& spec, const Scene& scene,
                     TrialRunInputs inputs) {
  const std::string here = scene_sha256(scene);
  if (here != recorded.scene_sha256) {
    throw InvalidArgument("the characters placed here are not the recorded ones (scene SHA-256 " +
                          here.substr(0, 12) + "... against the record's " +
                          recorded.scene_sha256.substr(0, 12) +
                          "...): other character data (--corpus, --store) or another layout");
  }
  inputs.force_law = recorded.force_law;
  inputs.safety = recorded.safety;
  inputs.passivity = recorded.passivity;
  std::unique_ptr<SimulatedDevice> device;
  if (recorded.simulated_device) {
    device = std::make_unique<SimulatedDevice>(*recorded.simulated_device);
    inputs.device = device.get();
  }
  return run_trial_spec(spec, scene, inputs);
}

}  // namespace calligraphy
