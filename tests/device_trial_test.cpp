// Trials on any device through run_trial: the emulated Phantom end to end, a disconnect and a
// safety fault in the middle of a trial, real-time pacing on the ServoLoop for devices without a hand port.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "calligraphy/trial/trial.hpp"
#include "embedded_scenes.hpp"
#include "testing/phantom_emulator.hpp"

using namespace calligraphy;
using phantom::EmulatedPhantomDevice;

namespace {

// The registry's emulated Phantom: powered on in the inkwell, lifted out after 50 ms.
phantom::EmulatorParameters undocking_emulator(const phantom::PhantomDeviceConfig& config) {
  auto parameters = phantom::emulator_matching(config);
  parameters.undock_after_s = 0.05;
  return parameters;
}

// The emulated Phantom, unplugged when the host asks for its `unplug_at`-th state (1-based).
class UnpluggedPhantom final : public HandDrivenDevice {
 public:
  explicit UnpluggedPhantom(int unplug_at)
      : inner_(phantom::phantom_omni_config(), undocking_emulator(phantom::phantom_omni_config())),
        unplug_at_(unplug_at) {}
  const DeviceInfo& info() const override { return inner_.info(); }
  void open() override { inner_.open(); }
  void close() noexcept override { inner_.close(); }
  bool is_open() const override { return inner_.is_open(); }
  void calibrate() override { inner_.calibrate(); }
  bool is_calibrated() const override { return inner_.is_calibrated(); }
  void enable_forces(bool enabled) override { inner_.enable_forces(enabled); }
  bool forces_enabled() const override { return inner_.forces_enabled(); }
  DeviceFault read_state(DeviceState& state) noexcept override {
    if (++reads_ == unplug_at_) inner_.emulator().disconnect();
    return inner_.read_state(state);
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override { return inner_.write_force(force_n); }
  void attach_hand(HandModel* hand) noexcept override { inner_.attach_hand(hand); }
  void advance(double dt_s) noexcept override { inner_.advance(dt_s); }
  EmulatedPhantomDevice& inner() { return inner_; }

 private:
  EmulatedPhantomDevice inner_;
  int unplug_at_;
  int reads_ = 0;
};

// A device moved by nobody (no hand port): a fixed pen above the paper that trips a safety limit at
// its `fault_at`-th state. It records how the runner drove it.
class FaultingDevice final : public HapticDevice {
 public:
  explicit FaultingDevice(int fault_at, double max_force_n = 3.0) : fault_at_(fault_at) {
    info_.max_force_n = max_force_n;
  }
  const DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }
  void close() noexcept override {
    open_ = false;
    ++closes;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { forces_ = enabled; }
  bool forces_enabled() const override { return forces_; }
  DeviceFault read_state(DeviceState& state) noexcept override {
    if (++reads == fault_at_) {
      forces_ = false;  // a device turns its forces off on a fault
      return DeviceFault::safety_limit;
    }
    state.position_m = Vec3(0.0, -0.05, 0.02);
    state.time_s = 0.001 * reads;
    return DeviceFault::none;
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    ++writes;
    last_force = force_n;
    return DeviceFault::none;
  }
  int reads = 0;
  int writes = 0;
  int closes = 0;
  Vec3 last_force = Vec3::Constant(1.0);

 private:
  DeviceInfo info_;
  int fault_at_;
  bool open_ = false;
  bool forces_ = false;
};

}  // namespace

TEST_CASE("A trial of 永 runs end to end on the emulated Phantom through the PhantomDevice path",
          "[device-trial][phantom]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"永");
  EmulatedPhantomDevice device(phantom::phantom_omni_config(),
                               undocking_emulator(phantom::phantom_omni_config()));
  const TrialResult result = run_trial(device, scene, TrialOptions{}, SimulationOptions{});
  CHECK_FALSE(result.aborted);
  CHECK(result.abort_reason.empty());
  CHECK(result.metrics.strokes_total == 5);
  CHECK(result.metrics.strokes_completed == 5);
  CHECK(result.metrics.completed_in_order);
  CHECK(result.metrics.max_force_n <= device.info().max_force_n);
  // Every tick went over the codec: one status packet read and one command packet written.
  REQUIRE(result.trace.size() > 1000);
  CHECK(device.emulator().commands_received() >= result.trace.size());
  CHECK(device.emulator().commands_rejected() == 0);
  CHECK(device.phantom().packet_errors().rejected() == 0);
  for (std::size_t i = 1; i < result.trace.size(); ++i) {
    REQUIRE(result.trace[i].force_n.allFinite());
    REQUIRE(result.trace[i].time_s == Approx(result.trace[i - 1].time_s + 0.001).margin(1e-9));
  }
  // Finished: forces off on both sides, link closed.
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(device.emulator().forces_active());
}

TEST_CASE("Lock-step trials on the emulated Phantom are deterministic for a seed",
          "[device-trial][phantom]") {
  DeviceRegistry registry;
  calligraphy::testing::register_emulated_phantom(registry);
  const Scene scene = calligraphy::testing::scene_of_text(U"口");
  TrialOptions options;
  options.keep_trace = false;
  SimulationOptions simulation;
  simulation.seed = 5;
  const auto first = run_trial(registry, "emulated-phantom", scene, options, simulation);
  const auto again = run_trial(registry, "emulated-phantom", scene, options, simulation);
  CHECK(first.metrics.strokes_completed == first.metrics.strokes_total);
  CHECK(first.metrics.mean_deviation_m == again.metrics.mean_deviation_m);
  CHECK(first.metrics.time_s == again.metrics.time_s);
}

TEST_CASE("The CLI's runner takes a registry name, an unknown name lists the devices",
          "[device-trial][registry]") {
  DeviceRegistry registry = standard_device_registry();
  calligraphy::testing::register_emulated_phantom(registry);
  const Scene scene = calligraphy::testing::scene_of_text(U"口");
  TrialOptions options;
  options.keep_trace = false;
  const TrialResult result = run_trial(registry, "emulated-phantom", scene, options);
  CHECK_FALSE(result.aborted);
  CHECK(result.metrics.strokes_completed == 3);
  try {
    (void)run_trial(registry, "no-such-device", scene, options);
    FAIL("expected DeviceNotFound");
  } catch (const DeviceNotFound& e) {
    const std::string message = e.what();
    CHECK(message.find("no-such-device") != std::string::npos);
    CHECK(message.find("simulated") != std::string::npos);
    CHECK(message.find("emulated-phantom") != std::string::npos);
  }
}

TEST_CASE("The simulated device runs the same loop as run_simulated_trial", "[device-trial]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"九");
  const TrialOptions options;
  SimulationOptions simulation;
  simulation.seed = 2;
  SimulatedDevice device(simulation.device);
  const auto a = run_simulated_trial(scene, options, simulation);
  const auto b = run_trial(device, scene, options, simulation);
  CHECK(a.metrics.mean_deviation_m == b.metrics.mean_deviation_m);
  CHECK(a.metrics.time_s == b.metrics.time_s);
  CHECK(a.trace.size() == b.trace.size());
  CHECK_FALSE(device.is_open());
}

TEST_CASE("A disconnect mid-trial aborts it with forces zeroed and the recording kept",
          "[device-trial][phantom]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"永");
  constexpr int kUnplugAt = 3000;  // 3 s in: the first stroke is being written
  UnpluggedPhantom device(kUnplugAt);
  const TrialResult result = run_trial(device, scene, TrialOptions{}, SimulationOptions{});
  REQUIRE(result.aborted);
  INFO(result.abort_reason);
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.device_fault == DeviceFault::link_lost);
  CHECK(result.abort_reason == device_fault_message(DeviceFault::link_lost, device.info().model));
  CHECK(result.abort_reason.find("unplugged") != std::string::npos);
  // Every tick before the failed read is kept and readable.
  REQUIRE(result.trace.size() == kUnplugAt - 1);
  // The trial's clock starts at its first tick (the emulator's own clock reads 2 ms there: the status
  // packet that opened it and the first tick's, each stamped when it arrived).
  CHECK(result.trace.front().time_s == 0.0);
  CHECK(result.trace.back().time_s == Approx(0.001 * (kUnplugAt - 2)).margin(1e-9));
  CHECK(result.device_time_at_start_s == Approx(0.002).margin(1e-12));
  bool wrote = false;
  for (const auto& sample : result.trace) {
    REQUIRE(sample.position_m.allFinite());
    REQUIRE(sample.force_n.allFinite());
    wrote = wrote || sample.state == InteractionState::writing;
  }
  CHECK(wrote);
  CHECK(result.metrics.strokes_total == 5);
  CHECK(result.metrics.strokes_completed < 5);
  CHECK(result.metrics.per_stroke.size() == 5);
  // Forces off on both sides, the link closed.
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.inner().emulator().forces_active());
  CHECK(device.inner().emulator().motor_torques().isZero());
}

