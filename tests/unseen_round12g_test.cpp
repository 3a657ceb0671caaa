// A haptic application's hostile round against the library's public headers: the cases were written from the
// documented contracts (include/calligraphy/**'s doc comments, docs/servo-loop.md, docs/devices.md,
// docs/architecture.md) before the implementation was read. The application ticks a trial from its own loop,
// runs the library's servo loop on a device of its own (one whose open, enable or reads fail, whose readings
// are NaN or 1e304 m, whose clock stalls or runs backwards, whose driver owns the servo clock and stops
// calling), and reads and writes trial records and traces. Each documented error must come as documented
// (its type, a message naming the thing), never a crash, a hang, undefined behaviour or a silent wrong
// result, and the force is zero and disabled after every fault.
#include <algorithm>
#include <atomic>
#include <bit>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/device_servo_clock.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/simulated_writing.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/runner.hpp"
#include "calligraphy/trial/session.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "temp_folder.hpp"

// Allocation count of the threads that ask for it (the servo path's promise: no allocation after
// reserve_trace): allocation_count.hpp, interposed only where the sanitizers do not own malloc.
#include "allocation_count.hpp"
#include "application_stylus.hpp"
#include "embedded_scenes.hpp"
#include "special_values.hpp"

using calligraphy::testing::cross_scene;
#if !defined(CALLIGRAPHY_TEST_SANITIZED) && defined(__GLIBC__)
#define UNSEEN12G_COUNTS_ALLOCATIONS 1
namespace {
using calligraphy::testing::count_this_thread;
using calligraphy::testing::counted_allocations;
}  // namespace
#endif

namespace {

using namespace calligraphy;
using Catch::Matchers::Contains;

using calligraphy::testing::kDenormal;
using calligraphy::testing::kInf;
using calligraphy::testing::kNaN;

const Scene& one_stroke_scene() {
  static const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'乙')});
  return scene;
}
// A point on the first stroke's start, `depth_m` into the paper.
Vec3 stroke_start(const Scene& scene, double depth_m) {
  const Vec2& start = scene.characters.front().strokes.front().centre_line.points_m.front();
  return {start.x(), start.y(), scene.layout.paper_z_m - depth_m};
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The application's device: a stylus the test places, on the machine's clock (or a clock the test drives),
// whose calls fail when told to. It keeps what it was commanded. Used by one thread at a time, as the loop's
// contract says; the counters the test reads while a loop runs are atomics.
class AppDevice : public HapticDevice {
 public:
  AppDevice() : info_(testing::application_stylus_info("app stylus")) {
    info_.manufacturer = "an application";
  }
  const DeviceInfo& info() const override { return info_; }
  void open() override {
    if (open_throws) throw CommunicationError("app stylus: the USB transfer timed out");
    open_ = true;
  }
  void close() noexcept override {
    forces_ = false;
    open_ = false;
    ++closes;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override {
    if (enabled && enable_throws) throw CommunicationError("app stylus: the amplifier did not answer");
    forces_ = enabled;
  }
  bool forces_enabled() const override { return forces_; }

  DeviceFault read_state(DeviceState& state) noexcept override {
    if (!open_) return DeviceFault::not_open;
    const std::uint64_t tick = reads.fetch_add(1, std::memory_order_relaxed) + 1;
    if (fail_read_at != 0 && tick >= fail_read_at) {
      forces_ = false;
      last_force = Vec3::Zero();
      return DeviceFault::link_lost;
    }
    state.position_m = position;
    state.velocity_m_s = Vec3::Zero();
    if (position_at) state.position_m = position_at(tick);
    state.time_s = clock ? clock(tick) : now_s();
    return DeviceFault::none;
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    if (!open_) return DeviceFault::not_open;
    writes.fetch_add(1, std::memory_order_relaxed);
    if (!force_n.allFinite()) {
      forces_ = false;
      last_force = Vec3::Zero();
      return DeviceFault::non_finite_force;
    }
    last_force = forces_ ? force_n : Vec3::Zero();
    largest_force_n = std::max(largest_force_n, last_force.norm());
    return DeviceFault::none;
  }

  DeviceInfo info_;
  Vec3 position = Vec3(0.0, 0.0, 0.02);            // above the paper: separation
  std::function<Vec3(std::uint64_t)> position_at;  // tick (1-based) -> position, when set
  std::function<double(std::uint64_t)> clock;      // tick (1-based) -> time stamp, when set
  std::uint64_t fail_read_at = 0;                  // the read that returns link_lost (0: none)
  bool open_throws = false;
  bool enable_throws = false;
  std::atomic<std::uint64_t> reads{0};
  std::atomic<std::uint64_t> writes{0};
  Vec3 last_force = Vec3::Zero();
  double largest_force_n = 0.0;
  int closes = 0;

 protected:
  bool open_ = false;
  bool forces_ = false;
};

// A device whose driver owns the servo thread (as OpenHaptics' scheduler does): a thread of its own calls the
// attached frame at `rate_hz`, until told to stop calling (a driver that hangs).
class ClockedDevice final : public AppDevice, public DeviceServoClock {
 public:
  explicit ClockedDevice(double rate_hz) : rate_hz_(rate_hz) {}
  ~ClockedDevice() override { detach(); }
  DeviceServoClock* servo_clock() noexcept override { return open_ ? this : nullptr; }
  double servo_rate_hz() const noexcept override { return rate_hz_; }
  void attach(FrameFunction frame, void* context) override {
    if (!open_) throw DeviceError("clocked stylus: not open");
    if (attach_throws) throw DeviceError("clocked stylus: the scheduler refused the callback");
    if (thread_.joinable()) throw StateError("clocked stylus: a frame function is attached");
    quit_ = false;
    thread_ = std::thread([this, frame, context] {
      while (!quit_.load()) {
        if (!silent.load()) frame(context);
        std::this_thread::sleep_for(std::chrono::microseconds(1000));
      }
    });
  }
  void detach() noexcept override {
    quit_ = true;
    if (thread_.joinable()) thread_.join();
  }
  std::atomic<bool> silent{false};  // the driver stops calling
  bool attach_throws = false;

 private:
  double rate_hz_;
  std::thread thread_;
  std::atomic<bool> quit_{false};
};

// Waits until `done` or `limit_s` of wall time passed; true when done. Not an assertion on time: a bound
// that turns a hang into a failure.
bool wait_until(const std::function<bool()>& done, double limit_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

template <typename Exception, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const Exception& e) {
    return e.what();
  }
  FAIL("nothing was thrown");
  return {};
}

// A short trial the simulated writer writes on the simulated device, its record, and the scene (shared by
// the record cases).
struct WrittenTrial {
  TrialSpec spec;
  TrialRun run;
  RecordedTrial record;
};
const WrittenTrial& written_trial() {
  static const WrittenTrial trial = [] {
    WrittenTrial t;
    t.spec.characters = "乙";
    t.spec.max_duration_s = 8.0;
    const Checked<TrialSpec> spec = Checked<TrialSpec>::check(t.spec);
    const DeviceRegistry registry = standard_device_registry();
    SimulatedWriting writing(t.spec);
    TrialRunInputs inputs;
    inputs.registry = &registry;
    inputs.hand_maker = &writing;
    t.run = run_trial_spec(spec, one_stroke_scene(), inputs);
    t.record = recorded_trial(t.spec, t.run, writing, one_stroke_scene());
    return t;
  }();
  return trial;
}

// Loop options without the stall bound: a case about something else must not end by a stall of a loaded
// machine.
ServoLoopOptions unstalled() {
  ServoLoopOptions options;
  options.stall_timeout_s = 0.0;
  return options;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

}  // namespace

// ---------------------------------------------------------------- ServoLoopOptions and construction

TEST_CASE("unseen12g: ServoLoopOptions refuse every bound's far side and non-finite values naming the field",
          "[unseen12g]") {
  struct Bad {
    const char* field;
    std::function<void(ServoLoopOptions&)> set;
  };
  const std::vector<Bad> bad{
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = kNaN; }},
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = kInf; }},
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = 99.999; }},
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = 10000.001; }},
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = -0.0; }},
      {"rate_hz", [](ServoLoopOptions& o) { o.rate_hz = 1e308; }},
      {"max_force_age_s", [](ServoLoopOptions& o) { o.max_force_age_s = 0.0; }},
      {"max_force_age_s", [](ServoLoopOptions& o) { o.max_force_age_s = kDenormal * -1.0; }},
      {"max_force_age_s", [](ServoLoopOptions& o) { o.max_force_age_s = 1.0000001; }},
      {"max_force_age_s", [](ServoLoopOptions& o) { o.max_force_age_s = kNaN; }},
      {"stall_timeout_s", [](ServoLoopOptions& o) { o.stall_timeout_s = 60.000001; }},
      {"stall_timeout_s", [](ServoLoopOptions& o) { o.stall_timeout_s = -1e-300; }},
      {"stall_timeout_s", [](ServoLoopOptions& o) { o.stall_timeout_s = kNaN; }},
      {"stall_timeout_s", [](ServoLoopOptions& o) { o.stall_timeout_s = kInf; }},
      {"priority", [](ServoLoopOptions& o) { o.priority = 100; }},
      {"priority", [](ServoLoopOptions& o) { o.priority = -1; }},
      {"priority", [](ServoLoopOptions& o) { o.realtime = RealtimeMode::enforce; }},  // 0 with enforce
  };
  AppDevice device;
  for (const Bad& b : bad) {
    ServoLoopOptions options;
    b.set(options);
    INFO(b.field);
    CHECK_THAT(message_of<InvalidArgument>([&] { options.validate(); }), Contains(b.field));
    CHECK_THROWS_AS(ServoLoop(
                        device, [](const DeviceState&, double) { return ServoCommand{}; }, options),
                    InvalidArgument);
  }
  // The edges themselves are in range; -0 s of stall bound is 0 (off), and a denormal force age is > 0.
  ServoLoopOptions edges;
  edges.rate_hz = 100.0;
  edges.stall_timeout_s = -0.0;
  edges.max_force_age_s = kDenormal;
  CHECK_NOTHROW(edges.validate());
  edges.rate_hz = 10000.0;
  edges.stall_timeout_s = kMaxStallTimeoutS;
  edges.max_force_age_s = 1.0;
  CHECK_NOTHROW(edges.validate());
}

