// An application's round against the library's documented errors: the cases were written from the doc
// comments of include/calligraphy/** alone, before the implementation was read. For every function whose
// comment says it throws, the throw is provoked and both the exception's type (the one errors.hpp and the
// comment name, not merely a base) and its message (the argument, field, file, character or JSON pointer
// the comment says it names) are checked; a value the comment promises to leave unchanged is compared after
// the throw. The functions a header promises never throw are checked to be declared `noexcept`, at compile
// time. (Each public header compiling on its own is the build's `calligraphy_public_headers`,
// tests/public_headers.)

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <vector>

#include "calligraphy/analysis/metrics.hpp"
#include "calligraphy/collision/constraint_space.hpp"
#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/spsc_queue.hpp"
#include "calligraphy/core/stop_signals.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/device_servo_clock.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/corpus_store.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/session.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "temp_folder.hpp"
#include "temporary_files.hpp"
#include "thrown_exactly.hpp"

using namespace calligraphy;
using calligraphy::testing::has;
using calligraphy::testing::thrown_exactly;

namespace {

// The first character of `library` for which `pick` holds (the test does not guess the embedded set).
char32_t first_character(const std::vector<char32_t>& characters, const std::function<bool(char32_t)>& pick) {
  for (const char32_t c : characters) {
    if (pick(c)) return c;
  }
  FAIL("no character fits");
  return 0;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// The hierarchy errors.hpp documents, and the functions a header promises never throw.

static_assert(std::is_base_of_v<std::runtime_error, Error>);
static_assert(std::is_base_of_v<Error, InvalidArgument> && std::is_base_of_v<Error, DataError>);
static_assert(std::is_base_of_v<DataError, CharacterNotFound> && std::is_base_of_v<DataError, InputError>);
static_assert(std::is_base_of_v<InputError, ProtocolError>);
static_assert(std::is_base_of_v<Error, DeviceError> && std::is_base_of_v<Error, StateError>);
static_assert(std::is_base_of_v<DeviceError, DeviceNotFound> &&
              std::is_base_of_v<DeviceError, DeviceUnavailable>);
static_assert(std::is_base_of_v<DeviceError, CommunicationError> &&
              std::is_base_of_v<DeviceError, SafetyFault>);
static_assert(std::is_base_of_v<DeviceError, CalibrationNeeded> &&
              std::is_base_of_v<DeviceError, RealtimeError>);
static_assert(!std::is_base_of_v<DeviceNotFound, DeviceUnavailable> &&
              !std::is_base_of_v<DataError, InvalidArgument>);

TEST_CASE("unseen15e: every function a header promises never throws is declared noexcept", "[unseen15e]") {
  // "Never throws": atomic_file.hpp, servo_loop.hpp, haptic_device.hpp, simulated_device.hpp, hand.hpp,
  // device_servo_clock.hpp, renderer.hpp, session.hpp ("step never ... throws"); "noexcept":
  // force_law.hpp, constraint_space.hpp ("no exceptions"), stroke_progress.hpp, nearest_point.hpp.
  static_assert(noexcept(guard_output_files()));
  static_assert(std::is_nothrow_destructible_v<ServoLoop>);
  static_assert(noexcept(std::declval<ServoLoop&>().stop()));
  static_assert(noexcept(std::declval<HapticDevice&>().close()));
  static_assert(noexcept(std::declval<HapticDevice&>().read_state(std::declval<DeviceState&>())));
  static_assert(noexcept(std::declval<HapticDevice&>().write_force(std::declval<const Vec3&>())));
  static_assert(noexcept(std::declval<SimulatedDevice&>().open()),
                "simulated_device.hpp: opening \"Never throws\"");
  static_assert(noexcept(std::declval<SimulatedDevice&>().close()));
  static_assert(noexcept(std::declval<DeviceServoClock&>().detach()));
  static_assert(noexcept(std::declval<Renderer&>().tick(std::declval<const DeviceState&>())));
  static_assert(noexcept(std::declval<TrialSession&>().step(std::declval<const DeviceState&>())));
  static_assert(
      noexcept(clamp_force(std::declval<const Vec3&>(), 1.0))&& noexcept(paper_force(0.0, 0.0, 1.0)));
  static_assert(noexcept(constraint_taper(0.0, 1.0, 1.0)));
  static_assert(noexcept(nearest_point_on_segment(std::declval<const Vec2&>(), std::declval<const Vec2&>(),
                                                  std::declval<const Vec2&>())));
  static_assert(noexcept(to_string(DeviceFault::link_lost))&& noexcept(device_fault_name(DeviceFault::none)));
  static_assert(noexcept(StopSignals::installed())&& noexcept(StopSignals::received()));
  static_assert(std::is_nothrow_move_constructible_v<DeviceRegistry>);
  static_assert(std::is_nothrow_move_assignable_v<DeviceRegistry>);
  static_assert(noexcept(std::declval<SpscQueue<int>&>().try_push(1)));
  SUCCEED("checked at compile time");
}

// ---------------------------------------------------------------------------------------------------------
// core

TEST_CASE("unseen15e: decode_utf8 names the byte offset and encode_utf8 refuses surrogates and U+110000",
          "[unseen15e]") {
  CHECK(has(thrown_exactly<InvalidArgument>([] { (void)decode_utf8(std::string_view("ab\xff", 3)); }),
            "byte 2"));
  // A cut sequence: 一, then at offset 3 the lead byte of a three-byte character and the end of the text.
  const std::string cut = "\xe4\xb8\x80\xe4";
  CHECK(has(thrown_exactly<InvalidArgument>([&] { (void)decode_utf8(cut); }), "byte 3"));
  (void)thrown_exactly<InvalidArgument>([] { (void)encode_utf8(char32_t{0xD800}); });
  (void)thrown_exactly<InvalidArgument>([] { (void)encode_utf8(char32_t{0x110000}); });
  (void)thrown_exactly<InvalidArgument>([] { (void)encode_utf8(std::u32string{U'a', char32_t{0xDFFF}}); });
  CHECK(encode_utf8(char32_t{0x10FFFF}) == "\xf4\x8f\xbf\xbf");
}

TEST_CASE("unseen15e: throw_device_fault maps each of the nine codes to its type with its message",
          "[unseen15e]") {
  for (std::size_t i = 1; i < kDeviceFaultCount; ++i) {
    const auto fault = static_cast<DeviceFault>(i);
    INFO(device_fault_name(fault));
    const std::string expected = device_fault_message(fault, "Arm 1", "packet 7 refused");
    CHECK(
        (has(expected, "Arm 1: ") && has(expected, to_string(fault)) && has(expected, "(packet 7 refused)")));
    if (is_link_fault(fault)) {
      CHECK(thrown_exactly<CommunicationError>(
                [&] { throw_device_fault(fault, "Arm 1", "packet 7 refused"); }) == expected);
    } else {
      CHECK(thrown_exactly<SafetyFault>([&] { throw_device_fault(fault, "Arm 1", "packet 7 refused"); }) ==
            expected);
    }
  }
  (void)thrown_exactly<InvalidArgument>([] { throw_device_fault(DeviceFault::none, "Arm 1"); });
  CHECK(device_fault_message(DeviceFault::watchdog, "") == to_string(DeviceFault::watchdog));
}

TEST_CASE("unseen15e: SpscQueue refuses a capacity of 0 and above 2^24 and takes 2^24", "[unseen15e]") {
  CHECK(has(thrown_exactly<InvalidArgument>([] { SpscQueue<char> queue(0); }), "0"));
  CHECK(has(thrown_exactly<InvalidArgument>([] { SpscQueue<char> queue((std::size_t{1} << 24) + 1); }),
            "16777217"));
  SpscQueue<char> largest(std::size_t{1} << 24);
  CHECK(largest.try_push('a'));
}

TEST_CASE("unseen15e: a second StopSignals while one lives is a StateError, and a third after it is fine",
          "[unseen15e]") {
  REQUIRE_FALSE(StopSignals::installed());
  {
    StopSignals first;
    CHECK(StopSignals::installed());
    (void)thrown_exactly<StateError>([] { StopSignals second; });
    CHECK(StopSignals::installed());
  }
  CHECK_FALSE(StopSignals::installed());
  StopSignals again;
  CHECK(StopSignals::installed());
}

TEST_CASE("unseen15e: the atomic writers name the path and the system's reason, and a set refuses reuse",
          "[unseen15e]") {
  const TempFolder folder;
  const auto missing = folder.path / "no-such-folder" / "out.txt";
  const std::string message = thrown_exactly<DataError>([&] { write_file_atomically(missing, "text"); });
  CHECK(has(message, missing.string()));
  CHECK(has(message, "No such file or directory"));
  // A folder where the file should be: "Is a directory".
  std::filesystem::create_directory(folder.path / "taken");
  CHECK(has(thrown_exactly<DataError>([&] { write_file_atomically(folder.path / "taken", "x"); }),
            (folder.path / "taken").string()));
  CHECK(has(thrown_exactly<DataError>([&] { (void)write_file_exclusively(missing, "text"); }),
            missing.string()));
  // Two links naming each other: ELOOP.
  std::filesystem::create_symlink(folder.path / "b", folder.path / "a");
  std::filesystem::create_symlink(folder.path / "a", folder.path / "b");
  CHECK(has(thrown_exactly<DataError>([&] { (void)written_path(folder.path / "a"); }),
            (folder.path / "a").string()));
  // read_file_for_update: larger than max_bytes is refused naming the path; no file is nullopt.
  write_text(folder.path / "doc.md", std::string(100, 'x'));
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_file_for_update(folder.path / "doc.md", 99); }),
            (folder.path / "doc.md").string()));
  CHECK(read_file_for_update(folder.path / "doc.md", 100) == std::string(100, 'x'));
  CHECK_FALSE(read_file_for_update(folder.path / "none.md").has_value());
  // AtomicFileSet: add after commit and a second commit are StateErrors; the committed file is whole.
  AtomicFileSet set;
  set.add(folder.path / "one.txt", "one");
  set.commit();
  CHECK(calligraphy::testing_files::contents(folder.path / "one.txt") == "one");
  (void)thrown_exactly<StateError>([&] { set.add(folder.path / "two.txt", "two"); });
  (void)thrown_exactly<StateError>([&] { set.commit(); });
  CHECK_FALSE(std::filesystem::exists(folder.path / "two.txt"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(folder.path)) ++entries;
  CHECK(entries == 5);  // taken, a, b, doc.md, one.txt: no temporary left, no-such-folder not made
}