TEST_CASE("The reports of an aborted trial say so and keep what was recorded", "[device-trial][phantom]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"口");
  UnpluggedPhantom device(1500);
  TrialOptions options;
  const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
  REQUIRE(result.aborted);
  CHECK(result.device_fault == DeviceFault::link_lost);
  const TrialDescription description{
      "口", true, "novice", 0, 1000.0, "emulated-phantom", device.info().model};
  const std::string json =
      trial_json(description, result, trial_writing_metrics(scene, result, StrokeAcceptance{}));
  CHECK(json.find("\"aborted\": true") != std::string::npos);
  CHECK(json.find("unplugged") != std::string::npos);
  CHECK(json.find("\"device\": \"emulated-phantom\"") != std::string::npos);
  const std::string csv = trial_csv(result.trace);
  CHECK(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')) ==
        result.trace.size() + 1);  // + header
  CHECK(trial_svg(scene, result).find("</svg>") != std::string::npos);
}

TEST_CASE("A safety fault aborts a trial on the servo loop, ticks are paced by absolute deadlines",
          "[device-trial]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"口");
  FaultingDevice device(40);
  TrialOptions options;
  const auto start = std::chrono::steady_clock::now();
  const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  REQUIRE(result.aborted);
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.device_fault == DeviceFault::safety_limit);
  CHECK(result.abort_reason == to_string(DeviceFault::safety_limit));  // the device has no model name
  CHECK(result.trace.size() == 39);
  // No hand port: the trial runs on the ServoLoop, which writes the 39 ticks' forces, then zero force
  // when the fault stops it.
  CHECK(device.writes == 40);
  CHECK(device.last_force == Vec3::Zero());
  CHECK(device.closes >= 1);
  CHECK_FALSE(device.forces_enabled());
  // Tick 39 (0-based) may not start before 39 ms: absolute deadlines never wake early.
  CHECK(elapsed_s >= 0.039);
}

TEST_CASE("A device that cannot calibrate refuses the trial and is closed", "[device-trial][phantom]") {
  auto config = phantom::phantom_omni_config();
  auto parameters = phantom::emulator_matching(config);
  parameters.start_docked = false;  // never in the inkwell: encoders cannot be homed
  EmulatedPhantomDevice device(config, parameters);
  CHECK_THROWS_AS(
      run_trial(device, calligraphy::testing::scene_of_text(U"口"), TrialOptions{}, SimulationOptions{}),
      CalibrationNeeded);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.emulator().forces_active());
}

TEST_CASE("A device without a usable force limit is refused after open() and closed again",
          "[device-trial]") {
  FaultingDevice device(1000, 0.0);
  CHECK_THROWS_AS(
      run_trial(device, calligraphy::testing::scene_of_text(U"口"), TrialOptions{}, SimulationOptions{}),
      InvalidArgument);
  CHECK(device.reads == 0);
  CHECK(device.closes == 1);
  CHECK_FALSE(device.is_open());
}