TEST_CASE("unseen12g: an empty callback is refused at construction, not at the first tick", "[unseen12g]") {
  AppDevice device;
  CHECK_THROWS_AS(ServoLoop(device, ServoCallback{}), InvalidArgument);
  // An empty after-write hook is documented as optional: accepted.
  CHECK_NOTHROW(ServoLoop(
      device, [](const DeviceState&, double) { return ServoCommand{}; }, ServoLoopOptions{},
      ServoLoop::AfterForceWrite{}));
}

// ---------------------------------------------------------------- calls in the wrong order

TEST_CASE("unseen12g: a loop on a device that was never opened refuses to start and stays stopped",
          "[unseen12g]") {
  AppDevice device;  // not opened
  ServoLoop loop(device, [](const DeviceState&, double) { return ServoCommand{Vec3(1.0, 0.0, 0.0), false}; });
  CHECK_THROWS_AS(loop.start(), DeviceError);
  CHECK_FALSE(loop.running());
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(loop.stop());  // nothing was running: no fault
  CHECK(device.writes.load() == 0);
}

TEST_CASE("unseen12g: stop before start, stop twice and wait after stop neither throw nor hang",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  ServoLoop loop(
      device,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.5, 0.0, 0.0), false};
      },
      unstalled());
  CHECK_FALSE(loop.stop());
  CHECK_FALSE(loop.stop());
  loop.start();
  REQUIRE(wait_until([&] { return device.writes.load() >= 3; }));
  const LoopFault first = loop.stop();
  CHECK_FALSE(first);
  CHECK_FALSE(loop.stop());
  CHECK_FALSE(loop.running());
  CHECK_NOTHROW(loop.wait());  // ended without a fault: returns
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: start twice is a StateError and leaves the first run ticking", "[unseen12g]") {
  AppDevice device;
  device.open();
  ServoLoop loop(
      device, [](const DeviceState&, double) { return ServoCommand{}; }, unstalled());
  loop.start();
  CHECK_THROWS_AS(loop.start(), StateError);
  CHECK(loop.running());
  const std::uint64_t before = device.writes.load();
  REQUIRE(wait_until([&] { return device.writes.load() > before + 2; }));
  CHECK_FALSE(loop.stop());
}

TEST_CASE("unseen12g: destroying a running loop stops it with zero force and forces off", "[unseen12g]") {
  AppDevice device;
  device.open();
  {
    ServoLoop loop(
        device,
        [](const DeviceState&, double) {
          return ServoCommand{Vec3(0.0, 0.7, 0.0), false};
        },
        unstalled());
    loop.start();
    REQUIRE(wait_until([&] { return device.writes.load() >= 5; }));
  }
  const std::uint64_t writes = device.writes.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  CHECK(device.writes.load() == writes);  // no thread writes after the destructor returned
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: a loop restarted after a fault clears the fault and its statistics", "[unseen12g]") {
  AppDevice device;
  device.open();
  device.fail_read_at = 4;
  ServoLoop loop(
      device,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.3, 0.0, 0.0), false};
      },
      unstalled());
  loop.start();
  CHECK_THROWS_AS(loop.wait(), CommunicationError);
  CHECK(loop.stats().fault.kind == LoopFaultKind::device);
  device.fail_read_at = 0;
  device.open();  // a link fault closed it, as a device does
  loop.start();
  REQUIRE(wait_until([&] { return loop.stats().ticks >= 3; }));
  CHECK(loop.stats().fault.kind == LoopFaultKind::none);
  CHECK_FALSE(loop.stop());
}