// ---------------------------------------------------------------------------------------------------------
// model

TEST_CASE("unseen15e: typical_stroke refuses 0 and 40 and keeps 1 and 39", "[unseen15e]") {
  CHECK(has(thrown_exactly<InvalidArgument>([] { (void)typical_stroke(0); }), "0"));
  CHECK(has(thrown_exactly<InvalidArgument>([] { (void)typical_stroke(40); }), "40"));
  (void)thrown_exactly<InvalidArgument>([] { (void)typical_stroke(std::numeric_limits<int>::min()); });
  CHECK(typical_stroke(1).id == 1);
  CHECK(typical_stroke(39).id == 39);
  CHECK_FALSE(typical_stroke_id("NOPE").has_value());
}

TEST_CASE("unseen15e: StrokeElement's makers name the control point and character_table the stroke",
          "[unseen15e]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(thrown_exactly<InvalidArgument>([&] { (void)StrokeElement::line(Vec2(0, 0), Vec2(nan, 0)); }) ==
        "StrokeElement::line: control point 1 is not finite");
  const std::array<Vec2, 5> points{Vec2(0, 0), Vec2(1, 1), Vec2(2, std::numeric_limits<double>::infinity()),
                                   Vec2(3, 0), Vec2(4, 0)};
  CHECK(thrown_exactly<InvalidArgument>([&] { (void)StrokeElement::bezier(points.data(), 3); }) ==
        "StrokeElement::bezier: control point 2 is not finite");
  (void)thrown_exactly<InvalidArgument>([&] { (void)StrokeElement::bezier(points.data(), 2); });
  (void)thrown_exactly<InvalidArgument>([&] { (void)StrokeElement::bezier(points.data(), 6); });
  // character_table: an element of degree 7, stroke 2 element 1 (from 1).
  Character character;
  character.code_point = U'二';
  Stroke good;
  good.typical_id = 1;
  good.elements = {StrokeElement::line(Vec2(0, 0), Vec2(1, 0))};
  good.attraction_factors = {1.0, 1.0};
  Stroke bad = good;
  bad.elements[0].degree = 7;
  character.strokes = {good, bad};
  const std::string message = thrown_exactly<InvalidArgument>([&] { (void)character_table(character); });
  CHECK(has(message, "stroke 2 element 1"));
  CHECK(has(message, "7"));
}

