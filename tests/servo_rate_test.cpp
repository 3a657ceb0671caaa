// Rates checked where they are set: a renderer or a trial built for one rate is refused at start by a loop or
// a device clock at another, both rates named; a loop at the asked rate whose ticks came late by the device's
// clock reports the measured rate as timing, not configuration. The slow loop is a device clock whose time
// stamps advance 1.5 ms a frame, so the measured rate does not depend on the machine's load.
#include <catch2/catch.hpp>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/logging.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/runner.hpp"
#include "calligraphy/trial/session.hpp"
#include "clocked_device.hpp"

using namespace calligraphy;
using test::ClockedDevice;

namespace {

// The library's warnings while it lives (through set_log_handler); the default log given back after.
class CapturedWarnings {
 public:
  CapturedWarnings() {
    set_log_handler([this](LogLevel level, std::string_view message) {
      if (level != LogLevel::warning) return;
      const std::lock_guard<std::mutex> lock(mutex_);
      lines_.emplace_back(message);
    });
  }
  ~CapturedWarnings() { set_log_handler({}); }
  CapturedWarnings(const CapturedWarnings&) = delete;
  CapturedWarnings& operator=(const CapturedWarnings&) = delete;

  // The one warning that starts with `prefix` (empty when none).
  [[nodiscard]] std::string starting_with(std::string_view prefix) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const std::string& line : lines_) {
      if (line.starts_with(prefix)) return line;
    }
    return {};
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
};

ServoLoopOptions loop_options(double rate_hz = 1000.0) {
  ServoLoopOptions o;
  o.rate_hz = rate_hz;
  o.lock_memory = false;
  o.stall_timeout_s = 0.0;
  o.max_force_age_s = 1.0;
  return o;
}

const Scene& scene() {
  static const Scene s = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  return s;
}

ServoCommand render(Renderer& renderer, const DeviceState& state) {
  const RenderOutput out = renderer.tick(state);
  return ServoCommand{out.force_n, out.finished};
}

}  // namespace

TEST_CASE("A renderer built for 500 Hz is refused at start by a 1 kHz loop or device clock, both rates named",
          "[servo][rate]") {
  SECTION("the loop's own thread") {
    SimulatedDevice device;
    device.open();
    device.enable_forces(false);  // refused before start() would enable them
    Renderer renderer(scene(), ForceLawParameters{}, device.info(), RendererOptions{.rate_hz = 500.0});
    ServoLoop loop(device,
                   ticking(renderer, [&](const DeviceState& s, double) { return render(renderer, s); }),
                   loop_options(1000.0));
    CHECK_THROWS_WITH(loop.start(),
                      "ServoLoop::start: the callback was built for 500 Hz (RendererOptions::rate_hz), "
                      "but the loop runs at 1000 Hz (ServoLoopOptions::rate_hz): set both to one rate");
    CHECK_FALSE(loop.running());
    CHECK_FALSE(device.forces_enabled());
  }
  SECTION("a device's own servo clock") {
    ClockedDevice device(1000.0);
    device.open();
    Renderer renderer(scene(), ForceLawParameters{}, device.info(), RendererOptions{.rate_hz = 500.0});
    ServoLoop loop(device,
                   ticking(renderer, [&](const DeviceState& s, double) { return render(renderer, s); }),
                   loop_options(1000.0));
    CHECK_THROWS_WITH(loop.start(), Catch::Contains("built for 500 Hz (RendererOptions::rate_hz)") &&
                                        Catch::Contains("own servo clock at 1000 Hz"));
    CHECK_FALSE(device.forces_enabled());
  }
  SECTION("the same renderer at the loop's rate starts") {
    ClockedDevice device(1000.0);
    device.open();
    Renderer renderer(scene(), ForceLawParameters{}, device.info(), RendererOptions{.rate_hz = 1000.0});
    ServoLoop loop(device,
                   ticking(renderer, [&](const DeviceState& s, double) { return render(renderer, s); }),
                   loop_options(1000.0));
    CHECK_NOTHROW(loop.start());
    CHECK_FALSE(loop.stop());
  }
}