// ---------------------------------------------------------------- faults of the device and the callback

TEST_CASE("unseen12g: enable_forces throwing at start is a DeviceError and leaves the loop stopped",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  device.enable_throws = true;
  ServoLoop loop(device, [](const DeviceState&, double) { return ServoCommand{Vec3(1.0, 0.0, 0.0), false}; });
  CHECK_THROWS_AS(loop.start(), CommunicationError);
  CHECK_FALSE(loop.running());
  CHECK(device.writes.load() == 0);
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(loop.stop());
}

TEST_CASE("unseen12g: a link lost mid-run ends it with the model named, zero force and forces off",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  device.fail_read_at = 6;
  ServoLoop loop(
      device,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.0, 0.0, 1.5), false};
      },
      unstalled());
  loop.start();
  const std::string what = message_of<CommunicationError>([&] { loop.wait(); });
  CHECK_THAT(what, Contains("app stylus"));
  const ServoLoopStats stats = loop.stats();
  CHECK(stats.fault.kind == LoopFaultKind::device);
  CHECK(stats.fault.device == DeviceFault::link_lost);
  CHECK(stats.fault.message == to_string(DeviceFault::link_lost));
  CHECK(stats.ticks == 5);  // the failed read gave no tick
  CHECK_FALSE(loop.running());
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: a NaN force from the callback is never held: the run ends as a SafetyFault, force zero",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  std::atomic<int> calls{0};
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) {
        const int n = ++calls;
        return ServoCommand{n < 4 ? Vec3(0.2, 0.0, 0.0) : Vec3(kNaN, 0.0, 0.0), false};
      },
      unstalled());
  loop.start();
  CHECK_THROWS_AS(loop.wait(), SafetyFault);
  CHECK(loop.stats().fault.device == DeviceFault::non_finite_force);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: a callback's exception comes back from wait() as itself, its message cut to 127 bytes",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  const std::string long_message(300, 'q');
  std::atomic<int> calls{0};
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) -> ServoCommand {
        if (++calls == 3) throw std::out_of_range(long_message);
        return ServoCommand{Vec3(0.4, 0.0, 0.0), false};
      },
      unstalled());
  loop.start();
  CHECK_THROWS_MATCHES(loop.wait(), std::out_of_range, Catch::Matchers::Message(long_message));
  const ServoLoopStats stats = loop.stats();
  CHECK(stats.fault.kind == LoopFaultKind::callback);
  CHECK(stats.fault.message.size() <= 127);
  CHECK(long_message.rfind(stats.fault.message, 0) == 0);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE(
    "unseen12g: a callback throwing a non-standard exception, and an after-write hook throwing, are "
    "contained",
    "[unseen12g]") {
  AppDevice device;
  device.open();
  {
    ServoLoop loop(
        device, [](const DeviceState&, double) -> ServoCommand { throw 42; }, unstalled());
    loop.start();
    CHECK_THROWS_AS(loop.wait(), int);
    CHECK(loop.stats().fault.kind == LoopFaultKind::callback);
    CHECK_FALSE(device.forces_enabled());
  }
  {
    std::atomic<int> hooks{0};
    ServoLoop loop(
        device,
        [](const DeviceState&, double) {
          return ServoCommand{Vec3(0.0, 0.1, 0.0), false};
        },
        unstalled(),
        [&] {
          if (++hooks == 2) throw std::logic_error("hook broke");
        });
    loop.start();
    CHECK_THROWS_WITH(loop.wait(), "hook broke");
    CHECK(loop.stats().fault.kind == LoopFaultKind::callback);
    CHECK_FALSE(device.forces_enabled());
    CHECK(device.last_force == Vec3::Zero());
  }
}

TEST_CASE("unseen12g: a callback that takes 10 ms has its stale force withheld and the loop goes on",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  std::atomic<int> calls{0};
  ServoLoopOptions options;
  options.stall_timeout_s = 0.0;  // off: this case is the stale-force guard alone
  ServoLoop loop(device, [&](const DeviceState&, double) {
    const int n = ++calls;
    if (n == 5) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // beyond the 2 ms bound
      return ServoCommand{Vec3(2.5, 0.0, 0.0), false};             // the stale force
    }
    return ServoCommand{Vec3(0.25, 0.0, 0.0), false};
  });
  loop.start();
  REQUIRE(wait_until([&] { return calls.load() >= 12; }));
  CHECK(loop.running());
  CHECK_FALSE(loop.stop());
  const ServoLoopStats stats = loop.stats();
  CHECK(stats.forces_withheld >= 1);
  CHECK(device.largest_force_n <= 0.25 + 1e-12);  // the 2.5 N of the slow tick never reached the device
}

TEST_CASE(
    "unseen12g: stop() called from inside the callback only requests, and stops the run without a "
    "deadlock",
    "[unseen12g]") {
  AppDevice device;
  device.open();
  std::atomic<int> calls{0};
  ServoLoop* self = nullptr;
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) {
        if (++calls == 3) (void)self->stop();
        return ServoCommand{Vec3(0.1, 0.0, 0.0), false};
      },
      unstalled());
  self = &loop;
  loop.start();
  REQUIRE(wait_until([&] { return !loop.running(); }));
  CHECK_FALSE(loop.stop());
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: statistics read from another thread while the loop runs are consistent",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  ServoLoop loop(
      device, [](const DeviceState&, double) { return ServoCommand{}; }, unstalled());
  loop.start();
  std::atomic<bool> done{false};
  std::uint64_t last_ticks = 0;
  bool monotonic = true;
  std::thread reader([&] {
    while (!done.load()) {
      const ServoLoopStats s = loop.stats();
      if (s.ticks < last_ticks) monotonic = false;
      last_ticks = s.ticks;
      (void)loop.running();
    }
  });
  REQUIRE(wait_until([&] { return loop.stats().ticks >= 20; }));
  done = true;
  reader.join();
  CHECK(monotonic);
  CHECK_FALSE(loop.stop());
  const ServoLoopStats s = loop.stats();
  CHECK_FALSE(s.running);
  CHECK(s.rate_hz == 1000.0);
  CHECK(s.callback_us_mean >= 0.0);
  CHECK(std::isfinite(s.period_jitter_us_max));
}

// ---------------------------------------------------------------- rates and the device's own clock

