// An application's round against the library as a haptic program links it: the cases were written from the
// public headers' comments and docs/servo-loop.md, force-rendering.md, devices.md and architecture.md alone,
// before the implementation was read. The application ticks a trial from its own loop on its own clock (an
// origin of years, a clock that stands still, runs back or jumps an hour, ticks at another rate, ticks past
// the stop), runs the library's loop on its own device (fault codes the device reports mid-run, an undefined
// code among them, a simulated pen nobody advances), reads the display from another thread, copies and moves
// a session mid-trial, and writes the library's files where they cannot go (a full device, a file size limit,
// a folder of /proc, through links). Each case holds the library to what its comment promises: the exact
// exception and what it names, the force bound and its continuity, zero force and forces off at the end,
// every tick kept, and no allocation on the tick path.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "allocation_count.hpp"
#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/logging.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/session.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "embedded_scenes.hpp"
#include "special_values.hpp"
#include "temp_folder.hpp"
#include "thrown_exactly.hpp"

using calligraphy::testing::cross_scene;
#include "temporary_files.hpp"

using namespace calligraphy;
using calligraphy::testing::count_this_thread;
using calligraphy::testing::counted_allocations;
using calligraphy::testing::has;
using calligraphy::testing::kCountsAllocations;
using calligraphy::testing::thrown_exactly;

namespace {

using calligraphy::testing::kInf;
using calligraphy::testing::kNaN;
// The per-tick change limit of the default safety chain [N per tick] (safety_chain.hpp), with rounding room.
constexpr double kStepLimitN = 0.25 + 1e-9;

DeviceInfo desktop() { return simulated_phantom_desktop_info(); }

// The pen `depth_m` below the paper on the first stroke's start, `along_m` along its first element.
DeviceState pressed(double time_s, double depth_m, double along_m = 0.0) {
  const Scene& scene = cross_scene();
  const auto& stroke = scene.characters.front().strokes.front();
  const Vec2 start = stroke.start();
  const Vec2 direction = (stroke.elements.front().end() - start).normalized();
  const Vec2 at = start + along_m * direction;
  DeviceState state;
  state.position_m = Vec3(at.x(), at.y(), scene.layout.paper_z_m - depth_m);
  state.time_s = time_s;
  return state;
}

// The application's writing hand: a spring-damper grip pulled along each stroke's centre line (down onto its
// start, along it 1 mm into the paper, up 1 cm, over to the next).
class PathHand final : public HandModel {
 public:
  PathHand(const Scene& scene, const Vec3& rest_m, double speed_m_s) : speed_(speed_m_s) {
    const double z = scene.layout.paper_z_m;
    path_.push_back(rest_m);
    for (const auto& character : scene.characters) {
      for (const auto& stroke : character.strokes) {
        const auto& line = stroke.centre_line.points_m;
        path_.emplace_back(line.front().x(), line.front().y(), z + 0.010);
        for (const Vec2& point : line) path_.emplace_back(point.x(), point.y(), z - 0.001);
        path_.emplace_back(line.back().x(), line.back().y(), z + 0.010);
      }
    }
    arc_.push_back(0.0);
    for (std::size_t i = 1; i < path_.size(); ++i)
      arc_.push_back(arc_.back() + (path_[i] - path_[i - 1]).norm());
  }
  [[nodiscard]] double duration_s() const { return arc_.back() / speed_; }
  Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) override {
    return 150.0 * (target(time_s) - position_m) - 4.0 * velocity_m_s;
  }

 private:
  [[nodiscard]] Vec3 target(double time_s) const {
    const double s = std::clamp(time_s * speed_, 0.0, arc_.back());
    std::size_t i = 1;
    while (i + 1 < arc_.size() && arc_[i] < s) ++i;
    const double span = arc_[i] - arc_[i - 1];
    const double t = span > 0.0 ? (s - arc_[i - 1]) / span : 1.0;
    return path_[i - 1] + t * (path_[i] - path_[i - 1]);
  }
  std::vector<Vec3> path_;
  std::vector<double> arc_;
  double speed_;
};

// A device of the application's own, for the library's servo loop: it reports a fault code at a chosen read
// or write, and keeps what the loop did to it (the last force written, forces on or off, how often they were
// turned on). Its clock is the application's: 1 ms a read from an origin of 5000 s.
class OwnDevice final : public HapticDevice {
 public:
  explicit OwnDevice(std::string model = "own test arm") : info_(desktop()) {
    info_.model = std::move(model);
  }
  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  [[nodiscard]] bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override {
    if (enabled) enables_.fetch_add(1);
    enabled_ = enabled;
  }
  [[nodiscard]] bool forces_enabled() const override { return enabled_; }
  DeviceFault read_state(DeviceState& state) noexcept override {
    const long n = reads_.fetch_add(1) + 1;
    if (n == read_fault_at) {
      enabled_ = false;
      return read_fault;
    }
    state.position_m = Vec3(0.0, 0.0, 0.02);
    state.velocity_m_s = Vec3::Zero();
    state.time_s = 5000.0 + 0.001 * static_cast<double>(n);
    return DeviceFault::none;
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    const long n = writes_.fetch_add(1) + 1;
    last_force_norm_ = force_n.norm();
    if (n == write_fault_at) {
      enabled_ = false;
      last_force_norm_ = 0.0;
      return write_fault;
    }
    return DeviceFault::none;
  }
  [[nodiscard]] double last_force_norm() const { return last_force_norm_; }
  [[nodiscard]] long reads() const { return reads_; }
  [[nodiscard]] long enables() const { return enables_; }

  long read_fault_at = -1;
  DeviceFault read_fault = DeviceFault::none;
  long write_fault_at = -1;
  DeviceFault write_fault = DeviceFault::none;

 private:
  DeviceInfo info_;
  std::atomic<bool> open_{false};
  std::atomic<bool> enabled_{false};
  std::atomic<long> reads_{0};
  std::atomic<long> writes_{0};
  std::atomic<long> enables_{0};
  std::atomic<double> last_force_norm_{0.0};
};

// One newton up, every tick: a force the loop must take back to zero at the end.
ServoCommand one_newton(const DeviceState& /*state*/, double /*dt_s*/) {
  return {Vec3(0.0, 0.0, 1.0), false};
}

