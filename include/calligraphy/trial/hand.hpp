#pragma once
/// \file hand.hpp
/// Who moves a device a person does not hold: the hand a lock-step trial is given (a simulated writer,
/// `SimulatedHand` in calligraphy/sim/simulated_hand.hpp). The trial knows only this interface; what the
/// hand is, how it writes and what it logs belong to the caller that made it.
#include <cstdint>
#include <memory>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/result.hpp"

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

/// What makes the hand when a trial specification's simulated writer writes (TrialRunInputs::hand_maker):
/// the caller's, from calligraphy/sim (`SimulatedWriting`), so that the trial layer makes no writer and
/// keeps none of its state. Used by one trial at a time.
class TrialHandMaker {
 public:
  virtual ~TrialHandMaker() = default;
  TrialHandMaker() = default;
  TrialHandMaker(const TrialHandMaker&) = delete;
  TrialHandMaker& operator=(const TrialHandMaker&) = delete;

  /// A hand that moves `device` (one with a hand port) to write `scene`, drawing at random from `seed`.
  [[nodiscard]] virtual std::unique_ptr<TrialHand> make_hand(HapticDevice& device, const Scene& scene,
                                                             std::uint64_t seed) = 0;
  /// After the trial of the hand last made, which has let go and is not yet destroyed: marks in `result`'s
  /// trace what the hand knows (which stroke each of its pen-down segments meant) and keeps what it did.
  virtual void after_trial(TrialResult& result) = 0;
};

}  // namespace calligraphy