TEST_CASE("unseen15e: a character library names the missing character, the folder and the outlines it lacks",
          "[unseen15e]") {
  const CharacterLibrary embedded = CharacterLibrary::embedded();
  const std::string message = thrown_exactly<CharacterNotFound>([&] { (void)embedded.load(U'\U0001F600'); });
  CHECK(has(message, "U+1F600"));
  CHECK(has(message, encode_utf8(U'\U0001F600')));
  (void)thrown_exactly<CharacterNotFound>([&] { (void)embedded.load_data(U'\U0001F600'); });
  const std::string folder = "/nonexistent/calligraphy-15e";
  CHECK(has(thrown_exactly<DataError>([&] { (void)CharacterLibrary::from_directory(folder); }), folder));
  // A character of the bundled store has its outlines, one per stroke; a bad tolerance is InvalidArgument.
  const CharacterLibrary standard = CharacterLibrary::standard();
  const char32_t stored =
      first_character(CorpusStore::bundled().characters(), [&](char32_t c) { return !embedded.contains(c); });
  CHECK(standard.load_outlines(stored).strokes.size() == standard.load(stored).strokes.size());
  (void)thrown_exactly<InvalidArgument>([&] { (void)standard.load_outlines(stored, -1.0); });
  const char32_t one = first_character(embedded.characters(), [](char32_t) { return true; });
  (void)thrown_exactly<InvalidArgument>([&] { (void)embedded.load_outlines(one, 0.0); });
  (void)thrown_exactly<InvalidArgument>([&] { (void)embedded.load_outlines(one, std::nan("")); });
  // An empty folder holds no character: characters() names it.
  const TempFolder empty;
  const CharacterLibrary none = CharacterLibrary::from_directory(empty.path);
  CHECK(has(thrown_exactly<DataError>([&] { (void)none.characters(); }), empty.path.string()));
}