// Waits (at most 5 s) until the loop has left its run.
void wait_until_stopped(const ServoLoop& loop) {
  for (int i = 0; i < 5000 && loop.running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  REQUIRE_FALSE(loop.running());
}

// What a loop run on `device` ended with: the exception `wait()` threw (type and message) and the fault.
struct LoopEnd {
  std::string type;
  std::string message;
  bool device_error = false;
  LoopFault fault;
};
LoopEnd run_until_fault(OwnDevice& device) {
  device.open();
  ServoLoop loop(device, one_newton);
  loop.start();
  LoopEnd end;
  try {
    loop.wait();
  } catch (const DeviceError& error) {
    end.type = typeid(error).name();
    end.message = error.what();
    end.device_error = true;
  } catch (const std::exception& error) {
    end.type = typeid(error).name();
    end.message = error.what();
  }
  end.fault = loop.stats().fault;
  return end;
}

// Steps `session` with `states` and returns the forces it commanded.
std::vector<Vec3> step_all(TrialSession& session, const std::vector<DeviceState>& states) {
  std::vector<Vec3> forces;
  forces.reserve(states.size());
  for (const DeviceState& state : states) forces.push_back(session.step(state).force_n);
  return forces;
}

// The pen pressed 3 mm into the paper moving slowly along the first stroke, with the time stamps
// `time_of(i)`.
std::vector<DeviceState> writing_states(int ticks, const std::function<double(int)>& time_of) {
  std::vector<DeviceState> states;
  for (int i = 0; i < ticks; ++i) {
    DeviceState state = pressed(time_of(i), 0.003, 0.02 * i / ticks);
    state.velocity_m_s = Vec3(0.0, 0.0, 0.0);
    states.push_back(state);
  }
  return states;
}

void check_force_bounded_and_continuous(const std::vector<Vec3>& forces, double max_force_n) {
  Vec3 previous = Vec3::Zero();
  double largest_step = 0.0;
  double largest = 0.0;
  bool finite = true;
  for (const Vec3& force : forces) {
    finite = finite && force.allFinite();
    largest = std::max(largest, force.norm());
    largest_step = std::max(largest_step, (force - previous).norm());
    previous = force;
  }
  CHECK(finite);
  CHECK(largest <= max_force_n + 1e-9);
  CHECK(largest_step <= kStepLimitN);
}

// Every log line of the library while it lives.
struct LogCapture {
  std::mutex mutex;
  std::vector<std::pair<LogLevel, std::string>> lines;
  LogCapture() {
    set_log_level(LogLevel::info);  // the default, which a test run before may have changed
    set_log_handler([this](LogLevel level, std::string_view message) {
      const std::lock_guard<std::mutex> lock(mutex);
      lines.emplace_back(level, std::string(message));
    });
  }
  ~LogCapture() { set_log_handler({}); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;
  // The warnings that speak of the device's clock (the renderer may warn of its stiffness as well).
  std::vector<std::string> clock_warnings() {
    const std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::string> found;
    for (const auto& [level, text] : lines) {
      if (level == LogLevel::warning && text.find("device's clock") != std::string::npos)
        found.push_back(text);
    }
    return found;
  }
};

std::vector<std::string> names_in(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// The application's own loop on its own clock (session.hpp: "times: the trial's clock starts at 0 with the
// first tick; state.time_s is on the device's clock (any origin) and only its differences are used").

TEST_CASE("unseen26a: a device clock three years after boot gives trial times of whole milliseconds from 0",
          "[unseen26a]") {
  const double origin_s = 1e8;  // OpenHaptics counts from the machine's boot
  TrialSession session(cross_scene(), desktop(), TrialOptions{});
  for (int i = 0; i < 300; ++i) (void)session.step(pressed(origin_s + 0.001 * i, 0.002));
  const TrialResult result = session.finish(TrialEnd::time_limit);
  REQUIRE(result.trace.size() == 300);
  double worst = 0.0;
  for (std::size_t i = 0; i < result.trace.size(); ++i) {
    worst = std::max(worst, std::abs(result.trace[i].time_s - 0.001 * static_cast<double>(i)));
  }
  CHECK(result.trace.front().time_s == 0.0);
  CHECK(worst < 1e-7);  // the double's resolution at 1e8 s is 1.5e-8 s
  CHECK(result.device_time_at_start_s == origin_s);
  CHECK(result.device_tick_rate_hz == Approx(1000.0).epsilon(1e-4));
}

TEST_CASE(
    "unseen26a: a clock that jumps an hour mid-stroke keeps every guidance mode's force bounded and smooth",
    "[unseen26a]") {
  FadingGuidance half;
  half.gain = 0.5;
  const std::vector<std::pair<const char*, GuidanceLaw>> laws{
      {"fixed", FixedGuidance{}},
      {"fading", half},
      {"timing", TimingGuidance{}},
      {"assist-as-needed", AssistAsNeededGuidance{}},
      {"error-amplification", ErrorAmplificationGuidance{}}};
  for (const auto& [name, law] : laws) {
    INFO("guidance " << name);
    TrialOptions options;
    options.force.guidance_law = law;
    TrialSession session(cross_scene(), desktop(), options);
    const auto states = writing_states(800, [](int i) { return 0.001 * i + (i >= 400 ? 3600.0 : 0.0); });
    const std::vector<Vec3> forces = step_all(session, states);
    check_force_bounded_and_continuous(forces, desktop().max_force_n);
    CHECK(forces.back().norm() > 0.5);  // the pen is still pressed into the paper: the force did not vanish
    const TrialResult result = session.finish(TrialEnd::time_limit);
    CHECK(result.trace[400].time_s == Approx(3600.4).margin(1e-6));
    bool ordered = true;
    for (std::size_t i = 1; i < result.trace.size(); ++i)
      ordered = ordered && result.trace[i].time_s >= result.trace[i - 1].time_s;
    CHECK(ordered);
  }
}

TEST_CASE("unseen26a: a clock that runs back 10 s or stands still holds the recorded time and a smooth force",
          "[unseen26a]") {
  for (const bool backwards : {true, false}) {
    INFO((backwards ? "back 10 s at tick 300" : "standing still from tick 300"));
    TrialOptions options;
    options.force.guidance_law = TimingGuidance{};
    TrialSession session(cross_scene(), desktop(), options);
    const auto states = writing_states(700, [&](int i) {
      if (i < 300) return 100.0 + 0.001 * i;
      return backwards ? 90.0 + 0.001 * i : 100.3;
    });
    const std::vector<Vec3> forces = step_all(session, states);
    check_force_bounded_and_continuous(forces, desktop().max_force_n);
    const TrialResult result = session.finish(TrialEnd::time_limit);
    REQUIRE(result.trace.size() == 700);
    double lowest_after = kInf;
    for (std::size_t i = 300; i < result.trace.size(); ++i)
      lowest_after = std::min(lowest_after, result.trace[i].time_s);
    CHECK(lowest_after >= result.trace[299].time_s);  // the recorded clock never runs backwards
    CHECK(std::isfinite(result.device_tick_rate_hz));
    CHECK(result.device_tick_rate_hz >= 0.0);
  }
}

TEST_CASE("unseen26a: an own loop ticking at 500 Hz or 2 kHz for a 1 kHz session is told so at finish",
          "[unseen26a]") {
  for (const double tick_hz : {500.0, 2000.0}) {
    INFO("ticks at " << tick_hz << " Hz");
    LogCapture log;
    TrialSession session(cross_scene(), desktop(), TrialOptions{});
    for (int i = 0; i < 200; ++i) (void)session.step(pressed(7.0 + i / tick_hz, -0.01));
    const TrialResult result = session.finish(TrialEnd::time_limit);
    CHECK(result.device_tick_rate_hz == Approx(tick_hz).epsilon(1e-6));
    const auto warnings = log.clock_warnings();
    REQUIRE(warnings.size() == 1);
    const std::string rate = tick_hz == 500.0 ? "500 Hz" : "2000 Hz";
    CHECK(has(warnings.front(), rate));
    CHECK(has(warnings.front(), "1000 Hz"));
    CHECK(has(warnings.front(), "TrialOptions::rate_hz"));
    if (tick_hz > 1000.0) CHECK(has(warnings.front(), "once per period"));
  }
}

TEST_CASE("unseen26a: an own loop that keeps stepping past the stop allocates nothing and is told to stop",
          "[unseen26a]") {
  TrialOptions options;
  options.max_duration_s = 0.2;  // 200 ticks
  TrialSession session(cross_scene(), desktop(), options);
  session.reserve_trace();
  std::vector<ServoCommand> commands(600);
  const long before = counted_allocations.load();
  count_this_thread = true;
  for (int i = 0; i < 600; ++i) commands[i] = session.step(pressed(0.001 * i, 0.003));
  count_this_thread = false;
  const long allocations = counted_allocations.load() - before;
  if (kCountsAllocations) CHECK(allocations == 0);
  CHECK_FALSE(commands[198].stop);
  bool stopped_after = true;
  bool finite = true;
  for (int i = 199; i < 600; ++i) {
    stopped_after = stopped_after && commands[i].stop;
    finite = finite && commands[i].force_n.allFinite() && commands[i].force_n.norm() <= desktop().max_force_n;
  }
  CHECK(stopped_after);
  CHECK(finite);
  CHECK(session.out_of_time());
}

TEST_CASE("unseen26a: hostile readings and clocks with passivity and a display attached allocate nothing",
          "[unseen26a]") {
  DisplayChannel channel;
  TrialOptions options;
  options.passivity.enabled = true;
  options.display = &channel;
  options.max_duration_s = 2.0;
  TrialSession session(cross_scene(), desktop(), options);
  session.reserve_trace();
  std::vector<DeviceState> states;
  for (int i = 0; i < 1500; ++i) {
    DeviceState state = pressed(0.001 * i, 0.004, 1e-5 * i);
    state.velocity_m_s = Vec3(0.02, 0.0, -0.01);
    switch (i % 97) {
      case 10:
        state.position_m.x() = kNaN;
        break;
      case 20:
        state.velocity_m_s.z() = kInf;
        break;
      case 30:
        state.position_m.y() = 1e304;
        break;
      case 40:
        state.time_s = kNaN;
        break;
      case 50:
        state.time_s = -1e300;
        break;
      case 60:
        state.time_s += 3600.0;
        break;
      case 70:
        state.position_m.z() = -kInf;
        break;
      default:
        break;
    }
    states.push_back(state);
  }
  std::vector<Vec3> forces(states.size());
  const long before = counted_allocations.load();
  count_this_thread = true;
  for (std::size_t i = 0; i < states.size(); ++i) forces[i] = session.step(states[i]).force_n;
  count_this_thread = false;
  if (kCountsAllocations) CHECK(counted_allocations.load() - before == 0);
  bool bounded = true;
  for (const Vec3& force : forces)
    bounded = bounded && force.allFinite() && force.norm() <= desktop().max_force_n;
  CHECK(bounded);
  CHECK(forces[97 + 10].norm() == 0.0);  // a rejected reading is zero force at once
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.metrics.readings_rejected >= 4 * 15);
}

TEST_CASE("unseen26a: a fault code mid-run in the application's loop keeps every tick stepped and names it",
          "[unseen26a]") {
  SimulatedDevice device;
  device.open();
  PathHand hand(cross_scene(), SimulatedDeviceParameters{}.initial_position_m, 0.04);
  device.hand_port()->attach_hand(&hand);
  TrialSession session(cross_scene(), device.info(), TrialOptions{});
  DeviceState state;
  DeviceFault fault = DeviceFault::none;
  std::size_t stepped = 0;
  for (int i = 0; i < 2000; ++i) {
    if ((fault = device.read_state(state)) != DeviceFault::none) break;
    if (i == 1500) state.position_m.x() = kNaN;  // a garbled reading first
    (void)session.step(state);
    ++stepped;
    if ((fault = device.write_force(session.last_output().force_n)) != DeviceFault::none) break;
    if (i < 1700) device.hand_port()->advance(0.001);  // then the application forgets to let time pass
  }
  REQUIRE(fault == DeviceFault::not_advanced);
  CHECK_FALSE(device.forces_enabled());
  const std::string reason = device_fault_message(fault, device.info().model);
  CHECK(has(reason, device.info().model));
  TrialResult result = session.finish(TrialEnd::device_fault, reason);
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.aborted);
  CHECK(result.abort_reason == reason);
  CHECK(result.trace.size() == stepped);
  CHECK(result.metrics.readings_rejected == 1);
  thrown_exactly<StateError>([&] { (void)session.finish(TrialEnd::completed); });
  device.hand_port()->attach_hand(nullptr);
}

TEST_CASE(
    "unseen26a: a trace of NaN, -1e300 and backward stamps goes to its HDF5 file and teacher JSON and back",
    "[unseen26a]") {
  TempFolder folder;
  TrialSession session(cross_scene(), desktop(), TrialOptions{});
  for (int i = 0; i < 400; ++i) {
    DeviceState state = pressed(50.0 + 0.001 * i, 0.002, 5e-5 * i);
    if (i % 50 == 7) state.time_s = kNaN;
    if (i % 50 == 17) state.time_s = -1e300;
    if (i % 50 == 27) state.time_s = 1.0;
    if (i % 50 == 37) state.position_m = Vec3(kInf, 0.0, 0.0);
    (void)session.step(state);
  }
  const TrialResult result = session.finish(TrialEnd::time_limit);
  REQUIRE(result.trace.size() == 400);
  const auto file = folder.path / "hostile.trace.h5";
  write_file_atomically(file, trial_trace_hdf5(result.trace));
  const TraceColumns columns = read_trace_hdf5(file);
  CHECK(columns.size() == 400);
  const TeacherRecording recording =
      teacher_recording_from_trace("十", "person", "own", 1000.0, result.trace);
  const TeacherRecording back = parse_teacher_recording(teacher_recording_json(recording), "hostile.json");
  CHECK(back.samples == recording.samples);
}

TEST_CASE("unseen26a: a session copied mid-stroke, and one moved, continue as the original", "[unseen26a]") {
  const auto states = writing_states(900, [](int i) { return 0.001 * i; });
  TrialSession original(cross_scene(), desktop(), TrialOptions{});
  for (int i = 0; i < 450; ++i) (void)original.step(states[i]);
  std::vector<Vec3> from_original;
  std::vector<Vec3> from_copy;
  std::vector<Vec3> from_moved;
  if constexpr (std::is_copy_constructible_v<TrialSession>) {
    TrialSession copy = original;
    TrialSession source = original;
    TrialSession moved = std::move(source);
    for (int i = 450; i < 900; ++i) {
      from_original.push_back(original.step(states[i]).force_n);
      from_copy.push_back(copy.step(states[i]).force_n);
      from_moved.push_back(moved.step(states[i]).force_n);
    }
    CHECK(from_copy == from_original);
    CHECK(from_moved == from_original);
    const TrialResult a = original.finish(TrialEnd::time_limit);
    const TrialResult b = copy.finish(TrialEnd::time_limit);
    REQUIRE(a.trace.size() == b.trace.size());
    CHECK(a.metrics.max_force_n == b.metrics.max_force_n);
    CHECK(a.trace.back().force_n == b.trace.back().force_n);
  } else {
    SUCCEED("TrialSession is not copyable");
  }
}

TEST_CASE("unseen26a: the display read from another thread while a clock runs back and jumps never goes back",
          "[unseen26a]") {
  DisplayChannel channel;
  TrialOptions options;
  options.display = &channel;
  TrialSession session(cross_scene(), desktop(), options);
  std::atomic<bool> done{false};
  std::uint64_t torn = 0;
  std::atomic<std::uint64_t> reads{0};
  std::thread display([&] {
    DisplaySnapshot previous;
    while (!done.load()) {
      DisplaySnapshot now;
      if (!channel.try_latest(now)) continue;
      ++reads;
      if (now.tick < previous.tick || (now.tick > previous.tick && now.time_s < previous.time_s) ||
          !std::isfinite(now.time_s) || !std::isfinite(now.force_n.x)) {
        ++torn;
      }
      previous = now;
      for (TracePoint point; channel.poll_trace(point);) {
      }
    }
  });
  for (int i = 0; i < 3000; ++i) {
    // The display thread reads along: the stepping waits for its first read, then for a read every 100 ticks.
    if (i % 100 == 0) {
      const std::uint64_t seen = reads.load();
      while (reads.load() == seen) std::this_thread::yield();
    }
    double t = 20.0 + 0.001 * i;
    if (i % 400 == 100) t = 5.0;   // back
    if (i % 400 == 200) t = kNaN;  // garbled
    if (i > 2000) t += 3600.0;     // an hour later
    (void)session.step(pressed(t, 0.002, 5e-6 * i));
  }
  done = true;
  display.join();
  CHECK(torn == 0);
  CHECK(reads.load() >= 30);
  const DisplaySnapshot last = channel.latest();
  CHECK(last.tick == 3000);
  CHECK(last.time_s == Approx(3600.0 + 2.999).margin(1e-6));
  (void)session.finish(TrialEnd::interrupted);
}

// ---------------------------------------------------------------------------------------------------------
// The renderer on its own (renderer.hpp, docs/force-rendering.md).

TEST_CASE("unseen26a: safety figures above the device's are taken as the device's, peak and continuous",
          "[unseen26a]") {
  SECTION("a peak of 50 N on a 7.9 N device") {
    RendererOptions options;
    options.safety.max_force_n = 50.0;
    options.safety.start_ramp_n_per_s = 0.0;
    Renderer renderer(cross_scene(), ForceLawParameters{}, desktop(), options);
    double largest = 0.0;
    for (int i = 0; i < 300; ++i) {
      largest = std::max(largest, renderer.tick(pressed(0.001 * i, 0.1)).force_n.norm());  // 80 N asked
    }
    CHECK(largest <= desktop().max_force_n + 1e-9);
    CHECK(largest > 0.9 * desktop().max_force_n);  // the device's peak is reached, not a lower one
  }
  SECTION("a continuous force of 40 N on a device of 1.75 N") {
    RendererOptions options;
    options.safety.max_continuous_force_n = 40.0;
    options.safety.continuous_time_constant_s = 0.05;
    Renderer renderer(cross_scene(), ForceLawParameters{}, desktop(), options);
    double largest = 0.0;
    Vec3 force = Vec3::Zero();
    for (int i = 0; i < 2000; ++i) {
      force = renderer.tick(pressed(0.001 * i, 0.1)).force_n;
      largest = std::max(largest, force.norm());
    }
    CHECK(largest <= desktop().max_force_n + 1e-9);
    CHECK(force.norm() <= desktop().max_continuous_force_n * 1.02);  // settled at the device's 1.75 N
  }
}

TEST_CASE("unseen26a: after every stroke is written a pen pressed back into the paper feels no force",
          "[unseen26a]") {
  SimulatedDevice device;
  device.open();
  PathHand hand(cross_scene(), SimulatedDeviceParameters{}.initial_position_m, 0.04);
  device.hand_port()->attach_hand(&hand);
  TrialSession session(cross_scene(), device.info(), TrialOptions{});
  DeviceState state;
  int ticks = 0;
  for (; ticks < 20000 && !session.finished(); ++ticks) {
    REQUIRE(device.read_state(state) == DeviceFault::none);
    const ServoCommand command = session.step(state);
    REQUIRE(device.write_force(command.force_n) == DeviceFault::none);
    device.hand_port()->advance(0.001);
  }
  device.hand_port()->attach_hand(nullptr);
  REQUIRE(session.finished());
  std::vector<Vec3> after;
  for (int i = 0; i < 300; ++i)
    after.push_back(session.step(pressed(state.time_s + 0.001 * (i + 1), 0.005)).force_n);
  CHECK(session.finished());
  bool zero_after_fade = true;
  for (std::size_t i = 40; i < after.size(); ++i) zero_after_fade = zero_after_fade && after[i].norm() == 0.0;
  CHECK(zero_after_fade);
  check_force_bounded_and_continuous(after, desktop().max_force_n);
}

TEST_CASE(
    "unseen26a: the passivity controller on hostile readings keeps the force finite, capped, allocation-free",
    "[unseen26a]") {
  RendererOptions options;
  options.passivity.enabled = true;
  Renderer renderer(cross_scene(), ForceLawParameters{}, desktop(), options);
  std::vector<DeviceState> states;
  for (int i = 0; i < 3000; ++i) {
    DeviceState state = pressed(0.001 * i, 0.003 + 0.002 * std::sin(i * 0.3), 1e-5 * i);
    state.velocity_m_s = Vec3(5.0 * std::cos(i * 0.7), 0.0, 50.0 * std::sin(i * 0.9));  // a shaking hand
    if (i % 101 == 0) state.velocity_m_s.x() = 1e300;
    if (i % 103 == 0) state.time_s = state.time_s - 1.0;
    if (i % 107 == 0) state.position_m.z() = -9.99;  // within the 10 m reading bound
    states.push_back(state);
  }
  std::vector<RenderOutput> outputs(states.size());
  const long before = counted_allocations.load();
  count_this_thread = true;
  for (std::size_t i = 0; i < states.size(); ++i) outputs[i] = renderer.tick(states[i]);
  count_this_thread = false;
  if (kCountsAllocations) CHECK(counted_allocations.load() - before == 0);
  bool bounded = true;
  bool damping_finite = true;
  for (const RenderOutput& out : outputs) {
    bounded = bounded && out.force_n.allFinite() && out.force_n.norm() <= desktop().max_force_n + 1e-9;
    damping_finite = damping_finite && std::isfinite(out.passivity_damping_n_s_per_m) &&
                     out.passivity_damping_n_s_per_m >= 0.0 &&
                     out.passivity_damping_n_s_per_m <= options.passivity.max_damping_n_s_per_m;
  }
  CHECK(bounded);
  CHECK(damping_finite);
  CHECK(std::isfinite(renderer.passivity().observed_energy_j()));
}

TEST_CASE("unseen26a: a reading just inside 10 m is rendered, one just beyond is rejected to zero at once",
          "[unseen26a]") {
  Renderer renderer(cross_scene(), ForceLawParameters{}, desktop());
  for (int i = 0; i < 400; ++i) (void)renderer.tick(pressed(0.001 * i, 0.004));
  REQUIRE(renderer.tick(pressed(0.4, 0.004)).force_n.norm() > 1.0);
  DeviceState inside = pressed(0.401, 0.004);
  inside.position_m.z() = -kMaxDeviceReadingM * 0.999;
  const RenderOutput in = renderer.tick(inside);
  CHECK_FALSE(in.input_rejected);
  CHECK(in.force_n.norm() > 1.0);  // not dropped: the chain moves at most 0.25 N a tick
  DeviceState beyond = pressed(0.402, 0.004);
  beyond.position_m.z() = -kMaxDeviceReadingM * 1.001;
  const RenderOutput out = renderer.tick(beyond);
  CHECK(out.input_rejected);
  CHECK(out.force_n.norm() == 0.0);
  CHECK((out.limits & safety_non_finite) != 0);
}

// ---------------------------------------------------------------------------------------------------------
// The library's servo loop on the application's own device (servo_loop.hpp, device_fault.hpp).

TEST_CASE(
    "unseen26a: a device's own watchdog code is a device fault, not the loop's stall, and a SafetyFault",
    "[unseen26a]") {
  OwnDevice device;
  device.read_fault_at = 30;
  device.read_fault = DeviceFault::watchdog;
  const LoopEnd end = run_until_fault(device);
  CHECK(end.type == typeid(SafetyFault).name());
  CHECK(has(end.message, "own test arm"));
  CHECK(end.fault.kind == LoopFaultKind::device);
  CHECK(end.fault.device == DeviceFault::watchdog);
  CHECK(end.fault.message == to_string(DeviceFault::watchdog));
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
}

TEST_CASE("unseen26a: a safety limit reported by write_force ends the run as a SafetyFault, force zero",
          "[unseen26a]") {
  OwnDevice device;
  device.write_fault_at = 25;
  device.write_fault = DeviceFault::safety_limit;
  const LoopEnd end = run_until_fault(device);
  CHECK(end.type == typeid(SafetyFault).name());
  CHECK(end.fault.kind == LoopFaultKind::device);
  CHECK(end.fault.device == DeviceFault::safety_limit);
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.reads() == 25);  // no tick after the fault
}

