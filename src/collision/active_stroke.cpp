#include "calligraphy/collision/active_stroke.hpp"

#include "calligraphy/collision/constraint_space.hpp"

namespace calligraphy {

ActiveStroke::ActiveStroke(const Scene& scene, const StrokeAcceptance& acceptance) noexcept
    : scene_(&scene), acceptance_(acceptance) {
  reset();
}

void ActiveStroke::reset() noexcept {
  character_ = 0;
  stroke_ = 0;
  element_ = 0;
  written_ = 0;
  assisted_ = 0;
  misses_ = 0;
  attempt_ = StrokeProgressTracker{};
  attempt_open_ = false;
  // Skip characters without strokes so that the active stroke always exists until finished.
  while (character_ < scene_->characters.size() && scene_->characters[character_].strokes.empty())
    ++character_;
}

void ActiveStroke::next_stroke() noexcept {
  misses_ = 0;
  element_ = 0;
  ++stroke_;
  while (character_ < scene_->characters.size() && stroke_ >= scene_->characters[character_].strokes.size()) {
    ++character_;
    stroke_ = 0;
  }
}

void ActiveStroke::begin(const Vec2& tip_m) noexcept {
  if (const PlacedStroke* s = stroke()) {
    attempt_.begin(*s, tip_m, acceptance_);
    attempt_open_ = true;
  }
}

StrokeProgress ActiveStroke::advance(const Vec2& tip_m) noexcept {
  StrokeProgress progress;
  if (stroke() == nullptr || !attempt_.in_attempt()) return progress;
  const bool completed = attempt_.update(tip_m);
  const std::size_t element = attempt_.element_index();
  if (element > element_) {
    progress.elements_passed = static_cast<int>(element - element_);
    element_ = element;
  }
  if (completed) {
    progress.stroke_completed = true;
    attempt_open_ = false;
    ++written_;
    next_stroke();
  } else if (!attempt_.in_attempt()) {
    element_ = 0;  // the pen left the stroke's end across it: nothing of this attempt counts
  }
  return progress;
}

StrokeProgress ActiveStroke::lift(bool counts_as_miss) noexcept {
  StrokeProgress progress;
  if (stroke() == nullptr || !attempt_open_) return progress;
  attempt_open_ = false;
  progress.refusal = attempt_.refusal();
  if (attempt_.lift()) {
    progress.stroke_completed = true;
    progress.refusal = StrokeRefusal::none;
    ++written_;
    next_stroke();
    return progress;
  }
  element_ = 0;  // the stroke's feature points are loaded again (section 4.3.3)
  if (counts_as_miss) count_miss(progress);
  return progress;
}

StrokeProgress ActiveStroke::miss() noexcept {
  StrokeProgress progress;
  if (stroke() == nullptr) return progress;
  progress.refusal = StrokeRefusal::wrong_place;
  count_miss(progress);
  return progress;
}

void ActiveStroke::count_miss(StrokeProgress& progress) noexcept {
  ++misses_;
  const double assist = acceptance_.assist_after_misses;
  if (assist > 0.0 && static_cast<double>(misses_) >= assist) {
    // Demonstrated and credited as assisted (Hanzi Writer's markStrokeCorrectAfterMisses): no dead end.
    progress.stroke_assisted = true;
    ++assisted_;
    next_stroke();
  }
}

bool ActiveStroke::hint_shown() const noexcept {
  const double hint = acceptance_.hint_after_misses;
  return hint > 0.0 && !finished() && static_cast<double>(misses_) >= hint;
}

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