TEST_CASE("unseen15e: parse_hanzi_writer_json names the source, the character and the JSON pointer",
          "[unseen15e]") {
  const std::string source = "data/一.json";
  const std::string big = thrown_exactly<DataError>(
      [&] { (void)parse_hanzi_writer_json(R"({"medians": [[[0, 0], [1e400, 0]]]})", U'一', source); });
  CHECK(has(big, source));
  CHECK(has(big, "/medians/0/1/0"));
  const std::string type = thrown_exactly<DataError>(
      [&] { (void)parse_hanzi_writer_json(R"({"medians": [[[0, 0], [10, "x"]]]})", U'一', source); });
  CHECK(has(type, "/medians/0/1/1"));
  const std::string syntax = thrown_exactly<DataError>(
      [&] { (void)parse_hanzi_writer_json("{\"medians\": [[[0, 0],\n [1", U'一', source); });
  CHECK(has(syntax, source));
  CHECK(has(syntax, "2:"));  // line:column of the cut, on line 2
  CHECK(has(
      thrown_exactly<DataError>([&] { (void)parse_hanzi_writer_json(R"({"strokes": []})", U'一', source); }),
      "/medians"));
}

TEST_CASE(
    "unseen15e: a corpus store names the file, the offset and the character, and encoding refuses bad input",
    "[unseen15e]") {
  const std::vector<std::uint8_t> junk(64, 0x5a);
  CHECK(has(thrown_exactly<DataError>([&] { (void)CorpusStore::from_bytes(junk, "junk.clg"); }), "junk.clg"));
  CHECK(has(thrown_exactly<DataError>([&] { (void)CorpusStore::from_bytes({}, "empty.clg"); }), "empty.clg"));
  const TempFolder folder;
  CHECK(
      has(thrown_exactly<DataError>([&] { (void)CorpusStore::open(folder.path / "none.clg"); }), "none.clg"));
  const CorpusStore& bundled = CorpusStore::bundled();
  const std::string missing = thrown_exactly<CharacterNotFound>([&] { (void)bundled.load(U'\U0001F600'); });
  CHECK(has(missing, "U+1F600"));
  CHECK(has(missing, bundled.name()));
  (void)thrown_exactly<CharacterNotFound>([&] { (void)bundled.record_bytes(U'\U0001F600'); });
  // Encoding: the same character twice, an empty character, a typical ID of 40.
  const Character one = CharacterLibrary::standard().load(U'一');
  (void)thrown_exactly<InvalidArgument>([&] { (void)encode_corpus_store(std::vector<Character>{one, one}); });
  Character empty = one;
  empty.strokes.clear();
  (void)thrown_exactly<InvalidArgument>([&] { (void)encode_corpus_store(std::vector<Character>{empty}); });
  Character forty = one;
  forty.strokes[0].typical_id = 40;
  (void)thrown_exactly<InvalidArgument>([&] { (void)encode_corpus_store(std::vector<Character>{forty}); });
  const auto unwritable = folder.path / "no-folder" / "x.clg";
  CHECK(has(thrown_exactly<DataError>([&] { write_corpus_store(unwritable, std::vector<Character>{one}); }),
            unwritable.string()));
  CHECK_FALSE(std::filesystem::exists(folder.path / "no-folder"));
}