TEST_CASE("unseen26a: a device that reports an undefined fault code still ends the run safely and typed",
          "[unseen26a]") {
  const auto undefined = static_cast<DeviceFault>(200);
  CHECK(device_fault_name(undefined) != nullptr);
  CHECK(to_string(undefined) != nullptr);
  OwnDevice device;
  device.read_fault_at = 20;
  device.read_fault = undefined;
  const LoopEnd end = run_until_fault(device);
  CHECK(end.device_error);
  CHECK(has(end.message, "own test arm"));
  CHECK(end.fault.kind == LoopFaultKind::device);
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.reads() == 20);
}

TEST_CASE(
    "unseen26a: a simulated pen held by a hand that nobody advances ends a loop as a CommunicationError",
    "[unseen26a]") {
  SimulatedDevice device;
  device.open();
  PathHand hand(cross_scene(), SimulatedDeviceParameters{}.initial_position_m, 0.04);
  device.hand_port()->attach_hand(&hand);
  ServoLoop loop(device, one_newton);  // no after-write hook: the application forgot advance()
  loop.start();
  const std::string message = thrown_exactly<CommunicationError>([&] { loop.wait(); });
  CHECK(has(message, device.info().model));
  CHECK(loop.stats().fault.device == DeviceFault::not_advanced);
  CHECK(loop.stats().ticks <= 2);
  CHECK(device.applied_force().norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  device.hand_port()->attach_hand(nullptr);
}

TEST_CASE("unseen26a: stop() after a device fault returns that fault, with the force zero and off",
          "[unseen26a]") {
  OwnDevice device;
  device.read_fault_at = 15;
  device.read_fault = DeviceFault::link_lost;
  device.open();
  ServoLoop loop(device, one_newton);
  loop.start();
  wait_until_stopped(loop);
  const LoopFault fault = loop.stop();
  CHECK(fault.kind == LoopFaultKind::device);
  CHECK(fault.device == DeviceFault::link_lost);
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  // the run is over: wait() throws the fault or returns, never hangs
  try {
    loop.wait();
  } catch (const CommunicationError&) {
  }
  SUCCEED();
}

TEST_CASE("unseen26a: two loops on two own devices, one faulting, leave the other ticking untouched",
          "[unseen26a]") {
  OwnDevice steady("steady arm");
  OwnDevice faulty("faulty arm");
  faulty.read_fault_at = 20;
  faulty.read_fault = DeviceFault::link_lost;
  steady.open();
  faulty.open();
  ServoLoop steady_loop(steady, one_newton);
  ServoLoop faulty_loop(faulty, one_newton);
  steady_loop.start();
  faulty_loop.start();
  const std::string message = thrown_exactly<CommunicationError>([&] { faulty_loop.wait(); });
  CHECK(has(message, "faulty arm"));
  CHECK_FALSE(has(message, "steady arm"));
  const long reads_then = steady.reads();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  CHECK(steady_loop.running());
  CHECK(steady.reads() > reads_then);
  CHECK(steady.forces_enabled());
  CHECK(steady.last_force_norm() == Approx(1.0));
  const LoopFault fault = steady_loop.stop();
  CHECK_FALSE(fault);
  CHECK(steady.last_force_norm() == 0.0);
  CHECK_FALSE(steady.forces_enabled());
  CHECK(faulty.last_force_norm() == 0.0);
}

TEST_CASE("unseen26a: a loop refused for the renderer's rate never turned the device's forces on",
          "[unseen26a]") {
  RendererOptions options;
  options.rate_hz = 500.0;
  Renderer renderer(cross_scene(), ForceLawParameters{}, desktop(), options);
  OwnDevice device;
  device.open();
  ServoLoop loop(device, ticking(renderer, [&](const DeviceState& state, double) {
                   return ServoCommand{renderer.tick(state).force_n, false};
                 }));
  const std::string message = thrown_exactly<InvalidArgument>([&] { loop.start(); });
  CHECK(has(message, "500 Hz"));
  CHECK(has(message, "1000 Hz"));
  CHECK(has(message, "RendererOptions::rate_hz"));
  CHECK(has(message, "ServoLoopOptions::rate_hz"));
  CHECK(device.enables() == 0);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.reads() == 0);
  CHECK_FALSE(loop.running());
}

