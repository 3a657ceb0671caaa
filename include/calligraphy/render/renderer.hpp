#pragma once
/// \file renderer.hpp
/// The per-tick haptic renderer (paper section 4, Fig. 15): device state in, force out. Usable on its
/// own from an application's servo loop (an OpenHaptics scheduler callback, a CHAI3D haptics thread):
/// call `tick` once per servo tick at the rate given in `RendererOptions`. `tick` is noexcept and never
/// allocates. Pipeline per tick: state machine (Fig. 6) -> collision with the active element (section
/// 4.3) -> force law (eqs. 7-9) with the smoothing of section 6 and paper friction -> optional
/// passivity controller -> safety chain. The in-plane guidance has three modes (guidance_mode.hpp: the
/// paper's fixed fixture, fading, teacher replay). Details and measurements: docs/force-rendering.md.
#include <cstdint>
#include <limits>

#include "calligraphy/collision/active_stroke.hpp"
#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/interaction_state.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/render/teacher_replay.hpp"
#include "calligraphy/render/timing_target.hpp"

namespace calligraphy {

/// How the renderer is run: the servo rate and the stages after the force law.
struct RendererOptions {
  double rate_hz = 1000.0;  ///< servo rate [Hz], in [100, 100000]
  /// Safety chain. `max_force_n` and `max_continuous_force_n` left at 0 take the device's figures; one given
  /// above the device's is taken as the device's (never more than the device can give).
  SafetyChainParameters safety{};
  PassivityParameters passivity{};  ///< Hannaford-Ryu observer and controller (off by default)
  /// Throws InvalidArgument naming the field when a value is out of range.
  void validate() const;
};

/// Everything one tick decided.
struct RenderOutput {
  Vec3 force_n = Vec3::Zero();  ///< command for the device [N], finite, within the safety chain's limits
  InteractionState state = InteractionState::separation;
  bool state_changed = false;
  std::size_t character = 0;         ///< active character index (valid unless `finished`)
  std::size_t stroke = 0;            ///< active stroke index within the character
  std::size_t element = 0;           ///< active element index within the stroke
  bool finished = false;             ///< every stroke of the scene has been written
  bool in_constraint_space = false;  ///< the tip is inside R_res of the active element
  Vec2 foot_m = Vec2::Zero();        ///< X_S on the active element (WS only) [m]
  bool stroke_completed = false;     ///< this tick wrote a stroke (passed its end, or lifted near it)
  bool stroke_abandoned = false;     ///< the pen was lifted in WS short of the tolerances: reloaded
  StrokeRefusal refusal = StrokeRefusal::none;  ///< why an abandoned stroke was refused (stroke_progress.hpp)
  /// The abandoned stroke was refused for the `assist_after_misses`-th time (StrokeAcceptance): credited
  /// as assisted, not written; the next stroke is active.
  bool stroke_assisted = false;
  /// The pen was lifted from a pen-down that never entered WS (it never came near the active stroke's start)
  /// and that counts as a miss (StrokeAcceptance::counts_as_miss): `refusal` wrong_place, `misses` one more,
  /// or the stroke credited assisted.
  bool missed_off_start = false;
  std::uint32_t misses = 0;  ///< refused attempts at the active stroke (after this tick)
  bool hint_shown = false;   ///< the active stroke is to be shown as a hint (misses >= hint_after_misses)
  /// The device state (position, velocity, time stamp) was not finite, or a coordinate lay beyond
  /// kMaxDeviceReadingM: zero force.
  bool input_rejected = false;
  bool force_error = false;                  ///< the force law gave a non-finite force: zero force
  std::uint8_t limits = safety_none;         ///< SafetyLimit bits: which safety stages acted
  double passivity_damping_n_s_per_m = 0.0;  ///< damper added by the passivity controller [N s/m]
};

class Renderer {
 public:
  /// `scene` must outlive the renderer. Throws InvalidArgument when the parameters or options are out
  /// of range, `device.max_force_n` is not positive, or (replay mode) the teacher trajectory does not
  /// write every stroke of the scene in order (teacher_replay.hpp). Logs a warning (here, never per tick)
  /// when a stiffness exceeds the device's stable maximum or Colgate's bound 2 (b - B) rate.
  Renderer(const Scene& scene, const ForceLawParameters& parameters, const DeviceInfo& device,
           const RendererOptions& options = {});
  /// The same with values already checked (checked.hpp): neither is validated again. What a trial session
  /// gives the renderer; the constructor above checks its arguments and comes here.
  Renderer(const Scene& scene, const Checked<ForceLawParameters>& parameters, const DeviceInfo& device,
           const Checked<RendererOptions>& options);