TEST_CASE("unseen15e: a scene of 1,001 characters names what and the limit", "[unseen15e]") {
  const std::string message = thrown_exactly<InvalidArgument>([] { check_scene_size(1001, "the text"); });
  CHECK(has(message, "the text"));
  CHECK(has(message, "1001"));
  CHECK(has(message, "1000"));
  check_scene_size(kMaxSceneCharacters, "the text");
  const Character one = CharacterLibrary::standard().load(U'一');
  (void)thrown_exactly<InvalidArgument>(
      [&] { (void)Scene::lay_out(std::vector<Character>(kMaxSceneCharacters + 1, one)); });
}

// ---------------------------------------------------------------------------------------------------------
// analysis, report

TEST_CASE("unseen15e: DeviationPool refuses a bad radius, a bad deviation, pools of two radii and no sample",
          "[unseen15e]") {
  (void)thrown_exactly<InvalidArgument>([] { DeviationPool pool(-1e-3); });
  (void)thrown_exactly<InvalidArgument>([] { DeviationPool pool(std::numeric_limits<double>::infinity()); });
  DeviationPool pool(1e-3);
  (void)thrown_exactly<InvalidArgument>([&] { (void)pool.summary(); });
  (void)thrown_exactly<InvalidArgument>([&] { pool.add(-1e-9); });
  (void)thrown_exactly<InvalidArgument>([&] { pool.add(std::nan("")); });
  CHECK(pool.samples() == 0);
  pool.add(2e-3);
  DeviationPool other(2e-3);
  other.add(1e-3);
  (void)thrown_exactly<InvalidArgument>([&] { pool.merge(other); });
  CHECK(pool.samples() == 1);
  CHECK(pool.summary().max_m == 2e-3);
}

TEST_CASE("unseen15e: the pen trace CSV reader names source:line, the column and the value", "[unseen15e]") {
  const std::string text = "t,x,y,pen\n0,0,0,1\n0.001,oops,0,1\n";
  const std::string message =
      thrown_exactly<DataError>([&] { (void)parse_pen_trace_csv(text, "pen.csv", Placement{}); });
  CHECK(has(message, "pen.csv:3"));
  CHECK(has(message, "x"));
  CHECK(has(message, "oops"));
  const std::string back = thrown_exactly<DataError>(
      [&] { (void)parse_pen_trace_csv("t,x,y,pen\n1,0,0,1\n0.5,0,0,1\n", "pen.csv", Placement{}); });
  CHECK(has(back, "pen.csv:3"));
  const std::string pen = thrown_exactly<DataError>(
      [&] { (void)parse_pen_trace_csv("t,x,y,pen\n0,0,0,2\n", "pen.csv", Placement{}); });
  CHECK(has(pen, "pen.csv:2"));
  CHECK(has(pen, "pen"));
  PenTraceCsvOptions options;
  options.max_samples = 0;
  (void)thrown_exactly<InvalidArgument>(
      [&] { (void)parse_pen_trace_csv("t,x,y\n", "pen.csv", Placement{}, options); });
  CHECK(has(thrown_exactly<InvalidArgument>([] { (void)parse_trace_units("feet"); }), "feet"));
  CHECK(has(thrown_exactly<DataError>([] { (void)read_pen_trace_csv("/nonexistent/p.csv", Placement{}); }),
            "/nonexistent/p.csv"));
}

