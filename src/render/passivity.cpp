#include "calligraphy/render/passivity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {

double colgate_stiffness_bound(double device_damping_n_s_per_m, double rate_hz,
                               double virtual_damping_n_s_per_m) {
  if (!std::isfinite(device_damping_n_s_per_m) || device_damping_n_s_per_m < 0.0) {
    throw InvalidArgument("colgate_stiffness_bound: device damping " +
                          shortest_decimal(device_damping_n_s_per_m) + " N s/m must be finite and >= 0");
  }
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0)) {
    throw InvalidArgument("colgate_stiffness_bound: rate " + detail::rate_text(rate_hz) +
                          " must be finite and > 0");
  }
  if (!std::isfinite(virtual_damping_n_s_per_m) || virtual_damping_n_s_per_m < 0.0) {
    throw InvalidArgument("colgate_stiffness_bound: virtual damping " +
                          shortest_decimal(virtual_damping_n_s_per_m) + " N s/m must be finite and >= 0");
  }
  return std::max(0.0, 2.0 * (device_damping_n_s_per_m - virtual_damping_n_s_per_m) * rate_hz);
}

namespace {

using PassivityField = ParameterField<PassivityParameters>;

constexpr std::array kPassivityFields{
    PassivityField{"max_damping_n_s_per_m", "N s/m", kPositiveRange, "cap on the variable damper alpha",
                   &PassivityParameters::max_damping_n_s_per_m},
    PassivityField{"min_speed_m_s", "m/s", kPositiveRange, "speed below which no damping is added",
                   &PassivityParameters::min_speed_m_s},
};

}  // namespace

std::span<const ParameterField<PassivityParameters>> ParameterTable<PassivityParameters>::fields() noexcept {
  return kPassivityFields;
}

void PassivityParameters::validate() const { check_parameters(*this); }

PassivityController::PassivityController(const PassivityParameters& parameters, double rate_hz)
    : parameters_(parameters) {
  parameters_.validate();
  if (!std::isfinite(rate_hz) || !(rate_hz > 0.0)) {
    throw InvalidArgument("PassivityController: rate_hz = " + detail::rate_text(rate_hz) +
                          " must be finite and > 0");
  }
  period_s_ = 1.0 / rate_hz;
}

void PassivityController::reset() noexcept {
  energy_j_ = 0.0;
  alpha_ = 0.0;
  have_position_ = false;
}

Vec3 PassivityController::apply(const Vec3& position_m, const Vec3& velocity_m_s, const Vec3& held_force_n,
                                const Vec3& force_n) noexcept {
  if (!position_m.allFinite() || !velocity_m_s.allFinite() || !held_force_n.allFinite() ||
      !force_n.allFinite()) {
    return force_n;
  }
  // Observer (Hannaford & Ryu 2002, eq. 4 in energy form): work of the held force on the displacement.
  if (have_position_) energy_j_ -= held_force_n.dot(position_m - last_position_);
  last_position_ = position_m;
  have_position_ = true;
  alpha_ = 0.0;
  const double speed_squared = velocity_m_s.squaredNorm();
  if (energy_j_ >= 0.0 || speed_squared < parameters_.min_speed_m_s * parameters_.min_speed_m_s)
    return force_n;
  // Controller: a damper that dissipates the produced energy over the next tick.
  alpha_ = std::min(-energy_j_ / (period_s_ * speed_squared), parameters_.max_damping_n_s_per_m);
  return force_n - alpha_ * velocity_m_s;
}

}  // namespace calligraphy
