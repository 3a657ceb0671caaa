#include "trainer/live_quiz.hpp"

#include <cstdio>
#include <string>

#include "calligraphy/report/pen_trace_csv.hpp"

namespace calligraphy::trainer {
namespace {

// Points closer than this to the last one kept are not drawn: the trace is drawn, not analysed (the quiz
// keeps every sample).
constexpr double kInkStepM = 0.0001;

}  // namespace

LiveQuiz::LiveQuiz(const Scene& scene, const QuizOptions& options) : paper_z_m_(scene.layout.paper_z_m) {
  std::size_t first = 0;
  for (const PlacedCharacter& c : scene.characters) {
    sessions_.emplace_back(c, options);
    assisted_.emplace_back(c.strokes.size(), false);
    first_stroke_.push_back(first);
    first += c.strokes.size();
  }
  hinted_.resize(sessions_.size());
  last_backwards_.resize(sessions_.size(), false);
  last_refusal_.resize(sessions_.size(), StrokeRefusal::none);
}

// As study_detail::pen_samples_of_character: a tick belongs to the character whose strokes hold the active
// stroke; ticks after the scene's last stroke to the last character.
std::size_t LiveQuiz::character_of(std::uint32_t stroke_index) const {
  std::size_t character = 0;
  for (std::size_t c = 0; c < first_stroke_.size(); ++c) {
    if (first_stroke_[c] <= stroke_index) character = c;
  }
  return character;
}

void LiveQuiz::take(std::size_t character, const std::vector<QuizEvent>& events,
                    std::vector<std::pair<std::size_t, QuizEvent>>& out) {
  for (const QuizEvent& e : events) {
    out.emplace_back(character, e);
    last_event_ = out.back();
    switch (e.kind) {
      case QuizEvent::Kind::stroke_accepted:
      case QuizEvent::Kind::stroke_missed:
      case QuizEvent::Kind::too_short:
        last_backwards_[character] = e.backwards;
        last_refusal_[character] = e.refusal;
        inks_.push_back(QuizInk{character, character == open_character_ ? open_run_ : std::vector<Vec2>{},
                                e.kind, std::chrono::steady_clock::now()});
        if (e.kind == QuizEvent::Kind::stroke_accepted) hinted_[character].reset();
        break;
      case QuizEvent::Kind::hint:
        hinted_[character] = e.stroke;
        break;
      case QuizEvent::Kind::stroke_assisted:
        hinted_[character].reset();
        assisted_[character][e.stroke] = true;
        last_assisted_ = Assisted{character, e.stroke, std::chrono::steady_clock::now()};
        break;
      case QuizEvent::Kind::character_completed:
        break;
    }
  }
}

std::vector<std::pair<std::size_t, QuizEvent>> LiveQuiz::feed(const TracePoint& point) {
  std::vector<std::pair<std::size_t, QuizEvent>> out;
  if (finished_) return out;
  const std::size_t character = character_of(point.stroke_index);
  const bool pen_down = point.hip_m.z - paper_z_m_ <= PenTraceCsvOptions{}.contact_threshold_m;
  const Vec2 position(point.hip_m.x, point.hip_m.y);
  if (character != open_character_) open_run_.clear();  // the run goes on in another character's quiz
  open_character_ = character;
  if (pen_down && !sessions_[character].complete() &&
      (open_run_.empty() || (open_run_.back() - position).norm() >= kInkStepM)) {
    open_run_.push_back(position);
  }
  take(character, sessions_[character].feed(PenSample{point.time_s, position, pen_down}), out);
  if (!pen_down) open_run_.clear();
  return out;
}

std::vector<std::pair<std::size_t, QuizEvent>> LiveQuiz::finish() {
  std::vector<std::pair<std::size_t, QuizEvent>> out;
  if (finished_) return out;
  for (std::size_t c = 0; c < sessions_.size(); ++c) take(c, sessions_[c].finish(), out);
  open_run_.clear();
  finished_ = true;
  return out;
}

bool LiveQuiz::assisted(std::size_t character, std::size_t stroke) const noexcept {
  return character < assisted_.size() && stroke < assisted_[character].size() && assisted_[character][stroke];
}

bool LiveQuiz::complete() const noexcept {
  for (const QuizSession& s : sessions_) {
    if (!s.complete()) return false;
  }
  return true;
}

std::vector<std::vector<QuizEvent>> LiveQuiz::events() const {
  std::vector<std::vector<QuizEvent>> all;
  for (const QuizSession& s : sessions_) all.push_back(s.events());
  return all;
}

std::string describe(const QuizEvent& event) {
  std::string why;
  if (event.backwards) {
    why = ", backwards";
  } else if (event.refusal != StrokeRefusal::none) {
    why = std::string(", ") + to_string(event.refusal);
  }
  if (event.written_stroke) why += ", wrote stroke " + std::to_string(*event.written_stroke + 1);
  char line[160];
  std::snprintf(line, sizeof line, "stroke %zu: %s (misses %d on the stroke, %d in all%s)", event.stroke + 1,
                to_string(event.kind), event.misses_on_stroke, event.total_misses, why.c_str());
  return line;
}

std::string count_of(std::size_t count, std::string_view one, std::string_view many) {
  return std::to_string(count) + " " + std::string(count == 1 ? one : many);
}

}  // namespace calligraphy::trainer
