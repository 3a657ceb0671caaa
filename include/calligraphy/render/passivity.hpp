#pragma once
/// \file passivity.hpp
/// Passivity of the rendered force: bounds and an energy check that keep the contact from injecting energy.
///  - `colgate_stiffness_bound`: a sampled virtual wall K with virtual damping B on a device with
///    physical damping b, held by a zero-order hold at period T, is passive when b > K T / 2 + |B|
///    (Colgate & Schenkel 1997), i.e. K < 2 (b - |B|) / T.
///  - `PassivityController`: the time-domain passivity observer and controller of Hannaford & Ryu
///    (2002). The observer sums the energy the virtual environment has absorbed through the device
///    port, E = -sum F(k-1) . (x(k) - x(k-1)) [J] (the force held over the last tick times the
///    displacement it acted on); while E < 0 the environment has produced energy, and a variable
///    damper -alpha v with alpha = -E / (T |v|^2) (capped) dissipates it.
/// Servo path: noexcept, no allocation.
#include "calligraphy/core/geometry.hpp"
#include "calligraphy/core/parameter_table.hpp"

namespace calligraphy {

/// Largest passive stiffness [N/m] of a sampled wall: 2 (b - B) / T = 2 (b - B) rate, 0 when B >= b.
/// `device_damping_n_s_per_m` b >= 0 [N s/m], `rate_hz` = 1/T > 0 [Hz], `virtual_damping_n_s_per_m`
/// B >= 0 [N s/m]. Throws InvalidArgument when a value is out of range or not finite.
[[nodiscard]] double colgate_stiffness_bound(double device_damping_n_s_per_m, double rate_hz,
                                             double virtual_damping_n_s_per_m = 0.0);

/// Parameters of the passivity controller.
struct PassivityParameters {
  bool enabled = false;                 ///< observer and controller on
  double max_damping_n_s_per_m = 20.0;  ///< cap on the variable damper alpha [N s/m], > 0
  double min_speed_m_s = 1e-4;          ///< below this speed no damping is added [m/s], > 0
  /// Throws InvalidArgument naming the field when a value is outside its table's range
  /// (`ParameterTable<PassivityParameters>`).
  void validate() const;
};

/// The numeric fields of PassivityParameters (parameter_table.hpp); `enabled` is not in it.
template <>
struct ParameterTable<PassivityParameters> {
  static constexpr std::string_view name = "PassivityParameters";
  [[nodiscard]] static std::span<const ParameterField<PassivityParameters>> fields() noexcept;
};

class PassivityController {
 public:
  /// `rate_hz` > 0 [Hz]. Throws InvalidArgument for bad parameters.
  PassivityController(const PassivityParameters& parameters, double rate_hz);

  /// One tick. `position_m`, `velocity_m_s`: device state now; `held_force_n`: the force commanded
  /// last tick (held over the interval just ended) [N]; `force_n`: the environment's force now [N].
  /// Returns `force_n` plus the damping force [N]. Non-finite input leaves the state unchanged.
  Vec3 apply(const Vec3& position_m, const Vec3& velocity_m_s, const Vec3& held_force_n,
             const Vec3& force_n) noexcept;
  /// Clears the observed energy and the last position.
  void reset() noexcept;

  /// Energy absorbed by the environment so far [J]; negative means it has produced energy.
  [[nodiscard]] double observed_energy_j() const noexcept { return energy_j_; }
  /// The damper of the last tick [N s/m].
  [[nodiscard]] double damping_n_s_per_m() const noexcept { return alpha_; }

 private:
  PassivityParameters parameters_;
  double period_s_;
  double energy_j_ = 0.0;
  double alpha_ = 0.0;
  Vec3 last_position_ = Vec3::Zero();
  bool have_position_ = false;
};

}  // namespace calligraphy
