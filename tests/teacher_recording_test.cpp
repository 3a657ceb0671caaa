// The teacher's recording file of the replay guidance mode: round trip through JSON and the errors of
// a bad file (trial/teacher_recording.hpp).
#include "calligraphy/trial/teacher_recording.hpp"

#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/teacher_replay.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"

using namespace calligraphy;

namespace {

TeacherRecording recorded_teacher(const Scene& scene) {
  TrialOptions options;
  options.keep_trace = true;
  SimulationOptions teacher;
  teacher.writer = WriterProfile::skilled();
  teacher.seed = 5;
  const TrialResult result = run_simulated_trial(scene, options, teacher);
  REQUIRE(result.metrics.completed_in_order);
  return teacher_recording_from_trace("十", "skilled", "simulated", options.rate_hz, result.trace);
}

}  // namespace

TEST_CASE("A teacher's recording reads back exactly and guides the replay", "[guidance][teacher]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  const TeacherRecording recording = recorded_teacher(scene);
  const TeacherRecording back = parse_teacher_recording(teacher_recording_json(recording), "t.json");
  CHECK(back.characters == "十");
  CHECK(back.writer == "skilled");
  CHECK(back.rate_hz == recording.rate_hz);
  REQUIRE(back.samples.size() == recording.samples.size());
  for (std::size_t i = 0; i < back.samples.size(); i += 97) {
    CHECK(back.samples[i].time_s == recording.samples[i].time_s);
    CHECK(back.samples[i].position_m == recording.samples[i].position_m);  // exact: shortest round trip
  }
  const TeacherReplay replay(scene, back.samples, ForceLawParameters{});
  CHECK(replay.stroke_count() == scene.stroke_count());
  CHECK_NOTHROW(require_teacher_for(back, "十"));
  CHECK_THROWS_WITH(require_teacher_for(back, "大"), Catch::Contains("十") && Catch::Contains("大"));
}

TEST_CASE("A bad teacher recording is refused naming the file and the key", "[guidance][teacher]") {
  const std::string good =
      R"({"format":"calligraphy-teacher-recording","version":1,"characters":"十","writer":"human",)"
      R"("device":"mouse","rate_hz":1000,"library_version":"","samples":{"t_s":[0,0.001,0.002],)"
      R"("x_m":[0,0,0],"y_m":[0,0.001,0.002],"z_m":[0,0,0]}})";
  CHECK(parse_teacher_recording(good, "t.json").samples.size() == 3);
  const auto refused = [&](std::string from, const std::string& to, const std::string& message) {
    from.replace(from.find(to.substr(0, to.find('|'))), to.find('|'), to.substr(to.find('|') + 1));
    CHECK_THROWS_WITH(parse_teacher_recording(from, "t.json"),
                      Catch::Contains("t.json") && Catch::Contains(message));
  };
  refused(good, R"("version":1|"version":2)", "/version");
  refused(good, R"("format":"calligraphy-teacher-recording"|"format":"other")", "/format");
  refused(good, R"("t_s":[0,0.001,0.002]|"t_s":[0,0.002,0.001])", "/samples/t_s/2");
  refused(good, R"("x_m":[0,0,0]|"x_m":[0,0])", "different lengths");
  refused(good, R"("y_m":[0,0.001,0.002]|"y_m":[0,"a",0.002])", "/samples/y_m/1");
  refused(good, R"("characters":"十",|)", "characters");
  // A number beyond a double's range, wherever it is, is a data error naming its pointer.
  refused(good, R"("y_m":[0,0.001,0.002]|"y_m":[0,1e999,0.002])", "/samples/y_m/1: not a finite number");
  refused(good, R"("rate_hz":1000|"rate_hz":-1e400)", "/rate_hz: not a finite number");
  refused(good, R"("characters":"十"|"characters":[1e999])", "/characters/0: not a finite number");
  CHECK_THROWS_WITH(parse_teacher_recording("{", "t.json"),
                    Catch::Contains("t.json: not valid JSON at byte"));
  CHECK_THROWS_WITH(read_teacher_recording("/nonexistent/teacher.json"), Catch::Contains("no such file"));
  CHECK_THROWS_WITH(read_teacher_recording("/dev/zero"), Catch::Contains("not a regular file"));
  CHECK_THROWS_AS(teacher_recording_from_trace("十", "skilled", "simulated", 1000.0, {}), InvalidArgument);
}

TEST_CASE("A teacher recording edited in a program that writes a byte-order mark is read",
          "[guidance][teacher]") {
  // nlohmann-json skips a UTF-8 byte-order mark at the start of the text (lexer::skip_bom).
  const std::string text =
      "\xEF\xBB\xBF"
      R"({"format":"calligraphy-teacher-recording","version":1,"characters":"十","writer":"human",)"
      R"("device":"mouse","rate_hz":1000,"library_version":"","samples":{"t_s":[0,0.001,0.002],)"
      R"("x_m":[0,0,0],"y_m":[0,0.001,0.002],"z_m":[0,0,0]}})";
  CHECK(parse_teacher_recording(text, "t.json").samples.size() == 3);
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("calligraphy_teacher_bom_" + std::to_string(::getpid()) + ".json");
  std::ofstream(path, std::ios::binary) << text;
  CHECK(read_teacher_recording(path).characters == "十");
  std::filesystem::remove(path);
}