TEST_CASE("unseen26a: a loop destroyed while a session ticks leaves zero force, forces off, ticks recorded",
          "[unseen26a]") {
  OwnDevice device;
  device.open();
  TrialSession session(cross_scene(), device.info(), TrialOptions{});
  session.reserve_trace();
  {
    ServoLoop loop(device, session.servo_callback());
    loop.start();
    while (device.reads() < 30) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  const std::size_t ticks = session.ticks();
  const TrialResult result = session.finish(TrialEnd::interrupted);
  CHECK(result.trace.size() == ticks);
  CHECK(result.device_time_at_start_s == Approx(5000.001));
}

// ---------------------------------------------------------------------------------------------------------
// Value types' documented preconditions.

TEST_CASE("unseen26a: DisplayChannelOptions refuse a zero or absurd queue and a trace stride out of range",
          "[unseen26a]") {
  const std::vector<std::pair<const char*, std::function<void(DisplayChannelOptions&)>>> bad{
      {"trace_every_ticks", [](DisplayChannelOptions& o) { o.trace_every_ticks = 0; }},
      {"trace_every_ticks", [](DisplayChannelOptions& o) { o.trace_every_ticks = 1001; }},
      {"event_capacity", [](DisplayChannelOptions& o) { o.event_capacity = 0; }},
      {"trace_capacity", [](DisplayChannelOptions& o) { o.trace_capacity = 0; }},
      {"trace_capacity", [](DisplayChannelOptions& o) { o.trace_capacity = std::size_t{1} << 40; }},
      {"event_capacity",
       [](DisplayChannelOptions& o) { o.event_capacity = std::numeric_limits<std::size_t>::max(); }},
  };
  for (const auto& [field, set] : bad) {
    INFO(field);
    DisplayChannelOptions options;
    set(options);
    const std::string message = thrown_exactly<InvalidArgument>([&] { DisplayChannel channel(options); });
    CHECK(has(message, field));
  }
}

TEST_CASE("unseen26a: the low-pass at or above half the servo rate is refused with the documented sentence",
          "[unseen26a]") {
  const std::string direct = thrown_exactly<InvalidArgument>([] { check_low_pass_cutoff(500.0, 1000.0); });
  CHECK(direct ==
        "low_pass_cutoff_hz = 500 Hz must be under half the servo rate (rate_hz / 2 = 500 Hz); 0 = off");
  CHECK_NOTHROW(check_low_pass_cutoff(499.0, 1000.0));
  CHECK_NOTHROW(check_low_pass_cutoff(0.0, 1000.0));
  SafetyChainParameters parameters;
  parameters.max_force_n = 5.0;
  parameters.low_pass_cutoff_hz = 600.0;
  const std::string chain = thrown_exactly<InvalidArgument>([&] { (void)SafetyChain(parameters, 1000.0); });
  CHECK(has(chain, "low_pass_cutoff_hz = 600 Hz"));
  RendererOptions options;
  options.safety.low_pass_cutoff_hz = 600.0;
  const std::string renderer = thrown_exactly<InvalidArgument>(
      [&] { (void)Renderer(cross_scene(), ForceLawParameters{}, desktop(), options); });
  CHECK(has(renderer, "low_pass_cutoff_hz"));
  TrialOptions trial;
  trial.rate_hz = 200.0;
  trial.safety.low_pass_cutoff_hz = 100.0;
  const std::string session =
      thrown_exactly<InvalidArgument>([&] { (void)TrialSession(cross_scene(), desktop(), trial); });
  CHECK(has(session, "low_pass_cutoff_hz"));
}

TEST_CASE("unseen26a: a bare safety chain needs a peak force and a positive finite rate, named",
          "[unseen26a]") {
  CHECK(has(thrown_exactly<InvalidArgument>([] { (void)SafetyChain(SafetyChainParameters{}, 1000.0); }),
            "max_force_n"));
  SafetyChainParameters parameters;
  parameters.max_force_n = 5.0;
  for (const double rate : {0.0, -1000.0, kNaN, kInf}) {
    INFO("rate " << rate);
    thrown_exactly<InvalidArgument>([&] { (void)SafetyChain(parameters, rate); });
  }
  parameters.max_continuous_force_n = 6.0;  // above the peak that is set
  CHECK(has(thrown_exactly<InvalidArgument>([&] { (void)SafetyChain(parameters, 1000.0); }),
            "max_continuous_force_n"));
}

TEST_CASE("unseen26a: a bare safety chain counts NaN inputs across reset and steps only to zero",
          "[unseen26a]") {
  SafetyChainParameters parameters;
  parameters.max_force_n = 5.0;
  SafetyChain chain(parameters, 1000.0);
  for (int i = 0; i < 500; ++i) (void)chain.apply(Vec3(0.0, 0.0, 1e300));
  REQUIRE(chain.last_output().norm() == Approx(5.0));
  const SafetyResult nan = chain.apply(Vec3(kNaN, 0.0, 0.0));
  CHECK(nan.force_n.norm() == 0.0);
  CHECK((nan.limits & safety_non_finite) != 0);
  chain.reset();
  (void)chain.apply(Vec3(0.0, -kInf, 0.0));
  CHECK(chain.non_finite_count() == 2);
  const SafetyResult after_reset = chain.apply(Vec3(0.0, 0.0, 1e300));
  CHECK(after_reset.force_n.norm() <= parameters.start_ramp_n_per_s * 0.001 * 2 + 1e-12);
  SafetyChain largest(parameters, 1000.0);
  for (int i = 0; i < 500; ++i) (void)largest.apply(Vec3(1.5e308, -1.5e308, 1e308));
  CHECK(largest.last_output().norm() == Approx(5.0));
  CHECK(largest.last_output().x() == Approx(-largest.last_output().y()));
}

TEST_CASE(
    "unseen26a: PassivityParameters, the controller's rate and Colgate's bound refuse what they document",
    "[unseen26a]") {
  const std::vector<std::pair<const char*, std::function<void(PassivityParameters&)>>> bad{
      {"max_damping_n_s_per_m", [](PassivityParameters& p) { p.max_damping_n_s_per_m = 0.0; }},
      {"max_damping_n_s_per_m", [](PassivityParameters& p) { p.max_damping_n_s_per_m = kNaN; }},
      {"min_speed_m_s", [](PassivityParameters& p) { p.min_speed_m_s = 0.0; }},
      {"min_speed_m_s", [](PassivityParameters& p) { p.min_speed_m_s = -kInf; }},
  };
  for (const auto& [field, set] : bad) {
    INFO(field);
    PassivityParameters parameters;
    set(parameters);
    CHECK(has(thrown_exactly<InvalidArgument>([&] { parameters.validate(); }), field));
    CHECK(
        has(thrown_exactly<InvalidArgument>([&] { (void)PassivityController(parameters, 1000.0); }), field));
  }
  thrown_exactly<InvalidArgument>([] { (void)PassivityController(PassivityParameters{}, 0.0); });
  thrown_exactly<InvalidArgument>([] { (void)PassivityController(PassivityParameters{}, kNaN); });
  thrown_exactly<InvalidArgument>([] { (void)colgate_stiffness_bound(kNaN, 1000.0); });
  thrown_exactly<InvalidArgument>([] { (void)colgate_stiffness_bound(0.5, 0.0); });
  thrown_exactly<InvalidArgument>([] { (void)colgate_stiffness_bound(0.5, 1000.0, -1.0); });
  CHECK(colgate_stiffness_bound(0.5, 1000.0) == Approx(1000.0));
}

TEST_CASE("unseen26a: a simulated device opened twice keeps its clock, closed it refuses and drops the force",
          "[unseen26a]") {
  SimulatedDevice device;
  device.open();
  DeviceState state;
  REQUIRE(device.read_state(state) == DeviceFault::none);
  REQUIRE(device.write_force(Vec3(0.0, 0.0, 2.0)) == DeviceFault::none);
  device.advance(1.5);
  device.open();  // opening an open device changes nothing
  CHECK(device.time() == 1.5);
  CHECK(device.applied_force().z() == Approx(2.0));
  device.close();
  CHECK(device.applied_force().norm() == 0.0);
  DeviceState untouched;
  untouched.time_s = -42.0;
  CHECK(device.read_state(untouched) == DeviceFault::not_open);
  CHECK(untouched.time_s == -42.0);
  CHECK(device.write_force(Vec3(0.0, 0.0, 3.0)) == DeviceFault::not_open);
  CHECK(device.applied_force().norm() == 0.0);
  device.open();  // its clock restarts at 0 s
  CHECK(device.time() == 0.0);
  REQUIRE(device.read_state(state) == DeviceFault::none);
  CHECK(state.time_s == 0.0);
  CHECK(state.velocity_m_s.norm() == 0.0);
}

TEST_CASE("unseen26a: advance refuses a step that is negative or NaN and leaves the clock where it was",
          "[unseen26a]") {
  SimulatedDevice device;
  device.open();
  device.advance(0.25);
  const Vec3 position = device.true_position();
  for (const double dt : {-0.001, kNaN, -kInf, kInf}) {
    INFO("dt " << dt);
    thrown_exactly<InvalidArgument>([&] { device.hand_port()->advance(dt); });
    CHECK(device.time() == 0.25);
    CHECK(device.true_position() == position);
  }
}

// ---------------------------------------------------------------------------------------------------------
// Files the application writes through the public API (atomic_file.hpp, trial_report.hpp).

TEST_CASE("unseen26a: a record written to /dev/full is a DataError naming it and the disk's reason",
          "[unseen26a]") {
  if (!std::filesystem::exists("/dev/full"))
    SUCCEED("no /dev/full here");
  else {
    const std::string message =
        thrown_exactly<DataError>([] { write_file_atomically("/dev/full", std::string(100000, 'x')); });
    CHECK(has(message, "/dev/full"));
    CHECK(has(message, "No space left on device"));
    const std::string report = thrown_exactly<DataError>([] { write_file("/dev/full", "{}\n"); });
    CHECK(has(report, "/dev/full"));
  }
}

TEST_CASE("unseen26a: a file size limit mid-write keeps the earlier record whole and leaves no temporary",
          "[unseen26a]") {
  TempFolder folder;
  const auto file = folder.path / "trial.json";
  write_file_atomically(file, "earlier\n");
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    ::close(pipe_fds[0]);
    guard_output_files();
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string what = "nothing thrown";
    int status = 3;
    try {
      write_file_atomically(file, std::string(1 << 20, 'y'));
    } catch (const DataError& error) {
      what = error.what();
      status = typeid(error) == typeid(DataError) ? 0 : 4;
    } catch (...) {
      what = "another exception";
    }
    (void)!::write(pipe_fds[1], what.data(), what.size());
    ::_exit(status);
  }
  ::close(pipe_fds[1]);
  std::string message;
  char buffer[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;)
    message.append(buffer, std::size_t(n));
  ::close(pipe_fds[0]);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  INFO(message);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(has(message, file.string()));
  CHECK(calligraphy::testing_files::contents(file) == "earlier\n");
  CHECK(names_in(folder.path) == std::vector<std::string>{"trial.json"});
}