TEST_CASE("unseen12g: a callback that says NaN Hz, or 0.5 Hz off, is refused at start naming the rate",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  const auto plain = [](const DeviceState&, double) { return ServoCommand{}; };
  for (const double said : {kNaN, 999.5, kInf, -1000.0}) {
    INFO(said);
    RatedServoCallback<decltype(plain)> rated{plain, said, "TrialOptions::rate_hz"};
    ServoLoop loop(device, rated);
    CHECK_THAT(message_of<InvalidArgument>([&] { loop.start(); }), Contains("TrialOptions::rate_hz"));
    CHECK_FALSE(loop.running());
    CHECK_FALSE(device.forces_enabled());
  }
}

TEST_CASE("unseen12g: a callback that names no place for its rate is still told which rate to change",
          "[unseen12g]") {
  AppDevice device;
  device.open();
  const auto plain = [](const DeviceState&, double) { return ServoCommand{}; };
  for (const char* name : {static_cast<const char*>(nullptr), ""}) {
    RatedServoCallback<decltype(plain)> rated{plain, 500.0, name};
    ServoLoop loop(device, rated);
    const std::string message = message_of<InvalidArgument>([&] { loop.start(); });
    CHECK_THAT(message, Contains("the callback's servo_rate_hz()"));
    CHECK_THAT(message, !Contains("(),"));  // the old message: "built for 500 Hz (), but ..."
    CHECK_FALSE(loop.running());
  }
}

TEST_CASE(
    "unseen12g: a device clock at NaN or 0 Hz, or whose attach throws, refuses the start with forces off",
    "[unseen12g]") {
  for (const double rate : {kNaN, 0.0, 500.0}) {
    INFO(rate);
    ClockedDevice device(rate);
    device.open();
    ServoLoop loop(device, [](const DeviceState&, double) {
      return ServoCommand{Vec3(1.0, 0.0, 0.0), false};
    });
    CHECK_THROWS_AS(loop.start(), InvalidArgument);
    CHECK_FALSE(loop.running());
    CHECK_FALSE(device.forces_enabled());
    CHECK(device.writes.load() == 0);
  }
  ClockedDevice device(1000.0);
  device.open();
  device.attach_throws = true;
  ServoLoop loop(device, [](const DeviceState&, double) { return ServoCommand{Vec3(1.0, 0.0, 0.0), false}; });
  CHECK_THROWS_AS(loop.start(), DeviceError);
  CHECK_FALSE(loop.running());
  CHECK_FALSE(device.forces_enabled());  // a start that failed leaves no force enabled
}

TEST_CASE("unseen12g: a driver that stops calling ends the run as a watchdog fault with zero force",
          "[unseen12g]") {
  ClockedDevice device(1000.0);
  device.open();
  ServoLoopOptions options;
  options.stall_timeout_s = 0.03;
  ServoLoop loop(
      device,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.0, 0.6, 0.0), false};
      },
      options);
  loop.start();
  REQUIRE(wait_until([&] { return device.writes.load() >= 5; }));
  device.silent = true;
  const bool ended = wait_until([&] { return !loop.running(); });
  CHECK(ended);  // running() turns false once the silence passed the bound
  const LoopFault fault = loop.stop();
  CHECK(fault.kind == LoopFaultKind::watchdog);
  CHECK(fault.message == kStallFaultMessage);
  CHECK(loop.stats().realtime.device_clock);
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

// ---------------------------------------------------------------- the trial session from the application's
// loop

TEST_CASE("unseen12g: TrialSession refuses a device whose maximum force is 0, negative, NaN or infinite",
          "[unseen12g]") {
  for (const double max_force : {0.0, -0.0, -3.0, kNaN, kInf, kDenormal * -1.0}) {
    INFO(max_force);
    DeviceInfo info = simulated_phantom_desktop_info();
    info.max_force_n = max_force;
    CHECK_THROWS_AS(TrialSession(cross_scene(), info, TrialOptions{}), InvalidArgument);
  }
}

TEST_CASE("unseen12g: TrialOptions refuse a NaN, infinite or absurd duration and rate before any allocation",
          "[unseen12g]") {
  struct Bad {
    const char* field;
    std::function<void(TrialOptions&)> set;
  };
  const std::vector<Bad> bad{
      {"max_duration_s", [](TrialOptions& o) { o.max_duration_s = kNaN; }},
      {"max_duration_s", [](TrialOptions& o) { o.max_duration_s = kInf; }},
      {"max_duration_s", [](TrialOptions& o) { o.max_duration_s = 0.0; }},
      {"max_duration_s", [](TrialOptions& o) { o.max_duration_s = -0.0; }},
      {"max_duration_s", [](TrialOptions& o) { o.max_duration_s = 1e308; }},  // 1e311 ticks to reserve
      {"rate_hz", [](TrialOptions& o) { o.rate_hz = kNaN; }},
      {"rate_hz", [](TrialOptions& o) { o.rate_hz = 100000.5; }},
      {"rate_hz",
       [](TrialOptions& o) {
         o.rate_hz = 20000.0;
         o.pacing = TrialPacing::real_time;
       }},
  };
  for (const Bad& b : bad) {
    TrialOptions options;
    b.set(options);
    INFO(b.field);
    CHECK_THAT(message_of<InvalidArgument>(
                   [&] { TrialSession session(cross_scene(), simulated_phantom_desktop_info(), options); }),
               Contains(b.field));
  }
}

TEST_CASE("unseen12g: step() on NaN, infinite and 1e304 m readings gives exactly zero force, and recovers",
          "[unseen12g]") {
  TrialSession session(cross_scene(), simulated_phantom_desktop_info(), TrialOptions{});
  const Vec3 pressing = stroke_start(cross_scene(), 0.002);
  double t = 0.0;
  const auto step = [&](const Vec3& position, const Vec3& velocity = Vec3::Zero()) {
    DeviceState state;
    state.position_m = position;
    state.velocity_m_s = velocity;
    state.time_s = (t += 0.001);
    return session.step(state);
  };
  for (int i = 0; i < 50; ++i) (void)step(pressing);
  REQUIRE(step(pressing).force_n.norm() > 0.0);  // the paper pushes back
  const std::vector<Vec3> garbled{Vec3(kNaN, 0, 0),  Vec3(0, kInf, 0),   Vec3(0, 0, -kInf),
                                  Vec3(1e304, 0, 0), Vec3(0, -1e304, 0), Vec3(0, 0, -10.000001)};
  for (const Vec3& p : garbled) {
    INFO(p.transpose());
    const ServoCommand command = step(p);
    CHECK(command.force_n == Vec3::Zero());
    CHECK(session.last_output().input_rejected);
  }
  const ServoCommand velocity_nan = step(pressing, Vec3(0.0, kNaN, 0.0));
  CHECK(velocity_nan.force_n == Vec3::Zero());
  CHECK(session.last_output().input_rejected);
  // Denormal and -0 coordinates are readings, not faults; the edge of kMaxDeviceReadingM is still a reading.
  for (const Vec3& p : {Vec3(pressing.x() + kDenormal, pressing.y(), pressing.z()), Vec3(-0.0, -0.0, 0.01),
                        Vec3(kMaxDeviceReadingM, 0.0, 0.02)}) {
    INFO(p.transpose());
    const ServoCommand command = step(p);
    CHECK(command.force_n.allFinite());
    CHECK_FALSE(session.last_output().input_rejected);
  }
  for (int i = 0; i < 50; ++i) (void)step(pressing);
  CHECK(step(pressing).force_n.norm() > 0.0);
  const TrialResult result = session.finish(TrialEnd::time_limit);
  for (const TrialSample& s : result.trace) {
    CHECK(std::isfinite(s.time_s));
    CHECK(s.force_n.allFinite());
  }
  CHECK(std::isfinite(result.metrics.max_force_n));
  CHECK(std::isfinite(result.metrics.max_force_step_n));
  // Each rejected reading counted, and only those: the denormal, -0 and edge readings were taken.
  CHECK(result.metrics.readings_rejected == garbled.size() + 1);
}