// ---------------------------------------------------------------------------------------------------------
// devices

TEST_CASE("unseen15e: a device registry refuses empty and taken names and empty functions, naming them",
          "[unseen15e]") {
  DeviceRegistry registry;
  const auto factory = [] { return std::make_unique<SimulatedDevice>(); };
  registry.register_device("bench", simulated_phantom_desktop_info(), factory);
  CHECK(has(thrown_exactly<InvalidArgument>(
                [&] { registry.register_device("bench", simulated_phantom_desktop_info(), factory); }),
            "bench"));
  (void)thrown_exactly<InvalidArgument>(
      [&] { registry.register_device("", simulated_phantom_desktop_info(), factory); });
  (void)thrown_exactly<InvalidArgument>(
      [&] { registry.register_device("other", simulated_phantom_desktop_info(), {}); });
  (void)thrown_exactly<InvalidArgument>(
      [&] { (void)registry.register_device_if_absent("other", simulated_phantom_desktop_info(), {}); });
  (void)thrown_exactly<InvalidArgument>([&] { registry.register_backend(DeviceBackend{"", {}, {}}); });
  DeviceBackend no_create{"nocreate", [] { return DeviceSurvey{}; }, {}};
  (void)thrown_exactly<InvalidArgument>([&] { registry.register_backend(no_create); });
  (void)thrown_exactly<InvalidArgument>([&] { (void)registry.register_backend_if_absent(no_create); });
  CHECK(registry.backend_names() == std::vector<std::string>{"bench"});
  // An unknown name: DeviceNotFound naming the devices that exist; through create and open as well.
  CHECK(has(thrown_exactly<DeviceNotFound>([&] { (void)registry.find("phantom"); }), "bench"));
  (void)thrown_exactly<DeviceNotFound>([&] { (void)registry.create("phantom"); });
  (void)thrown_exactly<DeviceNotFound>([&] { (void)registry.open("phantom"); });
  // The simulated device has a hand port, which the listing (registered without capabilities) denies.
  CHECK(has(thrown_exactly<InvalidArgument>([&] { (void)registry.open("bench"); }), "bench"));
  registry.register_device("moved", simulated_phantom_desktop_info(), factory,
                           DeviceCapabilities{.moved_by_simulated_hand = true});
  CHECK(registry.open("moved")->is_open());
}

TEST_CASE("unseen15e: a backend that cannot give its device now is DeviceUnavailable with its reason",
          "[unseen15e]") {
  DeviceRegistry registry;
  registry.register_backend(DeviceBackend{
      "armbus", []() -> DeviceSurvey { throw DeviceError("armbus: the driver found no arm on the bus"); },
      [](const DeviceListing&) -> std::unique_ptr<HapticDevice> {
        return std::make_unique<SimulatedDevice>();
      }});
  const std::string message = thrown_exactly<DeviceUnavailable>([&] { (void)registry.find("armbus"); });
  CHECK(has(message, "found no arm"));
  // The survey turns the same throw into a note.
  const DeviceSurvey survey = registry.survey();
  CHECK(survey.devices.empty());
  REQUIRE(survey.notes.size() == 1);
  CHECK(has(survey.notes[0], "found no arm"));
}

