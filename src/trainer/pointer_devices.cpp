// The "mouse" and "mouse-hand" devices (pointer_devices.hpp).
#include "trainer/pointer_devices.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>

#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/simulated_device.hpp"

namespace calligraphy::trainer {
namespace {

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The pointer on the paper plane z = 0: no force output at all.
class MouseDevice final : public HapticDevice {
 public:
  explicit MouseDevice(DeviceInfo info) : info_(std::move(info)) {}
  [[nodiscard]] const DeviceInfo& info() const override { return info_; }
  void open() override {
    open_ = true;
    start_s_ = steady_seconds();
    have_last_ = false;
  }
  void close() noexcept override { open_ = false; }
  [[nodiscard]] bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { forces_ = enabled; }
  [[nodiscard]] bool forces_enabled() const override { return forces_; }
  // Servo path: never faults (the pointer is always there).
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override {
    double x = 0.0;
    double y = 0.0;
    bool pressed = false;
    pointer_input().get(x, y, pressed);
    state = DeviceState{};
    state.time_s = steady_seconds() - start_s_;
    state.position_m = Vec3(x, y, pressed ? -kMousePressDepthM : kMouseLiftHeightM);
    state.buttons = pressed ? 1U : 0U;
    // Differenced velocity, low-passed at about 50 Hz (the pointer moves in pixel steps).
    if (have_last_ && state.time_s > last_.time_s) {
      const Vec3 raw = (state.position_m - last_.position_m) / (state.time_s - last_.time_s);
      const double alpha = std::min(1.0, (state.time_s - last_.time_s) * 2.0 * 3.14159265358979 * 50.0);
      velocity_ += alpha * (raw - velocity_);
    }
    state.velocity_m_s = velocity_;
    last_ = state;
    have_last_ = true;
    return DeviceFault::none;
  }
  [[nodiscard]] DeviceFault write_force(const Vec3& /*force_n*/) noexcept override {
    return DeviceFault::none;  // a mouse renders no force
  }

 private:
  DeviceInfo info_;
  bool open_ = false;
  bool forces_ = false;
  double start_s_ = 0.0;
  DeviceState last_;
  bool have_last_ = false;
  Vec3 velocity_ = Vec3::Zero();
};

// A hand model pulling the stylus towards the pointer.
class PointerHand final : public HandModel {
 public:
  explicit PointerHand(const MouseHandParameters& parameters) : parameters_(parameters) {}
  Vec3 hand_force(double /*time_s*/, const Vec3& position_m, const Vec3& velocity_m_s) override {
    double x = 0.0;
    double y = 0.0;
    bool pressed = false;
    pointer_input().get(x, y, pressed);
    const Vec3 target(x, y, pressed ? -parameters_.press_depth_m : parameters_.lift_height_m);
    return parameters_.stiffness_n_per_m * (target - position_m) -
           parameters_.damping_n_s_per_m * velocity_m_s;
  }

 private:
  MouseHandParameters parameters_;
};

// The simulated device with the pointer's hand, its physics advanced by the wall clock at each read.
// Not a HandPort: a person moves it, so a trial runs it in real time without a simulated writer.
class MouseHandDevice final : public HapticDevice {
 public:
  MouseHandDevice() : device_(parameters()), hand_(MouseHandParameters{}) { device_.attach_hand(&hand_); }
  [[nodiscard]] const DeviceInfo& info() const override { return device_.info(); }
  void open() override {
    device_.open();
    last_s_ = steady_seconds();
    touched_ = false;
  }
  void close() noexcept override { device_.close(); }
  [[nodiscard]] bool is_open() const override { return device_.is_open(); }
  void enable_forces(bool enabled) override { device_.enable_forces(enabled); }
  [[nodiscard]] bool forces_enabled() const override { return device_.forces_enabled(); }
  // Servo path: the simulated device faults only when not open. `advance` throws only for a negative or
  // non-finite step, which the clamp rules out.
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override {
    const double now_s = steady_seconds();
    // A stalled thread does not make the physics jump: at most 50 ms are integrated at once.
    device_.advance(std::clamp(now_s - last_s_, 0.0, 0.05));
    last_s_ = now_s;
    const DeviceFault fault = device_.read_state(state);
    if (fault == DeviceFault::none) hold_on_paper_while_pressed(state);
    return fault;
  }
  [[nodiscard]] DeviceFault write_force(const Vec3& force_n) noexcept override {
    return device_.write_force(force_n);
  }