TEST_CASE("unseen12g: a NaN, infinite or 1e308 device time stamp gives zero force and a finite trace",
          "[unseen12g]") {
  TrialSession session(cross_scene(), simulated_phantom_desktop_info(), TrialOptions{});
  const Vec3 pressing = stroke_start(cross_scene(), 0.002);
  DeviceState state;
  state.position_m = pressing;
  for (int i = 1; i <= 100; ++i) {
    state.time_s = 5000.0 + 0.001 * i;
    (void)session.step(state);
  }
  for (const double stamp : {kNaN, kInf, 1e308}) {
    INFO(stamp);
    state.time_s = stamp;
    const ServoCommand command = session.step(state);
    CHECK(command.force_n.allFinite());
    if (!std::isfinite(stamp)) CHECK(command.force_n == Vec3::Zero());
  }
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(std::isfinite(result.device_tick_rate_hz));
  CHECK(result.device_tick_rate_hz >= 0.0);
  for (const TrialSample& s : result.trace) CHECK(std::isfinite(s.time_s));
  CHECK(std::isfinite(result.metrics.time_s));
}

TEST_CASE("unseen12g: a clock that stalls or runs backwards never gives a negative or non-finite tick rate",
          "[unseen12g]") {
  for (const double step_s : {0.0, -0.001}) {
    INFO(step_s);
    TrialSession session(cross_scene(), simulated_phantom_desktop_info(), TrialOptions{});
    DeviceState state;
    state.position_m = stroke_start(cross_scene(), 0.001);
    for (int i = 0; i < 200; ++i) {
      state.time_s = 100.0 + step_s * i;
      CHECK(session.step(state).force_n.allFinite());
    }
    const TrialResult result = session.finish(TrialEnd::time_limit);
    CHECK(result.trace.size() == 200);
    CHECK(std::isfinite(result.device_tick_rate_hz));
    CHECK(result.device_tick_rate_hz >= 0.0);
    CHECK(result.metrics.time_s >= 0.0);
    // The recorded trace is one the library's own trace reader reads back (times must not decrease).
    const std::string csv = trial_csv(result.trace);
    CHECK_NOTHROW(parse_pen_trace_csv(csv, "stalled.csv", Placement{}));
  }
}

TEST_CASE("unseen12g: finish with no tick, and finish called twice, neither crash nor make up numbers",
          "[unseen12g]") {
  TrialSession session(cross_scene(), simulated_phantom_desktop_info(), TrialOptions{});
  const TrialResult result = session.finish(TrialEnd::interrupted, "closed before the first tick");
  CHECK(result.trace.empty());
  CHECK(result.aborted);
  CHECK(result.abort_reason == "closed before the first tick");
  CHECK(result.device_tick_rate_hz == 0.0);
  CHECK(result.metrics.strokes_completed == 0);
  CHECK(result.metrics.strokes_total == cross_scene().stroke_count());
  CHECK_FALSE(result.metrics.mean_deviation_m.has_value());
  CHECK(std::isfinite(result.metrics.time_s));
  // The session is spent: a second finish is a call in the wrong state.
  CHECK_THROWS_AS(session.finish(TrialEnd::completed), StateError);
}

TEST_CASE("unseen12g: step never allocates after reserve_trace, with a display attached", "[unseen12g]") {
#if defined(UNSEEN12G_COUNTS_ALLOCATIONS)
  DisplayChannel channel;
  TrialOptions options;
  options.max_duration_s = 3.0;
  options.display = &channel;
  TrialSession session(cross_scene(), simulated_phantom_desktop_info(), options);
  session.reserve_trace();
  const Scene& scene = cross_scene();
  const auto& points = scene.characters.front().strokes.front().centre_line.points_m;
  long allocations = -1;
  std::thread servo([&] {
    count_this_thread = true;
    const long before = counted_allocations.load();
    DeviceState state;
    for (int i = 0; i < 2500; ++i) {
      const double s = std::min(1.0, i / 1500.0);
      const std::size_t k =
          std::min(points.size() - 1, static_cast<std::size_t>(s * static_cast<double>(points.size() - 1)));
      state.position_m = Vec3(points[k].x(), points[k].y(), i < 100 ? 0.01 : -0.001);
      state.time_s = 0.001 * i;
      if (session.step(state).stop) break;
    }
    allocations = counted_allocations.load() - before;
    count_this_thread = false;
  });
  servo.join();
  CHECK(allocations == 0);
  CHECK(channel.publications() >= 1);
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.trace.size() == session.ticks());
#else
  SUCCEED("malloc belongs to the sanitizer here");
#endif
}

TEST_CASE("unseen12g: the display is read from another thread while the servo thread steps", "[unseen12g]") {
  DisplayChannelOptions channel_options;
  channel_options.trace_capacity = 64;  // small: points are dropped and counted, never waited for
  DisplayChannel channel(channel_options);
  TrialOptions options;
  options.max_duration_s = 2.0;
  TrialSession session(cross_scene(), simulated_phantom_desktop_info(), options);
  session.attach_display(&channel);
  session.reserve_trace();
  std::atomic<bool> done{false};
  std::size_t points = 0;
  std::thread display([&] {
    TracePoint point;
    DisplayEvent event;
    DisplaySnapshot snapshot;
    while (!done.load()) {
      (void)channel.try_latest(snapshot);
      while (channel.poll_trace(point)) ++points;
      while (channel.poll_event(event)) {
      }
    }
  });
  DeviceState state;
  state.position_m = stroke_start(cross_scene(), 0.001);
  for (int i = 0; i < 1500; ++i) {
    state.time_s = 0.001 * i;
    (void)session.step(state);
  }
  done = true;
  display.join();
  CHECK(channel.publications() >= 1500);
  CHECK(points + channel.dropped_trace_points() <= 1500);
  (void)session.finish(TrialEnd::time_limit);
  DisplayChannelOptions bad;
  bad.trace_every_ticks = 0;
  CHECK_THROWS_AS(DisplayChannel(bad), InvalidArgument);
  bad.trace_every_ticks = 1001;
  CHECK_THROWS_AS(DisplayChannel(bad), InvalidArgument);
}

