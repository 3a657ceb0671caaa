#include "calligraphy/devices/simulated_device.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "calligraphy/devices/phantom_models.hpp"

namespace calligraphy {

DeviceInfo simulated_phantom_desktop_info() {
  DeviceInfo info = phantom_desktop_info();  // the one table of Phantom figures
  info.model += " (simulated)";
  info.manufacturer = "calligraphy";
  return info;
}

namespace {

// "SimulatedDeviceParameters.moving_mass_kg = 1e-300 must be in [1e-4, 1e3] kg": the value printed with
// %g so that tiny and huge values stay readable.
[[noreturn]] void out_of_range(const char* name, double value, const char* range) {
  std::array<char, 48> number{};
  std::snprintf(number.data(), number.size(), "%g", value);
  throw InvalidArgument(std::string("SimulatedDeviceParameters.") + name + " = " + number.data() +
                        " must be " + range);
}

bool within(double value, double low, double high) { return value >= low && value <= high; }  // false for NaN

}  // namespace

void SimulatedDeviceParameters::validate() const {
  if (!within(moving_mass_kg, 1e-4, 1e3)) out_of_range("moving_mass_kg", moving_mass_kg, "in [1e-4, 1e3] kg");
  if (!within(damping_n_s_per_m, 0.0, 1e4))
    out_of_range("damping_n_s_per_m", damping_n_s_per_m, "in [0, 1e4] N s/m");
  if (!(encoder_resolution_m == 0.0 || within(encoder_resolution_m, 1e-9, 1e-3)))
    out_of_range("encoder_resolution_m", encoder_resolution_m, "0 (no quantisation) or in [1e-9, 1e-3] m");
  if (!(velocity_cutoff_hz > 0.0 && velocity_cutoff_hz <= 1e6))
    out_of_range("velocity_cutoff_hz", velocity_cutoff_hz, "in (0, 1e6] Hz");
  if (physics_substeps < 1 || physics_substeps > 10000)
    out_of_range("physics_substeps", physics_substeps, "an integer in 1..10000");
  if (!within(physics_rate_hz, 1e3, 1e8))
    out_of_range("physics_rate_hz", physics_rate_hz, "in [1e3, 1e8] Hz");
  // Within a haptic device's reach, as a scene's layout is (kDeviceReachM).
  if (!(initial_position_m.array().abs() <= kDeviceReachM).all())
    throw InvalidArgument(
        "SimulatedDeviceParameters.initial_position_m must be finite, each coordinate in [-1, 1] m");
  if (!(info.max_force_n > 0.0) || !std::isfinite(info.max_force_n))
    out_of_range("info.max_force_n", info.max_force_n, "> 0 N and finite");
  // The other figures as a device reports them, so that a trial record states them (a negative or NaN is
  // no figure).
  const std::pair<const char*, double> figures[] = {
      {"info.max_continuous_force_n", info.max_continuous_force_n},
      {"info.max_stiffness_n_per_m", info.max_stiffness_n_per_m},
      {"info.max_damping_n_s_per_m", info.max_damping_n_s_per_m},
      {"info.intrinsic_damping_n_s_per_m", info.intrinsic_damping_n_s_per_m},
      {"info.workspace_radius_m", info.workspace_radius_m},
      {"info.workspace_size_m", info.workspace_size_m.x()},
      {"info.workspace_size_m", info.workspace_size_m.y()},
      {"info.workspace_size_m", info.workspace_size_m.z()}};
  for (const auto& [name, value] : figures) {
    if (!(value >= 0.0) || !std::isfinite(value)) out_of_range(name, value, ">= 0 and finite");
  }
}

SimulatedDevice::SimulatedDevice(const SimulatedDeviceParameters& parameters)
    : parameters_(parameters),
      position_(parameters.initial_position_m),
      reported_position_(parameters.initial_position_m) {
  parameters_.validate();
  parameters_.info.intrinsic_damping_n_s_per_m = parameters_.damping_n_s_per_m;  // the simulation's truth
}

void SimulatedDevice::open() noexcept {
  if (open_) return;
  open_ = true;
  // DeviceState::time_s counts from open(); a velocity differenced across the re-open would span the gap.
  time_ns_ = 0;
  last_read_ns_ = 0;
  read_before_ = false;
  reported_velocity_ = Vec3::Zero();
  read_since_advance_ = false;
  written_since_read_ = false;
}

void SimulatedDevice::close() noexcept {
  force_ = Vec3::Zero();
  open_ = false;
}

void SimulatedDevice::enable_forces(bool enabled) {
  forces_enabled_ = enabled;
  if (!enabled) force_ = Vec3::Zero();
}

DeviceFault SimulatedDevice::write_force(const Vec3& force_n) noexcept {
  if (!open_) {  // as every device: nothing reaches a closed device (close() left the force at zero)
    force_ = Vec3::Zero();
    return DeviceFault::not_open;
  }
  force_ = forces_enabled_ ? clamp_force_magnitude(force_n, parameters_.info.max_force_n) : Vec3::Zero();
  written_since_read_ = read_since_advance_;
  return DeviceFault::none;
}

void SimulatedDevice::advance(double dt_s) {
  if (!(dt_s >= 0.0) || !std::isfinite(dt_s)) {
    std::array<char, 48> number{};
    std::snprintf(number.data(), number.size(), "%g", dt_s);
    throw InvalidArgument(std::string("SimulatedDevice::advance: dt_s = ") + number.data() +
                          " must be finite and >= 0 s");
  }
  // The clock's step in whole nanoseconds, checked before anything changes: 2^62 ns leaves room for the sum.
  constexpr double kClockLimitNs = 4.611686018427387904e18;
  const double step_ns = std::round(dt_s * 1e9);
  if (step_ns > kClockLimitNs - static_cast<double>(time_ns_)) {
    std::array<char, 48> number{};
    std::snprintf(number.data(), number.size(), "%g", dt_s);
    throw InvalidArgument(std::string("SimulatedDevice::advance: dt_s = ") + number.data() +
                          " s would run the device's clock past 2^62 ns (146 years)");
  }
  read_since_advance_ = false;
  written_since_read_ = false;
  if (dt_s == 0.0) return;
  const std::int64_t start_ns = time_ns_;
  const double start_s = time();
  const double m = parameters_.moving_mass_kg;
  const double b = parameters_.damping_n_s_per_m;
  // The longest stable, monotone substep (see the file comment); m / b only when there is damping.
  double max_step_s = 1.0 / parameters_.physics_rate_hz;
  if (b > 0.0) max_step_s = std::min(max_step_s, m / b);
  long substeps = parameters_.physics_substeps;
  double h = dt_s / static_cast<double>(substeps);
  double rest_s = 0.0;  // left for the closed form when the substeps would be too many
  // A relative slack of 1e-9 on the bound: the configured split stays exactly as it was where it already
  // met the bound up to rounding (1 ms / 10 against 1 / 10 kHz differ in the last bit), so lock-step trials
  // stay bit for bit the same, and 50 ms at 10 kHz is 500 substeps, not 501.
  constexpr double kSlack = 1e-9;
  if (h > max_step_s * (1.0 + kSlack)) {
    const double needed = std::ceil(dt_s / max_step_s * (1.0 - kSlack));
    if (needed <= static_cast<double>(kMaxSubstepsPerAdvance)) {
      substeps = static_cast<long>(needed);
      h = dt_s / needed;
    } else {
      substeps = kMaxSubstepsPerAdvance;
      h = max_step_s;
      rest_s = dt_s - static_cast<double>(kMaxSubstepsPerAdvance) * max_step_s;
    }
  }
  for (long i = 0; i < substeps; ++i) {
    const double t = start_s + static_cast<double>(i) * h;  // not a running sum: its rounding would add up
    const Vec3 hand = hand_ != nullptr ? hand_->hand_force(t, position_, velocity_) : Vec3::Zero();
    const Vec3 acceleration = (hand + force_ - b * velocity_) / m;
    velocity_ += h * acceleration;  // semi-implicit Euler: velocity first, then position with the new one
    position_ += h * velocity_;
  }
  if (rest_s > 0.0) {
    const double substeps_s = static_cast<double>(substeps) * h;
    time_ns_ = start_ns + static_cast<std::int64_t>(std::round(substeps_s * 1e9));  // kept if the rest throws
    integrate_exactly(rest_s, start_s + substeps_s);
  }
  time_ns_ = start_ns + static_cast<std::int64_t>(step_ns);
}

// m x'' = F - b x' with F held constant over t, in closed form with s = b t / m:
//   v(t) = v0 e^-s + (F / m) t phi1(s),   x(t) = x0 + v0 t phi1(s) + (F / m) t^2 phi2(s),
//   phi1(s) = (1 - e^-s) / s,   phi2(s) = (s - 1 + e^-s) / s^2,
// which stay accurate for small s (series; phi1(0) = 1, phi2(0) = 1/2: the undamped mass) and for b = 0.
void SimulatedDevice::integrate_exactly(double duration_s, double start_s) {
  const double m = parameters_.moving_mass_kg;
  const double s = parameters_.damping_n_s_per_m * duration_s / m;
  const double decay = std::exp(-s);
  double phi1 = 0.0;
  double phi2 = 0.0;
  if (s < 1e-3) {  // Taylor series: the closed forms cancel (and are 0 / 0 at s = 0); error below 2e-15
    phi1 = 1.0 - s / 2.0 + s * s / 6.0 - s * s * s / 24.0;
    phi2 = 0.5 - s / 6.0 + s * s / 24.0 - s * s * s / 120.0;
  } else {
    const double em1 = std::expm1(-s);  // e^-s - 1, accurate for small s
    phi1 = -em1 / s;
    phi2 = (s + em1) / (s * s);
  }
  const Vec3 hand = hand_ != nullptr ? hand_->hand_force(start_s, position_, velocity_) : Vec3::Zero();
  const Vec3 acceleration = (hand + force_) / m;  // the drive alone; the damping is in the closed form
  const Vec3 velocity = decay * velocity_ + (duration_s * phi1) * acceleration;
  const Vec3 position =
      position_ + (duration_s * phi1) * velocity_ + (duration_s * duration_s * phi2) * acceleration;
  if (!velocity.allFinite() || !position.allFinite()) {
    std::array<char, 48> number{};
    std::snprintf(number.data(), number.size(), "%g", duration_s);
    throw InvalidArgument(std::string("SimulatedDevice::advance: ") + number.data() +
                          " s more take the stylus out of the range of a double; advance by less");
  }
  velocity_ = velocity;
  position_ = position;
}

DeviceFault SimulatedDevice::read_state(DeviceState& state) noexcept {
  if (!open_) return DeviceFault::not_open;  // `state` untouched, as on every device
  // A held pen read, commanded and read again with no advance() between: the program forgot to let time
  // pass, and the pen would sit still while the hand "writes". Refused, so it cannot go unnoticed.
  if (hand_ != nullptr && read_since_advance_ && written_since_read_) {
    enable_forces(false);
    return DeviceFault::not_advanced;
  }
  read_since_advance_ = true;
  written_since_read_ = false;
  const double q = parameters_.encoder_resolution_m;
  Vec3 quantised = position_;
  if (q > 0.0) quantised = (position_ / q).array().round().matrix() * q;
  if (!quantised.allFinite()) quantised = position_;  // x / q overflows only beyond 1e299 m
  const double dt = static_cast<double>(time_ns_ - last_read_ns_) / 1e9;
  if (read_before_ && dt > 0.0) {
    const Vec3 raw = (quantised - reported_position_) / dt;
    const double alpha = std::exp(-2.0 * std::numbers::pi * parameters_.velocity_cutoff_hz * dt);
    reported_velocity_ = alpha * reported_velocity_ + (1.0 - alpha) * raw;
  }
  read_before_ = true;
  last_read_ns_ = time_ns_;
  reported_position_ = quantised;
  state = DeviceState{};
  state.position_m = reported_position_;
  state.velocity_m_s = reported_velocity_;
  state.time_s = time();
  return DeviceFault::none;
}

void register_simulated_device(DeviceRegistry& registry) {
  registry.register_device_if_absent(
      "simulated", SimulatedDevice{}.info(), [] { return std::make_unique<SimulatedDevice>(); },
      DeviceCapabilities{.moved_by_simulated_hand = true},
      "a point mass moved by a simulated hand; its time passes on advance()");
}

}  // namespace calligraphy