TEST_CASE("unseen15e: SimulatedDevice::advance refuses a negative, NaN or 2^62 ns step and keeps its state",
          "[unseen15e]") {
  SimulatedDevice device;
  device.open();
  device.advance(1e-3);
  DeviceState before;
  REQUIRE(device.read_state(before) == DeviceFault::none);
  for (const double dt : {-1e-3, std::nan(""), std::numeric_limits<double>::infinity(), 5e9}) {
    INFO("dt_s = " << dt);
    CHECK(has(thrown_exactly<InvalidArgument>([&] { device.advance(dt); }), "dt_s"));
  }
  DeviceState after;
  REQUIRE(device.read_state(after) == DeviceFault::none);
  CHECK(after.time_s == before.time_s);
  CHECK(after.position_m == before.position_m);
  SimulatedDeviceParameters bad;
  bad.physics_rate_hz = 10.0;
  CHECK(has(thrown_exactly<InvalidArgument>([&] { bad.validate(); }), "physics_rate_hz"));
}

TEST_CASE("unseen15e: a servo loop refuses an empty callback", "[unseen15e]") {
  SimulatedDevice device;
  (void)thrown_exactly<InvalidArgument>([&] { ServoLoop loop(device, ServoCallback{}); });
  ServoLoopOptions options;
  options.rate_hz = -1.0;
  CHECK(has(thrown_exactly<InvalidArgument>([&] {
              ServoLoop loop(
                  device, [](const DeviceState&, double) { return ServoCommand{}; }, options);
            }),
            "rate_hz"));
}

// ---------------------------------------------------------------------------------------------------------
// trial

TEST_CASE("unseen15e: writer profiles name an unknown profile or key and leave the profile unchanged",
          "[unseen15e]") {
  const std::string unknown = thrown_exactly<InvalidArgument>([] { (void)writer_profile("expert"); });
  CHECK(has(unknown, "expert"));
  CHECK((has(unknown, "novice") && has(unknown, "skilled") && has(unknown, "foreign")));
  WriterProfile profile = WriterProfile::novice();
  const WriterProfile original = profile;
  const std::string key =
      thrown_exactly<InvalidArgument>([&] { set_writer_parameter(profile, "bias_m", 1.0); });
  CHECK(has(key, "bias_m"));
  CHECK(has(key, "bias_offset_m"));  // the known ones listed
  (void)thrown_exactly<InvalidArgument>([&] { (void)writer_parameter(profile, "bias_m"); });
  CHECK(has(
      thrown_exactly<InvalidArgument>([&] { set_writer_parameter(profile, "max_attempts_per_stroke", 2.5); }),
      "max_attempts_per_stroke"));
  CHECK(has(
      thrown_exactly<InvalidArgument>([&] { set_writer_parameter(profile, "bias_offset_m", std::nan("")); }),
      "bias_offset_m"));
  CHECK(writer_parameter(profile, "bias_offset_m") == writer_parameter(original, "bias_offset_m"));
  for (const std::string& name : writer_parameter_names()) {
    INFO(name);
    CHECK(writer_parameter(profile, name) == writer_parameter(original, name));
  }
}

TEST_CASE("unseen15e: the trial specification names the option, the JSON pointer and the source",
          "[unseen15e]") {
  CHECK(
      has(thrown_exactly<InvalidArgument>([] { (void)parse_trial_pacing("fast", "--pacing"); }), "--pacing"));
  const std::string pacing = thrown_exactly<InvalidArgument>([] { (void)parse_trial_pacing("Lock-Step"); });
  CHECK((has(pacing, "auto") && has(pacing, "lock-step") && has(pacing, "real-time")));
  TrialSpec spec;
  const TrialSpec original = spec;
  CHECK(has(thrown_exactly<InvalidArgument>([&] { set_trial_spec_field(spec, "--no-such-option", "1"); }),
            "--no-such-option"));
  CHECK(
      has(thrown_exactly<InvalidArgument>([&] { set_trial_spec_field(spec, "--pacing", "fast"); }), "fast"));
  CHECK(spec == original);
  (void)thrown_exactly<InvalidArgument>([&] { (void)trial_spec_field_text(spec, "no_such_key"); });
  const std::string json =
      thrown_exactly<DataError>([] { (void)trial_spec_from_json(R"({"no_such_key": 1})", "spec.json"); });
  CHECK(has(json, "spec.json"));
  CHECK(has(json, "/no_such_key"));
  CHECK(has(thrown_exactly<DataError>([] { (void)trial_spec_from_json("{\"pacing\": ", "spec.json"); }),
            "spec.json"));
  const std::vector<std::string> words{"一", "--no-such-option", "1"};
  CHECK(has(thrown_exactly<InvalidArgument>([&] { (void)trial_spec_from_args(words); }), "--no-such-option"));
}