TEST_CASE("unseen26a: a record written into /proc or a missing folder is a DataError naming the path",
          "[unseen26a]") {
  TempFolder folder;
  const std::filesystem::path in_proc = "/proc/self/calligraphy-record.json";
  CHECK(has(thrown_exactly<DataError>([&] { write_file_atomically(in_proc, "{}"); }), in_proc.string()));
  CHECK(
      has(thrown_exactly<DataError>([&] { (void)write_file_exclusively(in_proc, "{}"); }), in_proc.string()));
  const auto missing = folder.path / "no" / "such" / "trial.csv";
  CHECK(has(thrown_exactly<DataError>([&] { write_file(missing.string(), "t,x\n"); }), missing.string()));
  CHECK_FALSE(std::filesystem::exists(folder.path / "no"));
}

TEST_CASE("unseen26a: a record written through a link replaces the file it names and leaves the link",
          "[unseen26a]") {
  TempFolder folder;
  const auto target = folder.path / "real.json";
  write_file_atomically(target, "old");
  const auto link = folder.path / "link.json";
  std::filesystem::create_symlink("real.json", link);
  write_file_atomically(link, "new");
  CHECK(std::filesystem::is_symlink(link));
  CHECK(calligraphy::testing_files::contents(target) == "new");
  const auto dangling = folder.path / "dangling.json";
  std::filesystem::create_symlink("made.json", dangling);
  write_file_atomically(dangling, "made");
  CHECK(std::filesystem::is_symlink(dangling));
  CHECK(calligraphy::testing_files::contents(folder.path / "made.json") == "made");
  const auto loop = folder.path / "loop.json";
  std::filesystem::create_symlink("loop.json", loop);
  CHECK(has(thrown_exactly<DataError>([&] { write_file_atomically(loop, "x"); }), loop.string()));
  CHECK(std::filesystem::is_symlink(loop));
}

