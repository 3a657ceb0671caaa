#include "calligraphy/collision/constraint_space.hpp"

namespace calligraphy {

bool lse_rules_inside(const Vec2& start, const Vec2& end, const Vec2& tip) noexcept {
  const Vec2 edge = end - start;               // PEdge
  if (edge.squaredNorm() == 0.0) return true;  // rule (d)
  const Vec2 p1 = tip - start;
  const double along = p1.dot(edge);
  if (along < 0.0) return false;  // rule (a)
  // Rules (b), (c) as printed compare |P1| with |PEdge|: a disc of radius |PEdge| around the start.
  // Inside the tube of radius R this trims only d^2 / (2 |PEdge|) off the end, and the end's feature
  // plane takes over there anyway.
  return p1.squaredNorm() <= edge.squaredNorm();
}

ElementContact element_contact(const StrokeElement& element, const Vec2& tip, double radius_m,
                               const NearestPointOptions& options) noexcept {
  ElementContact contact;
  if (element.degree == 1) {
    contact.nearest = nearest_point_on_segment(element.start(), element.end(), tip);
    contact.inside =
        lse_rules_inside(element.start(), element.end(), tip) && contact.nearest.distance <= radius_m;
    return contact;
  }
  try {
    contact.nearest = nearest_point(element, tip, options);
  } catch (...) {
    // Only non-finite input throws; the renderer rejects that before collision detection.
    contact.nearest = {0.0, element.start(), 0.0};
    return contact;
  }
  return element_contact_at(element, tip, contact.nearest, radius_m);
}

ElementContact element_contact_at(const StrokeElement& element, const Vec2& tip, const NearestPoint& nearest,
                                  double radius_m) noexcept {
  ElementContact contact;
  contact.nearest = nearest;
  if (element.degree == 1) {
    contact.inside = lse_rules_inside(element.start(), element.end(), tip) && nearest.distance <= radius_m;
    return contact;
  }
  const Vec2 start_tangent = element.unit_tangent(0.0);
  const Vec2 end_tangent = element.unit_tangent(1.0);
  const bool before_start = (tip - element.start()).dot(start_tangent) < 0.0 && contact.nearest.t <= 0.0;
  const bool past_end = (tip - element.end()).dot(end_tangent) > 0.0 && contact.nearest.t >= 1.0;
  contact.inside = !before_start && !past_end && contact.nearest.distance <= radius_m;
  return contact;
}


}  // namespace calligraphy
