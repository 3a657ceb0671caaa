#pragma once
/// \file hand.hpp
/// Who moves a device a person does not hold: the hand a lock-step trial is given (a simulated writer,
/// `SimulatedHand` in calligraphy/sim/simulated_hand.hpp). The trial knows only this interface; what the
/// hand is, how it writes and what it logs belong to the caller that made it.
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/render/renderer.hpp"

namespace calligraphy {

/// A hand that moves a device between servo ticks. Called on the thread that steps the trial (the
/// `ServoLoop` thread in real time), right after each tick; not thread-safe.
class TrialHand {
 public:
  virtual ~TrialHand() = default;
  TrialHand() = default;
  TrialHand(const TrialHand&) = delete;
  TrialHand& operator=(const TrialHand&) = delete;

  /// Sees one tick: the renderer's output (the force commanded and what the display shows) and the
  /// pen's state that tick was computed from.
  virtual void observe(const RenderOutput& output, const DeviceState& pen) = 0;
  /// True once the hand has stopped writing before the character was written (it gave up); the trial then
  /// ends with `TrialEnd::gave_up`.
  [[nodiscard]] virtual bool stopped() const noexcept = 0;
  /// True when the hand stopped because it wrote all it meant to write, not because it gave up: the trial
  /// then ends with `TrialEnd::writer_finished`. The default: false.
  [[nodiscard]] virtual bool finished() const noexcept { return false; }
  /// Lets `dt_s` seconds [s] of the device's time pass under the force held since the last
  /// `write_force` and the hand's own force (the device's time advances only here).
  virtual void advance(double dt_s) = 0;
  /// Lets go of the stylus; called once on every way out of the trial. Never throws.
  virtual void release() noexcept = 0;
};

}  // namespace calligraphy