TEST_CASE("unseen26a: a set with a link among its targets is refused by name and changes no earlier file",
          "[unseen26a]") {
  TempFolder folder;
  write_file_atomically(folder.path / "a.json", "a0");
  write_file_atomically(folder.path / "elsewhere.json", "e0");
  std::filesystem::create_symlink("elsewhere.json", folder.path / "b.json");
  {
    AtomicFileSet set;
    set.add(folder.path / "a.json", "a1");
    const auto link = folder.path / "b.json";
    CHECK(has(thrown_exactly<DataError>([&] { set.add(link, "b1"); }), link.string()));
  }
  CHECK(calligraphy::testing_files::contents(folder.path / "a.json") == "a0");
  CHECK(calligraphy::testing_files::contents(folder.path / "elsewhere.json") == "e0");
  CHECK(names_in(folder.path) == std::vector<std::string>{"a.json", "b.json", "elsewhere.json"});
}

TEST_CASE("unseen26a: an exclusive record made twice keeps the first, a folder in the way is named",
          "[unseen26a]") {
  TempFolder folder;
  const auto file = folder.path / "001.json";
  CHECK(write_file_exclusively(file, "first"));
  CHECK_FALSE(write_file_exclusively(file, "second"));
  CHECK(calligraphy::testing_files::contents(file) == "first");
  const auto in_the_way = folder.path / "trace.h5";
  std::filesystem::create_directory(in_the_way);
  CHECK(has(thrown_exactly<DataError>([&] { write_file_atomically(in_the_way, "x"); }), in_the_way.string()));
  CHECK(std::filesystem::is_directory(in_the_way));
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_trace_hdf5(in_the_way); }), in_the_way.string()));
  CHECK(
      has(thrown_exactly<DataError>([&] { (void)read_teacher_recording(in_the_way); }), in_the_way.string()));
  const auto csv = folder.path / "trace.csv";
  write_file_atomically(csv, "t,x,y,z\n0,0,0,0\n");
  CHECK(has(thrown_exactly<DataError>([&] { (void)read_trace_hdf5(csv); }), csv.string()));
}