TEST_CASE("unseen12g: an empty scene is refused or finishes at once, never a crash", "[unseen12g]") {
  const Scene empty = Scene::lay_out({});
  try {
    TrialSession session(empty, simulated_phantom_desktop_info(), TrialOptions{});
    DeviceState state;
    const ServoCommand command = session.step(state);
    CHECK(command.stop);
    CHECK(command.force_n == Vec3::Zero());
    const TrialResult result = session.finish(TrialEnd::completed);
    CHECK(result.metrics.strokes_total == 0);
  } catch (const InvalidArgument& e) {
    CHECK_FALSE(std::string(e.what()).empty());
  }
}

// ---------------------------------------------------------------- whole trials on an application's device

TEST_CASE("unseen12g: run_trial on a device whose open throws propagates it and records nothing",
          "[unseen12g]") {
  AppDevice device;
  device.open_throws = true;
  TrialOptions options;
  options.max_duration_s = 0.05;
  CHECK_THROWS_AS(run_trial(device, cross_scene(), options), CommunicationError);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.writes.load() == 0);
}

TEST_CASE("unseen12g: run_trial lock-step without a hand is refused and the device is closed again",
          "[unseen12g]") {
  AppDevice device;
  TrialOptions options;
  options.pacing = TrialPacing::lock_step;
  options.max_duration_s = 0.05;
  CHECK_THROWS_AS(run_trial(device, cross_scene(), options), InvalidArgument);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.writes.load() == 0);
}

TEST_CASE("unseen12g: a real-time trial whose device loses its link keeps every tick and names the fault",
          "[unseen12g]") {
  AppDevice device;
  device.position = stroke_start(cross_scene(), 0.001);
  device.fail_read_at = 40;
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.max_duration_s = 5.0;
  options.loop.stall_timeout_s = 0.0;
  const TrialResult result = run_trial(device, cross_scene(), options);
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.aborted);
  CHECK(result.device_fault == DeviceFault::link_lost);
  CHECK_THAT(result.abort_reason, Contains("app stylus"));
  CHECK(result.trace.size() == 39);
  REQUIRE(result.loop.has_value());
  CHECK(result.loop->fault.device == DeviceFault::link_lost);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.forces_enabled());
  CHECK(device.last_force == Vec3::Zero());
}

TEST_CASE("unseen12g: a real-time trial on a device that reads 1e304 m commands only zero force",
          "[unseen12g]") {
  AppDevice device;
  device.position_at = [](std::uint64_t tick) {
    return tick % 2 == 0 ? Vec3(1e304, -1e304, 0.0) : Vec3(kNaN, 0.0, -0.001);
  };
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.max_duration_s = 0.05;
  options.loop.stall_timeout_s = 0.0;
  const TrialResult result = run_trial(device, cross_scene(), options);
  CHECK(device.largest_force_n == 0.0);
  CHECK(result.metrics.max_force_n == 0.0);
  CHECK(result.metrics.strokes_completed == 0);
  CHECK_FALSE(result.metrics.mean_deviation_m.has_value());
}

// ---------------------------------------------------------------- the simulated device

TEST_CASE(
    "unseen12g: SimulatedDevice::advance refuses NaN, inf, negative and clock-overflowing steps, state "
    "unchanged",
    "[unseen12g]") {
  SimulatedDevice device;
  device.open();
  device.advance(0.25);
  const Vec3 before = device.true_position();
  const double time_before = device.time();
  for (const double dt : {kNaN, kInf, -kInf, -1e-9, -kDenormal, 1e308, 4.7e9}) {
    INFO(dt);
    CHECK_THROWS_AS(device.advance(dt), InvalidArgument);
    CHECK(device.time() == time_before);
    CHECK(device.true_position() == before);
  }
  device.advance(-0.0);  // -0 s is a step of nothing
  device.advance(kDenormal);
  CHECK(device.time() == time_before);
}

TEST_CASE(
    "unseen12g: SimulatedDevice saturates 1e308 N keeping its direction and drops NaN and disabled forces",
    "[unseen12g]") {
  SimulatedDevice device;
  device.open();
  device.enable_forces(true);
  const double max_force = device.info().max_force_n;
  CHECK(device.write_force(Vec3(1e308, 1e308, 0.0)) == DeviceFault::none);
  CHECK(device.applied_force().norm() == Approx(max_force));
  CHECK(device.applied_force().x() == Approx(device.applied_force().y()));
  CHECK(device.write_force(Vec3(kNaN, 1.0, 0.0)) == DeviceFault::none);
  CHECK(device.applied_force() == Vec3::Zero());
  CHECK(device.write_force(Vec3(0.0, -kInf, 0.0)) == DeviceFault::none);
  CHECK(device.applied_force() == Vec3::Zero());
  CHECK(device.write_force(Vec3(kDenormal, 0.0, -0.0)) == DeviceFault::none);
  CHECK(device.applied_force().allFinite());
  device.enable_forces(false);
  CHECK(device.write_force(Vec3(1.0, 0.0, 0.0)) == DeviceFault::none);
  CHECK(device.applied_force() == Vec3::Zero());
}

TEST_CASE("unseen12g: SimulatedDeviceParameters refuse each field past its range naming it", "[unseen12g]") {
  struct Bad {
    const char* field;
    std::function<void(SimulatedDeviceParameters&)> set;
  };
  const std::vector<Bad> bad{
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = 0.0; }},
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = kNaN; }},
      {"moving_mass_kg", [](SimulatedDeviceParameters& p) { p.moving_mass_kg = 1000.001; }},
      {"damping_n_s_per_m", [](SimulatedDeviceParameters& p) { p.damping_n_s_per_m = -kDenormal; }},
      {"encoder_resolution_m", [](SimulatedDeviceParameters& p) { p.encoder_resolution_m = 1e-10; }},
      {"encoder_resolution_m", [](SimulatedDeviceParameters& p) { p.encoder_resolution_m = kDenormal; }},
      {"velocity_cutoff_hz", [](SimulatedDeviceParameters& p) { p.velocity_cutoff_hz = 0.0; }},
      {"physics_substeps", [](SimulatedDeviceParameters& p) { p.physics_substeps = 0; }},
      {"physics_substeps", [](SimulatedDeviceParameters& p) { p.physics_substeps = 10001; }},
      {"physics_rate_hz", [](SimulatedDeviceParameters& p) { p.physics_rate_hz = 1e8 * 1.0000001; }},
      {"initial_position_m", [](SimulatedDeviceParameters& p) { p.initial_position_m = Vec3(kNaN, 0, 0); }},
      {"initial_position_m", [](SimulatedDeviceParameters& p) { p.initial_position_m = Vec3(0, 0, 2.0); }},
  };
  for (const Bad& b : bad) {
    SimulatedDeviceParameters parameters;
    b.set(parameters);
    INFO(b.field);
    CHECK_THAT(message_of<InvalidArgument>([&] { parameters.validate(); }), Contains(b.field));
  }
  SimulatedDeviceParameters edge;
  edge.encoder_resolution_m = -0.0;  // 0: no quantisation
  CHECK_NOTHROW(edge.validate());
}