  // One touch is one pen-down. The simulated stylus lands on a stiff paper behind a soft, lightly damped
  // hand, so it bounces: about 57 ms above the paper's contact hysteresis, which the renderer reads as a
  // lift and a new touch (an abandoned attempt, a doubled count, a spurious "too short" in a quiz). A
  // hand's pen does not leave the paper while it presses, so from the first contact of a press until the
  // button is released the reported pen is held at most on the paper (the stylus' in-plane motion and its
  // depth below the paper are reported as they are). A release debounce (e.g. 30 ms) would not do: it
  // must outlast the bounce, and every real lift would then come that much late, the pen moving on the
  // paper meanwhile; with the hold, a release lifts the pen at once.
  void hold_on_paper_while_pressed(DeviceState& state) {
    double x = 0.0;
    double y = 0.0;
    bool pressed = false;
    pointer_input().get(x, y, pressed);
    if (!pressed) {
      touched_ = false;
      return;
    }
    if (state.position_m.z() <= kPaperZM) touched_ = true;
    if (touched_ && state.position_m.z() > kPaperZM) {
      state.position_m.z() = kPaperZM;
      state.velocity_m_s.z() = 0.0;  // held on the paper: not moving off it
    }
  }

  static SimulatedDeviceParameters parameters() {
    SimulatedDeviceParameters p;
    p.info.model = "mouse-hand (simulated Phantom Desktop, hand coupled to the mouse)";
    p.initial_position_m = Vec3(0.0, 0.0, 0.01);
    return p;
  }

 private:
  static constexpr double kPaperZM = 0.0;  // the trainer's scenes lay the paper at z = 0 (SceneLayout)
  SimulatedDevice device_;
  PointerHand hand_;
  double last_s_ = 0.0;
  bool touched_ = false;  // the pen has met the paper since the button went down
};

DeviceInfo mouse_info() {
  DeviceInfo info = simulated_phantom_desktop_info();  // the forces a Desktop would render are recorded
  info.model = "mouse (2-DOF, no force output)";
  info.manufacturer = "calligraphy";
  info.intrinsic_damping_n_s_per_m = 0.0;
  return info;
}

bool registered(const DeviceRegistry& registry, const std::string& name) {
  const auto names = registry.backend_names();
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

void PointerInput::set(double x_m, double y_m, bool pressed) noexcept {
  const float xy[2] = {static_cast<float>(x_m), static_cast<float>(y_m)};
  std::uint64_t packed = 0;
  std::memcpy(&packed, xy, sizeof packed);
  position_.store(packed, std::memory_order_relaxed);
  pressed_.store(pressed, std::memory_order_relaxed);
}

void PointerInput::get(double& x_m, double& y_m, bool& pressed) const noexcept {
  const std::uint64_t packed = position_.load(std::memory_order_relaxed);
  float xy[2];
  std::memcpy(xy, &packed, sizeof xy);
  x_m = xy[0];
  y_m = xy[1];
  pressed = pressed_.load(std::memory_order_relaxed);
}

PointerInput& pointer_input() {
  static PointerInput input;
  return input;
}

void register_pointer_devices(DeviceRegistry& registry) {
  if (!registered(registry, "mouse")) {
    registry.register_device(
        "mouse", mouse_info(), [] { return std::make_unique<MouseDevice>(mouse_info()); },
        DeviceCapabilities{},
        "the window's pointer on the paper plane; left button = pen on the paper; no force output "
        "(calligraphy train only)");
  }
  if (!registered(registry, "mouse-hand")) {
    registry.register_device(
        "mouse-hand", MouseHandDevice::parameters().info, [] { return std::make_unique<MouseHandDevice>(); },
        DeviceCapabilities{},
        "simulated Phantom Desktop held by a hand (150 N/m, 3 N s/m) coupled to the window's pointer "
        "(calligraphy train only)");
  }
}

}  // namespace calligraphy::trainer