// ---------------------------------------------------------------------------------------------------------
// Added after the first run and its fixes.

TEST_CASE("unseen26a: a pen that teleports between the characters mid-stroke meets a bounded, smooth force",
          "[unseen26a]") {
  static const Scene pair =
      Scene::lay_out({CharacterLibrary::embedded().load(U'十'), CharacterLibrary::embedded().load(U'十')});
  for (const double jump_m : {0.066, 0.5, -0.9}) {
    INFO("jump " << jump_m << " m");
    Renderer renderer(pair, ForceLawParameters{}, desktop());
    std::vector<Vec3> forces;
    for (int i = 0; i < 600; ++i) {
      DeviceState state = pressed(0.001 * i, 0.003, 1e-5 * i);
      if (i >= 300 && i < 320) state.position_m.x() += jump_m;  // a glitch of 20 ticks, then back
      forces.push_back(renderer.tick(state).force_n);
    }
    check_force_bounded_and_continuous(forces, desktop().max_force_n);
  }
}

TEST_CASE("unseen26a: reset() after the last stroke brings back the first stroke, SS and the force",
          "[unseen26a]") {
  Renderer renderer(cross_scene(), ForceLawParameters{}, desktop());
  SimulatedDevice device;
  device.open();
  PathHand hand(cross_scene(), SimulatedDeviceParameters{}.initial_position_m, 0.04);
  device.hand_port()->attach_hand(&hand);
  DeviceState state;
  RenderOutput out;
  for (int i = 0; i < 20000 && !out.finished; ++i) {
    REQUIRE(device.read_state(state) == DeviceFault::none);
    out = renderer.tick(state);
    REQUIRE(device.write_force(out.force_n) == DeviceFault::none);
    device.hand_port()->advance(0.001);
  }
  device.hand_port()->attach_hand(nullptr);
  REQUIRE(out.finished);
  renderer.reset();
  CHECK(renderer.state() == InteractionState::separation);
  const RenderOutput first = renderer.tick(pressed(state.time_s + 0.001, 0.003));
  CHECK_FALSE(first.finished);
  CHECK(first.stroke == 0);
  CHECK(first.character == 0);
  Vec3 force = first.force_n;
  for (int i = 2; i < 400; ++i) force = renderer.tick(pressed(state.time_s + 0.001 * i, 0.003)).force_n;
  CHECK(force.z() > 1.0);  // the paper pushes again
}

