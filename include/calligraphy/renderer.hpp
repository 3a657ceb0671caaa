#pragma once
/// \file renderer.hpp
/// The per-tick haptic renderer (paper section 4, Fig. 15): device state in, force out. Usable on its
/// own from an application's servo loop (an OpenHaptics scheduler callback, a CHAI3D haptics thread):
/// call `tick` once per servo tick. `tick` is noexcept and never allocates.
#include "calligraphy/active_stroke.hpp"
#include "calligraphy/force_law.hpp"
#include "calligraphy/haptic_device.hpp"
#include "calligraphy/interaction_state.hpp"
#include "calligraphy/scene.hpp"

namespace calligraphy {

/// Everything one tick decided.
struct RenderOutput {
  Vec3 force_n = Vec3::Zero();                 ///< command for the device [N], finite, clamped
  InteractionState state = InteractionState::separation;
  bool state_changed = false;
  std::size_t character = 0;                   ///< active character index (valid unless `finished`)
  std::size_t stroke = 0;                      ///< active stroke index within the character
  std::size_t element = 0;                     ///< active element index within the stroke
  bool finished = false;                       ///< every stroke of the scene has been written
  bool in_constraint_space = false;            ///< the tip is inside R_res of the active element
  Vec2 foot_m = Vec2::Zero();                  ///< X_S on the active element (WS only) [m]
  bool stroke_completed = false;               ///< this tick wrote the last feature point of a stroke
  bool stroke_abandoned = false;               ///< the pen was lifted in WS: the stroke was reloaded
  bool input_rejected = false;                 ///< the device state was not finite: zero force
};

class Renderer {
 public:
  /// `scene` must outlive the renderer. Throws InvalidArgument when the parameters are out of range
  /// or `device.max_force_n` is not positive; logs a warning when a stiffness exceeds the device's.
  Renderer(const Scene& scene, const ForceLawParameters& parameters, const DeviceInfo& device);

  /// One servo tick. Never throws, never allocates.
  RenderOutput tick(const DeviceState& state) noexcept;
  /// Back to the first stroke, state SS.
  void reset() noexcept;

  [[nodiscard]] const ActiveStroke& active() const noexcept { return active_; }
  [[nodiscard]] InteractionState state() const noexcept { return state_; }
  [[nodiscard]] const ForceLawParameters& parameters() const noexcept { return parameters_; }
  [[nodiscard]] const Scene& scene() const noexcept { return *scene_; }

 private:
  const Scene* scene_;
  ForceLawParameters parameters_;
  double max_force_n_;
  ActiveStroke active_;
  InteractionState state_ = InteractionState::separation;
};

}  // namespace calligraphy
