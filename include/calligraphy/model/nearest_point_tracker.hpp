#pragma once
/// \file nearest_point_tracker.hpp
/// Following the nearest point on one stroke element from servo tick to tick (1 kHz). Each tick
/// refines the previous foot point with a few damped Newton steps (a local search);
/// every `global_check_period` ticks the exact global search runs as well, and the tracker moves
/// to the global minimum only when it is nearer than the tracked one by more than
/// `switch_hysteresis_m`. So the foot point does not flip between near-equal minima (a pen on the
/// axis of a symmetric arc, near a self-crossing); it still jumps when another part of the curve
/// becomes clearly nearer (the pen crossed the curve's medial axis), which the force path must smooth.
/// Behaviour and measurements: docs/nearest-point.md.

#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// Parameters of `NearestPointTracker`.
struct NearestPointTrackerOptions {
  /// Ticks between two global (exact) searches, >= 1; 1 searches globally every tick. At 1 kHz
  /// the default bounds the time spent in a stale minimum to 16 ms.
  int global_check_period = 16;
  /// Length [m], >= 0: a minimum found by the global search replaces the tracked one only when
  /// it is nearer by more than this. 0.1 mm by default, above a haptic pen's position noise.
  double switch_hysteresis_m = 1e-4;
  /// Damped Newton steps per tick from the previous parameter, >= 1.
  int newton_iterations = 4;
  /// Parameter tolerance (dimensionless, in t) of the global search, > 0; see NearestPointOptions.
  double tolerance = 1e-12;
};

/// Tracks the foot point of a moving point on one element. Value type; allocation-free; `update`
/// is noexcept. Call `reset()` when the element changes (the next update then searches globally).
class NearestPointTracker {
 public:
  /// Throws InvalidArgument when an option is out of range (see NearestPointTrackerOptions).
  explicit NearestPointTracker(const NearestPointTrackerOptions& options = {});

  /// The nearest point of `p` on `element` (both in m) for this tick. The first update after
  /// construction or `reset()` is a global search. When `p` or a control point is not finite (or
  /// beyond 1e150 in magnitude, or the degree is not 1..4) the state is left unchanged and
  /// `current()` is returned: t = 0, foot (0, 0), distance 0 if nothing was tracked yet.
  NearestPoint update(const StrokeElement& element, const Vec2& p) noexcept;

  /// Forgets the tracked foot point; call it when the element changes.
  void reset() noexcept;

  /// True once an update has succeeded since construction or the last `reset()`.
  [[nodiscard]] bool tracking() const noexcept { return tracking_; }
  /// The last result returned by `update`.
  [[nodiscard]] const NearestPoint& current() const noexcept { return current_; }
  [[nodiscard]] const NearestPointTrackerOptions& options() const noexcept { return options_; }

 private:
  NearestPointTrackerOptions options_;
  NearestPoint current_;
  bool tracking_ = false;
  int ticks_since_global_ = 0;
};

}  // namespace calligraphy
