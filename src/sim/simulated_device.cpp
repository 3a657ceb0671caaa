#include "calligraphy/sim/simulated_device.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/phantom_models.hpp"
#include "calligraphy/render/force_law.hpp"

namespace calligraphy {

DeviceInfo simulated_phantom_desktop_info() {
  DeviceInfo info = phantom_desktop_info();  // the one table of Phantom figures
  info.model += " (simulated)";
  info.manufacturer = "calligraphy";
  return info;
}

void SimulatedDeviceParameters::validate() const {
  const auto fail = [](const std::string& what) {
    throw InvalidArgument("SimulatedDeviceParameters: " + what);
  };
  if (!(moving_mass_kg > 0.0) || !std::isfinite(moving_mass_kg)) fail("moving_mass_kg must be > 0");
  if (!(damping_n_s_per_m >= 0.0) || !std::isfinite(damping_n_s_per_m))
    fail("damping_n_s_per_m must be >= 0");
  if (!(encoder_resolution_m >= 0.0) || !std::isfinite(encoder_resolution_m))
    fail("encoder_resolution_m must be >= 0");
  if (!(velocity_cutoff_hz > 0.0)) fail("velocity_cutoff_hz must be > 0");
  if (physics_substeps < 1) fail("physics_substeps must be >= 1");
  if (!initial_position_m.allFinite()) fail("initial_position_m must be finite");
  if (!(info.max_force_n > 0.0)) fail("info.max_force_n must be > 0");
}

SimulatedDevice::SimulatedDevice(const SimulatedDeviceParameters& parameters)
    : parameters_(parameters),
      position_(parameters.initial_position_m),
      reported_position_(parameters.initial_position_m) {
  parameters_.validate();
}

void SimulatedDevice::close() noexcept {
  force_ = Vec3::Zero();
  open_ = false;
}

void SimulatedDevice::enable_forces(bool enabled) {
  forces_enabled_ = enabled;
  if (!enabled) force_ = Vec3::Zero();
}

void SimulatedDevice::write_force(const Vec3& force_n) {
  force_ = forces_enabled_ ? clamp_force(force_n, parameters_.info.max_force_n) : Vec3::Zero();
}

void SimulatedDevice::advance(double dt_s) noexcept {
  if (!(dt_s > 0.0)) return;
  const double h = dt_s / parameters_.physics_substeps;
  for (int i = 0; i < parameters_.physics_substeps; ++i) {
    const Vec3 hand = hand_ != nullptr ? hand_->hand_force(time_, position_, velocity_) : Vec3::Zero();
    const Vec3 acceleration =
        (hand + force_ - parameters_.damping_n_s_per_m * velocity_) / parameters_.moving_mass_kg;
    velocity_ += h * acceleration;  // semi-implicit Euler: stable for the stiff hand spring at h <= 0.1 ms
    position_ += h * velocity_;
    time_ += h;
  }
}

DeviceState SimulatedDevice::read_state() {
  const double q = parameters_.encoder_resolution_m;
  Vec3 quantised = position_;
  if (q > 0.0) quantised = (position_ / q).array().round().matrix() * q;
  const double dt = time_ - last_read_time_;
  if (read_before_ && dt > 0.0) {
    const Vec3 raw = (quantised - reported_position_) / dt;
    const double alpha = std::exp(-2.0 * std::numbers::pi * parameters_.velocity_cutoff_hz * dt);
    reported_velocity_ = alpha * reported_velocity_ + (1.0 - alpha) * raw;
  }
  read_before_ = true;
  last_read_time_ = time_;
  reported_position_ = quantised;
  DeviceState state;
  state.position_m = reported_position_;
  state.velocity_m_s = reported_velocity_;
  state.time_s = time_;
  return state;
}

void register_simulated_device(DeviceRegistry& registry) {
  const auto present = [&] {
    const auto names = registry.backend_names();
    return std::find(names.begin(), names.end(), "simulated") != names.end();
  };
  if (present()) return;
  try {
    registry.register_device("simulated", simulated_phantom_desktop_info(),
                             [] { return std::make_unique<SimulatedDevice>(); });
  } catch (const InvalidArgument&) {
    if (!present()) throw;  // another thread registered it between the check and here
  }
}

DeviceRegistry& device_registry_with_simulation() {
  DeviceRegistry& registry = device_registry();
  register_simulated_device(registry);
  return registry;
}

}  // namespace calligraphy