TEST_CASE(
    "unseen26a: a loop ticking a session ends by itself at the time limit, restarted it ticks once at zero",
    "[unseen26a]") {
  OwnDevice device;
  device.open();
  TrialOptions options;
  options.max_duration_s = 0.05;  // 50 ticks
  TrialSession session(cross_scene(), device.info(), options);
  session.reserve_trace();
  ServoLoop loop(device, session.servo_callback());
  loop.start();
  loop.wait();  // ended by the session's stop, no fault: returns
  CHECK(device.reads() == 50);
  CHECK(session.ticks() == 50);
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  loop.start();  // an application that restarts the loop on the spent trial
  loop.wait();
  CHECK(device.reads() == 51);
  CHECK(device.last_force_norm() == 0.0);
  CHECK_FALSE(device.forces_enabled());
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.trace.size() == 50);
  CHECK(result.trace.back().time_s == Approx(0.049));
}

TEST_CASE("unseen26a: a session that keeps no trace never allocates a tick and still counts what it saw",
          "[unseen26a]") {
  TrialOptions options;
  options.keep_trace = false;
  options.max_duration_s = 3.0;
  TrialSession session(cross_scene(), desktop(), options);
  session.reserve_trace();  // nothing when the trace is not kept
  const long before = counted_allocations.load();
  count_this_thread = true;
  for (int i = 0; i < 2500; ++i) {
    DeviceState state = pressed(0.001 * i, 0.003, 1e-5 * i);
    if (i % 100 == 0) state.position_m.y() = kNaN;
    (void)session.step(state);
  }
  count_this_thread = false;
  if (kCountsAllocations) CHECK(counted_allocations.load() - before == 0);
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.trace.empty());
  CHECK(result.metrics.readings_rejected == 25);
  CHECK(result.metrics.max_force_n > 1.0);
}

TEST_CASE("unseen26a: finish at a time on the device's clock closes the metrics at that time from the origin",
          "[unseen26a]") {
  TrialSession session(cross_scene(), desktop(), TrialOptions{});
  for (int i = 0; i < 1000; ++i) (void)session.step(pressed(5000.0 + 0.001 * i, -0.02));  // hovering
  const TrialResult result = session.finish(TrialEnd::interrupted, "window closed", 5001.5);
  CHECK(result.metrics.time_s == Approx(1.5));
  CHECK(result.abort_reason == "window closed");
  CHECK(result.metrics.strokes_completed == 0);
  CHECK_FALSE(result.metrics.mean_deviation_m.has_value());
}

TEST_CASE(
    "unseen26a: an exclusive record over a dangling link makes nothing, a link to a missing folder is named",
    "[unseen26a]") {
  TempFolder folder;
  const auto dangling = folder.path / "001.json";
  std::filesystem::create_symlink("elsewhere.json", dangling);
  CHECK_FALSE(write_file_exclusively(dangling, "record"));
  CHECK_FALSE(std::filesystem::exists(folder.path / "elsewhere.json"));
  CHECK(std::filesystem::is_symlink(dangling));
  std::filesystem::create_directory_symlink(folder.path / "gone", folder.path / "trials");
  const auto inside = folder.path / "trials" / "001.json";
  CHECK(has(thrown_exactly<DataError>([&] { write_file_atomically(inside, "x"); }), inside.string()));
  CHECK(has(thrown_exactly<DataError>([&] { (void)write_file_exclusively(inside, "x"); }), inside.string()));
  CHECK_FALSE(std::filesystem::exists(folder.path / "gone"));
}