  /// One servo tick. Never throws, never allocates.
  RenderOutput tick(const DeviceState& state) noexcept;
  /// Back to the first stroke, state SS; the safety chain's ramp restarts.
  void reset() noexcept;

  [[nodiscard]] const ActiveStroke& active() const noexcept { return active_; }
  [[nodiscard]] InteractionState state() const noexcept { return state_; }
  [[nodiscard]] const ForceLawParameters& parameters() const noexcept { return parameters_; }
  [[nodiscard]] const RendererOptions& options() const noexcept { return options_; }
  /// The rate `tick` must be called at [Hz] and where it was set: a `ServoLoop` given the renderer's callback
  /// through `ticking(renderer, callback)` (servo_loop.hpp) refuses to start at another rate.
  [[nodiscard]] double servo_rate_hz() const noexcept { return options_.rate_hz; }
  [[nodiscard]] static const char* servo_rate_name() noexcept { return "RendererOptions::rate_hz"; }
  [[nodiscard]] const Scene& scene() const noexcept { return *scene_; }
  [[nodiscard]] const SafetyChain& safety_chain() const noexcept { return chain_; }
  [[nodiscard]] const PassivityController& passivity() const noexcept { return passivity_; }
  /// The teacher's strokes in the replay mode (empty in the others).
  [[nodiscard]] const TeacherReplay& teacher_replay() const noexcept { return replay_; }

 private:
  /// `slack` in [0, 1]: the share of the guidance released near a corner (renderer.cpp, corner_slack).
  Vec2 guidance_force(const DeviceState& device, RenderOutput& out, bool element_changed,
                      double slack) noexcept;
  void command(const Vec3& force, RenderOutput& out) noexcept;

  const Scene* scene_;
  ForceLawParameters parameters_;
  RendererOptions options_;
  double period_s_;
  ActiveStroke active_;
  InteractionState state_ = InteractionState::separation;
  SafetyChain chain_;
  PassivityController passivity_;
  NearestPointTracker tracker_;
  TeacherReplay replay_;
  TimingTarget timing_;  // the `timing` mode's moving target
  // The guidance law's numbers, read from its variant once at construction so that a tick reads plain values.
  GuidanceMode mode_ = GuidanceMode::fixed;
  double guidance_gain_ = 1.0;     // the fading or repulsive gain; 1 in the other modes
  double assist_band_m_ = 0.0;     // assist-as-needed's slack band; 0 in the other modes
  double guidance_reach_m_ = 0.0;  // where the pull saturates: a moving target's max lead, else R_res
  double guidance_max_force_n_ = std::numeric_limits<double>::infinity();  // the repulsive field's bound
  double writing_since_s_ = 0.0;  // device time at which WS was entered on the active stroke (replay clock)
  Vec2 off_stroke_velocity_ = Vec2::Zero();  // low-passed in-plane velocity for the off-stroke damper
  Vec2 off_stroke_anchor_ = Vec2::Zero();    // adhesion point of the off-stroke friction in CS
  bool anchor_valid_ = false;
  double off_stroke_alpha_ = 1.0;  // its filter coefficient per tick
  // The pen-down under way, from the touch-down (its samples are ticks; entered WS also when it wrote a
  // stroke without a lift): a refusal at its lift is a miss by StrokeAcceptance::counts_as_miss.
  RefusedPenDown contact_;
  Vec2 contact_tip_m_ = Vec2::Zero();  // where the pen-down's path reached last tick
  // Smoothing state.
  Vec2 rendered_foot_ = Vec2::Zero();  // attraction target, rate-limited towards the tracked foot
  bool foot_valid_ = false;
  double paper_weight_ = 0.0;      // fade of the paper force, 0..1
  Vec2 guidance_ = Vec2::Zero();   // last in-plane guidance force after the cross-fade
  Vec2 fade_from_ = Vec2::Zero();  // guidance force at the start of the running cross-fade
  double fade_elapsed_s_ = 0.0;
  bool was_inside_ = false;
};

}  // namespace calligraphy
