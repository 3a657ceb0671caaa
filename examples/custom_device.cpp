// How an application plugs in its own haptic device: implement calligraphy::HapticDevice (SI units,
// device frame x right, y away from the writer, z up), optionally register it by name, and run a
// guided trial on it with run_trial, the same loop the Phantom backends use.
//
// The device here is a toy: a 0.1 kg puck on a voice-coil stage with viscous friction, 0.05 mm
// encoders and a 2 N amplifier. Because it is simulated, it also implements HandPort, so the
// library's simulated writer can hold it and the trial runs lock-step (deterministic, much faster than
// real time). A real device would implement HapticDevice only: run_trial then paces the ticks
// by the wall clock and the person holding the device writes.
#include <calligraphy/core/errors.hpp>
#include <calligraphy/devices/device_registry.hpp>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/devices/hand_port.hpp>
#include <calligraphy/sim/simulated_hand.hpp>
#include <calligraphy/trial/trial.hpp>
#include <cmath>
#include <cstdio>
#include <memory>

namespace {

using calligraphy::Vec3;

class VoiceCoilPuck final : public calligraphy::HandDrivenDevice {
 public:
  VoiceCoilPuck() {
    info_.model = "voice-coil puck (example)";
    info_.manufacturer = "an application";
    info_.max_force_n = 2.0;
    info_.max_continuous_force_n = 1.0;
    info_.max_stiffness_n_per_m = 1000.0;
    info_.max_damping_n_s_per_m = 5.0;
    info_.workspace_radius_m = 0.08;
    info_.workspace_size_m = Vec3(0.16, 0.16, 0.05);
  }

  // --- HapticDevice: what every device implements ---
  const calligraphy::DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }  // a real device: open the link, throw DeviceNotFound
  void close() noexcept override {
    force_ = Vec3::Zero();
    forces_enabled_ = false;
    open_ = false;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override {
    if (enabled && !open_) throw calligraphy::DeviceError("puck: enable_forces(true) before open()");
    forces_enabled_ = enabled;
    if (!enabled) force_ = Vec3::Zero();
  }
  bool forces_enabled() const override { return forces_enabled_; }
  // Servo path: noexcept, and no allocation, lock, logging or string, also when it fails. A fault is a
  // code (calligraphy/core/device_fault.hpp): the servo loop stops on it with zero force, and off the
  // servo path calligraphy::throw_device_fault turns it into CommunicationError or SafetyFault. A real
  // device would return DeviceFault::link_lost for a lost link; its detail (an error number, a packet)
  // goes into a counter or a plain record that is formatted later, away from the servo thread.
  calligraphy::DeviceFault read_state(calligraphy::DeviceState& state) noexcept override {
    if (!open_) return calligraphy::DeviceFault::not_open;
    state.position_m = (position_ / kEncoderStep).array().round().matrix() * kEncoderStep;
    state.velocity_m_s = velocity_;
    state.buttons = 0;
    state.time_s = time_;
    return calligraphy::DeviceFault::none;
  }
  calligraphy::DeviceFault write_force(const Vec3& force_n) noexcept override {
    if (!open_) return calligraphy::DeviceFault::not_open;
    if (!force_n.allFinite()) {  // zero force, forces off, and say why
      force_ = Vec3::Zero();
      forces_enabled_ = false;
      ++non_finite_commands_;
      return calligraphy::DeviceFault::non_finite_force;
    }
    const double norm = force_n.norm();
    const Vec3 limited = norm > info_.max_force_n ? force_n * (info_.max_force_n / norm) : force_n;
    force_ = forces_enabled_ ? limited : Vec3::Zero();
    return calligraphy::DeviceFault::none;
  }

  /// Non-finite force commands refused so far: a detail kept as a counter on the servo path.
  long non_finite_commands() const noexcept { return non_finite_commands_; }

  // --- HandPort: only because this device is simulated ---
  void attach_hand(calligraphy::HandModel* hand) noexcept override { hand_ = hand; }
  void advance(double dt_s) noexcept override {
    constexpr int kSubsteps = 10;
    const double h = dt_s / kSubsteps;
    for (int i = 0; i < kSubsteps; ++i) {
      const Vec3 hand = hand_ != nullptr ? hand_->hand_force(time_, position_, velocity_) : Vec3::Zero();
      velocity_ += h * (hand + force_ - kFriction * velocity_) / kMass;
      position_ += h * velocity_;
      time_ += h;
    }
  }

 private:
  static constexpr double kMass = 0.1;          // puck and hand [kg]
  static constexpr double kFriction = 1.0;      // viscous [N s/m]
  static constexpr double kEncoderStep = 5e-5;  // [m]
  calligraphy::DeviceInfo info_;
  calligraphy::HandModel* hand_ = nullptr;
  Vec3 position_ = Vec3(0.0, -0.05, 0.02);  // parked in front of the paper, above it [m]
  Vec3 velocity_ = Vec3::Zero();
  Vec3 force_ = Vec3::Zero();
  double time_ = 0.0;
  bool open_ = false;
  bool forces_enabled_ = false;
  long non_finite_commands_ = 0;  // a counter, not a message: read and reported off the servo path
};

}  // namespace

int main() {
  using namespace calligraphy;
  // Registering is optional (run_trial also takes the device itself); a device registered in a registry
  // the application owns is listed by its `survey()` and opened by name, like the standard ones.
  DeviceRegistry registry = standard_device_registry();
  registry.register_device("voice-coil-puck", VoiceCoilPuck{}.info(), [] { return std::make_unique<VoiceCoilPuck>(); },
                           DeviceCapabilities{.moved_by_simulated_hand = true});

  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'口')});
  TrialOptions options;  // 1 kHz, novice writer, guidance on
  SimulationOptions simulation;  // the simulated writer that holds the puck (it has a hand port)
  simulation.seed = 1;
  const TrialResult result = run_trial(registry, "voice-coil-puck", scene, options, simulation);

  // A device fault mid-trial ends it with the code and its message (device_fault_message); off the servo
  // path, throw_device_fault would make it the typed exception.
  if (result.device_fault != DeviceFault::none) {
    std::fprintf(stderr, "device fault %s: %s\n", device_fault_name(result.device_fault),
                 result.abort_reason.c_str());
  }
  const TrialMetrics& m = result.metrics;
  std::printf(
      "口 on the voice-coil puck: %zu/%zu strokes in %.1f s, mean deviation %.2f mm, max |F| %.2f N%s\n",
      m.strokes_completed, m.strokes_total, m.time_s, m.mean_deviation_m.value_or(std::nan("")) * 1e3,
      m.max_force_n, result.aborted ? " (aborted)" : "");
  return !result.aborted && m.completed_in_order ? 0 : 1;
}