TEST_CASE("A trial whose rate is not the device clock's is refused at start, both rates named",
          "[servo][rate][trial]") {
  SECTION("the runner") {
    ClockedDevice device(1000.0);
    TrialOptions options;
    options.rate_hz = 500.0;
    options.pacing = TrialPacing::real_time;
    options.loop.lock_memory = false;
    CHECK_THROWS_WITH(
        run_trial(device, scene(), options),
        "ServoLoop::start: the callback was built for 500 Hz (TrialOptions::rate_hz), but 'clocked test "
        "device' runs its own servo clock at 1000 Hz: set TrialOptions::rate_hz to 1000 Hz");
    CHECK_FALSE(device.forces_enabled());
  }
  SECTION("a session's own callback on the application's ServoLoop") {
    SimulatedDevice device;
    device.open();
    TrialOptions options;
    options.rate_hz = 500.0;
    TrialSession session(scene(), device.info(), options);
    ServoLoop loop(device, session.servo_callback(), loop_options(1000.0));  // 1 kHz
    CHECK_THROWS_WITH(loop.start(), Catch::Contains("500 Hz (TrialOptions::rate_hz)") &&
                                        Catch::Contains("1000 Hz (ServoLoopOptions::rate_hz)"));
    CHECK(session.ticks() == 0);
  }
}

TEST_CASE("A loop at the asked rate whose ticks came late reports the rate it kept, as timing",
          "[servo][rate][trial]") {
  ClockedDevice device(1000.0);
  device.set_time_per_frame_s(0.0015);  // by the device's clock, a tick every 1.5 ms: 666.7 Hz kept
  device.open();
  TrialOptions options;
  options.max_duration_s = 0.2;  // 200 ticks, then the session asks to stop
  TrialSession session(scene(), device.info(), options);
  session.reserve_trace();
  ServoLoop loop(device, session.servo_callback(), loop_options(1000.0));
  const CapturedWarnings warnings;
  loop.start();
  loop.wait();
  const TrialResult result = session.finish(TrialEnd::time_limit);
  device.close();
  CHECK(session.ticks() == 200);
  CHECK(result.device_tick_rate_hz == Approx(1.0 / 0.0015));
  const std::string warning = warnings.starting_with("trial:");
  INFO(warning);
  CHECK_THAT(warning, Catch::StartsWith("trial: the servo loop kept 666.7 Hz of the 1000 Hz asked") &&
                          Catch::Contains("late (load on the machine") &&
                          !Catch::Contains("step the session"));
}

TEST_CASE(
    "An application's own loop that stepped slower than its promise hears the measured rate and both causes",
    "[rate][trial]") {
  SimulatedDevice device;
  TrialOptions options;  // 1000 Hz promised
  TrialSession session(scene(), device.info(), options);
  DeviceState state;
  state.position_m = Vec3(0.0, 0.0, 0.05);  // above the paper
  for (int i = 0; i < 150; ++i) {
    state.time_s = 12.0 + 0.002 * i;  // 500 Hz by the device's clock
    static_cast<void>(session.step(state));
  }
  const CapturedWarnings warnings;
  const TrialResult result = session.finish(TrialEnd::interrupted);
  CHECK(result.device_tick_rate_hz == Approx(500.0));
  const std::string warning = warnings.starting_with("trial:");
  INFO(warning);
  CHECK_THAT(warning,
             Catch::StartsWith("trial: the ticks came at 500 Hz by the device's clock, not the 1000 Hz of "
                               "TrialOptions::rate_hz: late ticks (load on the machine)") &&
                 Catch::Contains("a loop at another rate"));
}

TEST_CASE("Rates in the loop's and the trial's errors read as numbers of Hz, not std::to_string's",
          "[servo][rate]") {
  ServoLoopOptions loop;
  loop.rate_hz = 50.0;
  CHECK_THROWS_WITH(loop.validate(), "ServoLoopOptions.rate_hz = 50 Hz must be in [100, 10000] Hz");
  TrialOptions trial;
  trial.rate_hz = 99.5;
  CHECK_THROWS_WITH(trial.validate(), Catch::StartsWith("TrialOptions.rate_hz = 99.5 Hz must be in [100, "));
}
