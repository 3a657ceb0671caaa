#include "calligraphy/collision/active_stroke.hpp"

#include "calligraphy/collision/constraint_space.hpp"

namespace calligraphy {

ActiveStroke::ActiveStroke(const Scene& scene) noexcept : scene_(&scene) { reset(); }

void ActiveStroke::reset() noexcept {
  character_ = 0;
  stroke_ = 0;
  element_ = 0;
  written_ = 0;
  // Skip characters without strokes so that the active stroke always exists until finished.
  while (character_ < scene_->characters.size() && scene_->characters[character_].strokes.empty())
    ++character_;
}

void ActiveStroke::next_stroke() noexcept {
  ++written_;
  element_ = 0;
  ++stroke_;
  while (character_ < scene_->characters.size() && stroke_ >= scene_->characters[character_].strokes.size()) {
    ++character_;
    stroke_ = 0;
  }
}

StrokeProgress ActiveStroke::advance(const Vec2& tip_m, double plane_margin_m) noexcept {
  StrokeProgress progress;
  const PlacedStroke* s = stroke();
  if (s == nullptr) return progress;
  while (element_ < s->elements.size() &&
         feature_plane_passed(s->elements[element_], tip_m, plane_margin_m)) {
    ++element_;
    ++progress.planes_passed;
  }
  if (element_ >= s->elements.size()) {
    progress.stroke_completed = true;
    next_stroke();
  }
  return progress;
}

void ActiveStroke::reload() noexcept { element_ = 0; }

const PlacedCharacter* ActiveStroke::character() const noexcept {
  return finished() ? nullptr : &scene_->characters[character_];
}

const PlacedStroke* ActiveStroke::stroke() const noexcept {
  const PlacedCharacter* c = character();
  return c == nullptr ? nullptr : &c->strokes[stroke_];
}

const StrokeElement* ActiveStroke::element() const noexcept {
  const PlacedStroke* s = stroke();
  return s == nullptr ? nullptr : &s->elements[element_];
}

double ActiveStroke::attraction(double t) const noexcept {
  const PlacedStroke* s = stroke();
  if (s == nullptr || s->attraction_factors.size() < element_ + 2) return 1.0;
  return (1.0 - t) * s->attraction_factors[element_] + t * s->attraction_factors[element_ + 1];
}

}  // namespace calligraphy