TEST_CASE(
    "unseen15e: a recorded trial names the source and pointer, and its file reader keeps the two kinds apart",
    "[unseen15e]") {
  CHECK(has(thrown_exactly<DataError>([] { (void)read_recorded_trial("{}", "rec.json"); }), "rec.json"));
  CHECK(has(thrown_exactly<DataError>([] { (void)read_recorded_trial("[1, 2", "rec.json"); }), "rec.json"));
  const TempFolder folder;
  const auto missing = (folder.path / "none.json").string();
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_recorded_trial_file(missing); }), missing));
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_recorded_trial_file(folder.path.string()); }),
            folder.path.string()));
  write_text(folder.path / "empty.json", "{}");
  const auto file = (folder.path / "empty.json").string();
  CHECK(has(thrown_exactly<InputError>([&] { (void)read_recorded_trial_file(file); }), file));
}

TEST_CASE("unseen15e: teacher recordings name the source, the key and the sample", "[unseen15e]") {
  (void)thrown_exactly<InvalidArgument>([] {
    (void)teacher_recording_from_trace("一", "novice", "simulated", 1000.0, std::vector<TrialSample>(1));
  });
  CHECK(has(thrown_exactly<DataError>([] { (void)parse_teacher_recording("[]", "teacher.json"); }),
            "teacher.json"));
  std::vector<TrialSample> trace(3);
  for (std::size_t i = 0; i < trace.size(); ++i) trace[i].time_s = 1e-3 * static_cast<double>(i);
  const TeacherRecording recording = teacher_recording_from_trace("一", "novice", "simulated", 1000.0, trace);
  std::string json = teacher_recording_json(recording);
  CHECK(parse_teacher_recording(json, "teacher.json").samples.size() == 3);
  (void)thrown_exactly<InvalidArgument>([&] { require_teacher_for(recording, "十"); });
  const std::string both = thrown_exactly<InvalidArgument>([&] { require_teacher_for(recording, "十"); });
  CHECK((has(both, "一") && has(both, "十")));
  require_teacher_for(recording, "一");
  const TempFolder folder;
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_teacher_recording(folder.path / "none.json"); }),
            "none.json"));
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_teacher_recording(folder.path); }),
            folder.path.string()));
}

// ---------------------------------------------------------------------------------------------------------
// study

TEST_CASE("unseen15e: a protocol's text errors are ProtocolErrors naming the source, a file's are DataErrors",
          "[unseen15e]") {
  const std::string syntax =
      thrown_exactly<ProtocolError>([] { (void)parse_study_protocol("{", "paper.json"); });
  CHECK(has(syntax, "paper.json"));
  CHECK(has(thrown_exactly<ProtocolError>([] { (void)parse_study_protocol("[]", "paper.json"); }),
            "paper.json"));
  const TempFolder folder;
  const auto missing = folder.path / "none.json";
  CHECK(has(thrown_exactly<DataError>([&] { (void)load_study_protocol(missing); }), missing.string()));
  CHECK(
      has(thrown_exactly<DataError>([&] { (void)load_study_protocol(folder.path); }), folder.path.string()));
  // Larger than kMaxProtocolBytes: a DataError, not the parser's.
  write_text(folder.path / "big.json", std::string(kMaxProtocolBytes + 1, ' '));
  CHECK(has(thrown_exactly<DataError>([&] { (void)load_study_protocol(folder.path / "big.json"); }),
            "big.json"));
  write_text(folder.path / "bad.json", "{\"unknown\": 1}");
  CHECK(has(thrown_exactly<ProtocolError>([&] { (void)load_study_protocol(folder.path / "bad.json"); }),
            "bad.json"));
}
