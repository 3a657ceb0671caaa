#include "calligraphy/trial/teacher_recording.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "core/json_document.hpp"
#include "core/whole_file.hpp"

namespace calligraphy {
namespace {

constexpr const char* kFormat = "calligraphy-teacher-recording";
constexpr int kVersion = 1;

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw DataError(source + ": " + what);
}

const nlohmann::json& member(const nlohmann::json& object, const char* key, const std::string& source,
                             const std::string& where) {
  const auto found = object.find(key);
  if (found == object.end()) fail(source, "missing key " + where + key);
  return *found;
}

std::string text_member(const nlohmann::json& object, const char* key, const std::string& source) {
  const nlohmann::json& value = member(object, key, source, "/");
  if (!value.is_string()) fail(source, std::string("/") + key + ": expected a string");
  return value.get<std::string>();
}

std::vector<double> number_array(const nlohmann::json& samples, const char* key, const std::string& source) {
  const nlohmann::json& array = member(samples, key, source, "/samples/");
  const std::string where = std::string("/samples/") + key;
  if (!array.is_array()) fail(source, where + ": expected an array of numbers");
  std::vector<double> values;
  values.reserve(array.size());
  for (std::size_t i = 0; i < array.size(); ++i) {
    const nlohmann::json& value = array[i];
    if (!value.is_number()) fail(source, where + "/" + std::to_string(i) + ": expected a number");
    const double number = value.get<double>();
    if (!std::isfinite(number)) fail(source, where + "/" + std::to_string(i) + ": not a finite number");
    values.push_back(number);
  }
  return values;
}

}  // namespace

TeacherRecording teacher_recording_from_trace(std::string characters, std::string writer, std::string device,
                                              double rate_hz, const std::vector<TrialSample>& trace) {
  if (trace.size() < 2) {
    throw InvalidArgument("a teacher recording needs the trial's trace (at least 2 samples), got " +
                          std::to_string(trace.size()) + "; run the trial with keep_trace");
  }
  TeacherRecording recording{
      std::move(characters), std::move(writer), std::move(device), rate_hz, CALLIGRAPHY_VERSION, {}};
  recording.samples.reserve(trace.size());
  for (const TrialSample& sample : trace) recording.samples.push_back({sample.time_s, sample.position_m});
  validate_teacher_trajectory(recording.samples);
  return recording;
}

std::string teacher_recording_json(const TeacherRecording& recording) {
  nlohmann::json t = nlohmann::json::array(), x = nlohmann::json::array(), y = nlohmann::json::array(),
                 z = nlohmann::json::array();
  for (const TeacherSample& sample : recording.samples) {
    t.push_back(sample.time_s);
    x.push_back(sample.position_m.x());
    y.push_back(sample.position_m.y());
    z.push_back(sample.position_m.z());
  }
  const nlohmann::json document = {{"format", kFormat},
                                   {"version", kVersion},
                                   {"characters", recording.characters},
                                   {"writer", recording.writer},
                                   {"device", recording.device},
                                   {"rate_hz", recording.rate_hz},
                                   {"library_version", recording.library_version},
                                   {"samples", {{"t_s", t}, {"x_m", x}, {"y_m", y}, {"z_m", z}}}};
  return json_text(document) + "\n";
}

TeacherRecording parse_teacher_recording(std::string_view json_text, const std::string& source) {
  const nlohmann::json document = json_detail::parse_json_document(json_text, source);
  if (!document.is_object()) fail(source, "expected a JSON object");
  // Another kind of JSON document (a trial record, a protocol, a session.json) has no such format: say so
  // rather than name the first key it lacks.
  const auto format = document.find("format");
  if (format == document.end() || *format != kFormat) {
    fail(source, std::string("/format: ") +
                     (format == document.end() ? "missing" : "not \"" + std::string(kFormat) + "\"") +
                     ": not a teacher's recording (one has format \"" + kFormat +
                     "\", as trial --record writes it)");
  }
  const nlohmann::json& version = member(document, "version", source, "/");
  if (version != kVersion) fail(source, "/version: expected " + std::to_string(kVersion));

  TeacherRecording recording;
  recording.characters = text_member(document, "characters", source);
  if (recording.characters.empty()) fail(source, "/characters: empty");
  recording.writer = text_member(document, "writer", source);
  recording.device = text_member(document, "device", source);
  recording.library_version = text_member(document, "library_version", source);
  const nlohmann::json& rate = member(document, "rate_hz", source, "/");
  if (!rate.is_number() || !(rate.get<double>() > 0.0) || !std::isfinite(rate.get<double>()))
    fail(source, "/rate_hz: expected a positive number");
  recording.rate_hz = rate.get<double>();

  const nlohmann::json& samples = member(document, "samples", source, "/");
  if (!samples.is_object()) fail(source, "/samples: expected an object");
  const std::vector<double> t = number_array(samples, "t_s", source);
  const std::vector<double> x = number_array(samples, "x_m", source);
  const std::vector<double> y = number_array(samples, "y_m", source);
  const std::vector<double> z = number_array(samples, "z_m", source);
  if (x.size() != t.size() || y.size() != t.size() || z.size() != t.size()) {
    fail(source, "/samples: t_s, x_m, y_m and z_m have different lengths (" + std::to_string(t.size()) +
                     ", " + std::to_string(x.size()) + ", " + std::to_string(y.size()) + ", " +
                     std::to_string(z.size()) + ")");
  }
  if (t.size() < 2) fail(source, "/samples: fewer than 2 samples");
  recording.samples.reserve(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (i > 0 && t[i] < t[i - 1]) {
      fail(source, "/samples/t_s/" + std::to_string(i) + ": time " + shortest_decimal(t[i]) +
                       " s is below the previous one");
    }
    recording.samples.push_back({t[i], Vec3(x[i], y[i], z[i])});
  }
  return recording;
}

TeacherRecording read_teacher_recording(const std::filesystem::path& path) {
  const std::string text = read_regular_file(path, kMaxTeacherRecordingBytes);
  return parse_teacher_recording(text, path.string());
}

void require_teacher_for(const TeacherRecording& recording, std::string_view characters) {
  if (recording.characters != characters) {
    throw InvalidArgument("the teacher's recording is of \"" + recording.characters +
                          "\" and cannot guide \"" + std::string(characters) + "\"");
  }
}

}  // namespace calligraphy