// ---------------------------------------------------------------- records and traces through the public API

TEST_CASE("unseen12g: a record written, read back and run again gives the same trace bit for bit",
          "[unseen12g]") {
  const WrittenTrial& trial = written_trial();
  REQUIRE(trial.run.result.trace.size() > 100);
  const std::string text = recorded_trial_json(trial.record);
  const RecordedTrial read = read_recorded_trial(text, "trial.json");
  CHECK(read.defaulted.empty());
  CHECK(recorded_trial_json(read) == text);
  SimulatedWriting writing = recorded_writing(read);
  const DeviceRegistry registry = standard_device_registry();
  TrialRunInputs inputs;
  inputs.registry = &registry;
  inputs.hand_maker = &writing;
  const TrialRun again = rerun_trial(read, Checked<TrialSpec>::check(read.spec), one_stroke_scene(), inputs);
  const auto& a = trial.run.result.trace;
  const auto& b = again.result.trace;
  REQUIRE(a.size() == b.size());
  bool same = true;
  for (std::size_t i = 0; i < a.size() && same; ++i) {
    same = same_bits(a[i].time_s, b[i].time_s);
    for (int k = 0; k < 3; ++k) {
      same = same && same_bits(a[i].position_m[k], b[i].position_m[k]) &&
             same_bits(a[i].force_n[k], b[i].force_n[k]);
    }
  }
  CHECK(same);
  // The copy of a record is equal to it as written (value semantics).
  const RecordedTrial copy = read;
  CHECK(recorded_trial_json(copy) == text);
}

TEST_CASE("unseen12g: a record re-run on other characters, or a record with a forged SHA-256, is refused",
          "[unseen12g]") {
  const WrittenTrial& trial = written_trial();
  SimulatedWriting writing = recorded_writing(trial.record);
  const DeviceRegistry registry = standard_device_registry();
  TrialRunInputs inputs;
  inputs.registry = &registry;
  inputs.hand_maker = &writing;
  CHECK_THROWS_AS(
      rerun_trial(trial.record, Checked<TrialSpec>::check(trial.record.spec), cross_scene(), inputs),
      InvalidArgument);
  for (const std::string& forged :
       {std::string(64, 'G'), std::string(63, 'a'), std::string(64, 'A'), std::string(65, '0')}) {
    INFO(forged);
    CHECK_THROWS_AS(recorded_trial(trial.spec, trial.run.options, nullptr, one_stroke_scene(), forged),
                    InvalidArgument);
  }
}

TEST_CASE("unseen12g: hostile record texts are refused as DataError naming the source", "[unseen12g]") {
  const std::string good = recorded_trial_json(written_trial().record);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
    return text;
  };
  const std::string version = "\"version\": " + std::to_string(kRecordedTrialVersion);
  const std::vector<std::string> bad{
      "",
      "null",
      "[]",
      "{}",
      good.substr(0, good.size() / 2),
      replaced(version, "\"version\": " + std::to_string(kRecordedTrialVersion + 1)),
      replaced(version, "\"version\": 0"),
      replaced(version, "\"version\": 7.5"),
      replaced(version, "\"version\": 1e999"),
      replaced("\"calligraphy-trial-specification\"", "\"calligraphy-trial-spec\""),
      replaced("\"format\"", "\"surprise\": 1, \"format\""),
      replaced("\"rate_hz\": 1000", "\"rate_hz\": NaN"),
      replaced("\"rate_hz\": 1000", "\"rate_hz\": 1e308"),
      replaced("\"rate_hz\": 1000", "\"rate_hz\": -0"),
      replaced("\"rate_hz\": 1000", "\"rate_hz\": \"1000\""),
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    INFO("text " << i);
    const std::string what =
        message_of<DataError>([&] { (void)read_recorded_trial(bad[i], "hostile.json"); });
    CHECK_THAT(what, Contains("hostile.json"));
  }
}

TEST_CASE("unseen12g: record files that are missing, folders, empty or over 64 MiB are refused by name",
          "[unseen12g]") {
  TempFolder folder;
  const std::filesystem::path missing = folder.path / "missing.json";
  const std::filesystem::path empty = folder.path / "empty.json";
  const std::filesystem::path huge = folder.path / "huge.json";
  { std::ofstream(empty.string()); }
  {
    std::ofstream out(huge.string());
    out << "{";
  }
  std::filesystem::resize_file(huge, kMaxRecordedTrialBytes + 1);  // sparse: nothing is written
  CHECK_THAT(message_of<DataError>([&] { (void)read_recorded_trial_file(missing.string()); }),
             Contains("missing.json"));
  CHECK_THAT(message_of<DataError>([&] { (void)read_recorded_trial_file(folder.path.string()); }),
             Contains(folder.path.filename().string()));
  CHECK_THAT(message_of<InputError>([&] { (void)read_recorded_trial_file(empty.string()); }),
             Contains("empty.json"));
  CHECK_THAT(message_of<DataError>([&] { (void)read_recorded_trial_file(huge.string()); }),
             Contains("huge.json"));
}

TEST_CASE("unseen12g: a trace with 1e300 N, NaN and -0 forces goes through its HDF5 file and back",
          "[unseen12g]") {
  std::vector<TrialSample> trace(3);
  for (std::size_t i = 0; i < trace.size(); ++i) {
    trace[i].time_s = 0.001 * static_cast<double>(i);
    trace[i].position_m = Vec3(0.01, -0.02, 0.0005);
    trace[i].stroke = i;
    trace[i].state = InteractionState::writing;
    trace[i].attempt = 1;
  }
  trace[0].force_n = Vec3(1e300, 0.0, 0.0);
  trace[1].force_n = Vec3(kNaN, -0.0, 2.5);
  trace[2].force_n = Vec3(-1e300, 1.0, 0.0);
  const std::string bytes = trial_trace_hdf5(trace);
  CHECK(is_trace_hdf5(bytes));
  const TraceColumns columns = parse_trace_hdf5(bytes, "forces.trace.h5");
  REQUIRE(columns.size() == 3);
  CHECK(columns.fx_n[0] == 1e300);
  CHECK(std::isnan(columns.fx_n[1]));
  CHECK(columns.fz_n[1] == 2.5);
  CHECK(columns.fx_n[2] == -1e300);
  CHECK(columns.x_m[2] == Approx(0.01).margin(1e-7));
  const std::vector<TrialSample> back = trial_samples(columns);
  REQUIRE(back.size() == 3);
  CHECK(back[2].stroke == 2);
  CHECK(back[1].state == InteractionState::writing);
  // An empty trace is a file too.
  const TraceColumns none = parse_trace_hdf5(trial_trace_hdf5({}), "empty.trace.h5");
  CHECK(none.size() == 0);
}

