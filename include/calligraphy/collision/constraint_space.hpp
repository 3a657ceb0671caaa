#pragma once
/// \file constraint_space.hpp
/// Constraint space of stroke elements and feature planes (paper section 4.3). Servo path: no
/// allocation, no exceptions; callers pass finite values. Lengths in m.
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/element.hpp"

namespace calligraphy {

/// Where the tip is relative to an element (paper section 4.3.1, Fig. 19; extended to CSEs).
struct ElementContact {
  NearestPoint nearest;  ///< foot point X_S on the element
  bool inside = false;   ///< inside the constraint space R_res
};

/// LSE rules (a)-(d) of section 4.3.1 with P1 = tip - start, PEdge = end - start:
/// (a) P1.PEdge < 0: outside; (b) P1.PEdge > 0 and |P1| > |PEdge|: outside; (c) P1.PEdge > 0 and
/// |P1| < |PEdge|: inside; (d) start == end: inside. The boundaries (P1.PEdge == 0, |P1| == |PEdge|)
/// count as inside, which keeps the space closed.
[[nodiscard]] bool lse_rules_inside(const Vec2& start, const Vec2& end, const Vec2& tip) noexcept;

/// Contact with an element: the nearest point, and whether the tip is inside the constraint space,
/// i.e. within `radius_m` of the element and, for an LSE, inside rules (a)-(d); for a CSE, with its
/// foot past the start (the analogue of rule (a)) and not past the end (rule (b)).
[[nodiscard]] ElementContact element_contact(const StrokeElement& element, const Vec2& tip, double radius_m,
                                             const NearestPointOptions& options) noexcept;

/// The same with the foot point already found (e.g. by a NearestPointTracker): the inside rules only.
[[nodiscard]] ElementContact element_contact_at(const StrokeElement& element, const Vec2& tip,
                                                const NearestPoint& nearest, double radius_m) noexcept;

}  // namespace calligraphy