TEST_CASE("unseen12g: cut, flipped, empty and foreign trace bytes are refused as DataError naming the file",
          "[unseen12g]") {
  std::vector<TrialSample> trace(200);
  for (std::size_t i = 0; i < trace.size(); ++i) {
    trace[i].time_s = 0.001 * static_cast<double>(i);
    trace[i].position_m = Vec3(0.0001 * static_cast<double>(i), 0.0, 0.001);
  }
  const std::string bytes = trial_trace_hdf5(trace);
  std::vector<std::string> bad{"", std::string(511, '\0'), bytes.substr(0, bytes.size() - 1),
                               bytes.substr(0, 512), bytes + "x"};
  for (const std::size_t at : {std::size_t{5}, std::size_t{600}, bytes.size() / 2, bytes.size() - 2}) {
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(flipped[at] ^ 0x20);
    bad.push_back(flipped);
  }
  for (std::size_t i = 0; i < bad.size(); ++i) {
    INFO("bytes " << i);
    CHECK_THAT(message_of<DataError>([&] { (void)parse_trace_hdf5(bad[i], "hostile.trace.h5"); }),
               Contains("hostile.trace.h5"));
  }
  // Columns of different lengths are not samples; a stroke index past 2^32 - 1 is not written.
  TraceColumns uneven = parse_trace_hdf5(bytes, "good.trace.h5");
  uneven.x_m.pop_back();
  CHECK_THROWS_AS(trial_samples(uneven), InvalidArgument);
  std::vector<TrialSample> far(1);
  far[0].stroke = std::size_t{1} << 32;
  CHECK_THROWS_AS(trial_trace_hdf5(far), InvalidArgument);
}

TEST_CASE("unseen12g: a trial's CSV reads back, and hostile CSV rows are refused naming the line",
          "[unseen12g]") {
  const WrittenTrial& trial = written_trial();
  const std::string csv = trial_csv(trial.run.result.trace);
  PenTraceCsvOptions options;
  options.read_force = true;
  const std::vector<PenSample> samples = parse_pen_trace_csv(csv, "trial.csv", Placement{}, options);
  REQUIRE(samples.size() == trial.run.result.trace.size());
  for (std::size_t i = 0; i < samples.size(); i += 97) {
    CHECK(samples[i].time_s == Approx(trial.run.result.trace[i].time_s).margin(0.6e-6));
    CHECK(samples[i].position_m.x() == Approx(trial.run.result.trace[i].position_m.x()).margin(0.6e-7));
  }
  const std::vector<std::pair<std::string, std::string>> bad{
      {"t,x,y,pen\n0,0,0,1\n0.001,nan,0,1\n", ":3"},
      {"t,x,y,pen\n0,0,0,1\n0.001,1e309,0,1\n", ":3"},
      {"t,x,y,pen\n0,0,0,1\n0.001,0x10,0,1\n", ":3"},
      {"t,x,y,pen\n0.002,0,0,1\n0.001,0,0,1\n", ":3"},
      {"t,x,y,pen\n0,0,0,2\n", ":2"},
      {"t,x,y,pen\n0,0,0\n", ":2"},
      {"t,x,x,pen\n0,0,0,1\n", ":1"},
      {"t,x,pen\n0,0,1\n", "y"},
  };
  for (const auto& entry : bad) {
    const std::string& text = entry.first;
    const std::string& where = entry.second;
    INFO(text);
    const std::string what =
        message_of<DataError>([&] { (void)parse_pen_trace_csv(text, "hostile.csv", Placement{}); });
    CHECK_THAT(what, Contains("hostile.csv") && Contains(where));
  }
  // Padding, CR LF, a byte-order mark, comments and blank lines are the documented format.
  const std::vector<PenSample> padded = parse_pen_trace_csv(
      "\xEF\xBB\xBFt , x, y ,pen\r\n# note\r\n\r\n 0 , -0 ,1e-3, 1\r\n", "padded.csv", Placement{});
  REQUIRE(padded.size() == 1);
  CHECK(padded[0].pen_down);
  CHECK(padded[0].position_m.y() == 1e-3);
  PenTraceCsvOptions bad_options;
  bad_options.max_samples = 0;
  CHECK_THROWS_AS(parse_pen_trace_csv(csv, "trial.csv", Placement{}, bad_options), InvalidArgument);
  bad_options = {};
  bad_options.contact_threshold_m = kNaN;
  CHECK_THROWS_AS(parse_pen_trace_csv(csv, "trial.csv", Placement{}, bad_options), InvalidArgument);
  bad_options = {};
  bad_options.max_samples = 10;
  CHECK_THAT(
      message_of<DataError>([&] { (void)parse_pen_trace_csv(csv, "long.csv", Placement{}, bad_options); }),
      Contains("long.csv"));
}

TEST_CASE("unseen12g: the device registry refuses empty, duplicate and null-making backends by name",
          "[unseen12g]") {
  DeviceRegistry registry;
  register_simulated_device(registry);
  CHECK_THAT(message_of<DeviceNotFound>([&] { (void)registry.create("no-such-arm"); }),
             Contains("simulated"));
  const auto make = [] { return std::unique_ptr<HapticDevice>(std::make_unique<AppDevice>()); };
  CHECK_THROWS_AS(registry.register_device("", AppDevice().info(), make), InvalidArgument);
  CHECK_THROWS_AS(registry.register_device("simulated", AppDevice().info(), make), InvalidArgument);
  CHECK_THROWS_AS(registry.register_device("app-arm", AppDevice().info(), {}), InvalidArgument);
  CHECK_THROWS_AS(registry.register_backend(DeviceBackend{"app-backend", {}, {}}), InvalidArgument);
  // A factory of the application's that gives nothing: an error naming the device, never a null device.
  registry.register_device("null-arm", AppDevice().info(), [] { return std::unique_ptr<HapticDevice>(); });
  try {
    const std::unique_ptr<HapticDevice> device = registry.create("null-arm");
    CHECK(device != nullptr);
  } catch (const DeviceError& e) {
    CHECK_THAT(std::string(e.what()), Contains("null-arm"));
  }
  // The application's device, created by its name, is the application's.
  registry.register_device("app-arm", AppDevice().info(), make);
  const std::unique_ptr<HapticDevice> app = registry.create("app-arm");
  REQUIRE(app != nullptr);
  CHECK(app->info().model == "app stylus");
  CHECK_FALSE(app->is_open());
}
