#include "calligraphy/analysis/quiz.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "analysis/segmentation.hpp"
#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"

namespace calligraphy {

void QuizOptions::validate() const {
  acceptance.validate();
  if (!std::isfinite(start_radius_m) || !(start_radius_m > 0.0)) {
    throw InvalidArgument("QuizOptions::start_radius_m must be finite and > 0, got " +
                          shortest_decimal(start_radius_m));
  }
  const ParameterRange range = parameter_field(&StrokeAcceptance::hint_after_misses).range;
  if (hint_after_misses && !range.contains(static_cast<double>(*hint_after_misses))) {
    throw InvalidArgument("QuizOptions::hint_after_misses must be " + range.text("") + ", got " +
                          std::to_string(*hint_after_misses));
  }
}

const char* to_string(QuizEvent::Kind kind) noexcept {
  switch (kind) {
    case QuizEvent::Kind::stroke_accepted:
      return "stroke_accepted";
    case QuizEvent::Kind::stroke_missed:
      return "stroke_missed";
    case QuizEvent::Kind::hint:
      return "hint";
    case QuizEvent::Kind::character_completed:
      return "character_completed";
    case QuizEvent::Kind::too_short:
      return "too_short";
    case QuizEvent::Kind::stroke_assisted:
      return "stroke_assisted";
  }
  return "unknown";
}

QuizSession::QuizSession(PlacedCharacter character, const QuizOptions& options)
    : character_(std::move(character)), options_(options) {
  options_.validate();
  if (character_.strokes.empty()) throw InvalidArgument("quiz: the character has no strokes");
  for (std::size_t i = 0; i < character_.strokes.size(); ++i) {
    if (character_.strokes[i].elements.empty()) {
      throw InvalidArgument("quiz: stroke " + std::to_string(i + 1) + " of the character has no elements");
    }
  }
}

std::vector<QuizEvent> QuizSession::judge_segment(bool lifted) {
  std::vector<QuizEvent> out;
  if (segment_.empty() || complete()) {
    segment_.clear();
    return out;
  }
  QuizEvent event;
  event.stroke = current_;
  event.time_s = segment_.back().time_s;
  event.samples = segment_.size();
  const ScoreOptions too_short;  // score_trace's rule for a segment it ignores
  const std::vector<WrittenSegment> runs = trial_detail::pen_down_segments(
      segment_, too_short.min_segment_samples, too_short.min_segment_length_m);
  if (runs.size() == 1 && runs.front().ignored) {
    event.kind = QuizEvent::Kind::too_short;
    event.misses_on_stroke = misses_on_stroke_;
    event.total_misses = total_misses_;
    out.push_back(event);
  } else {
    std::vector<Vec2> path;
    path.reserve(segment_.size());
    for (const PenSample& s : segment_) path.push_back(s.position_m);
    const StrokeMatch match =
        match_stroke(character_, current_, path, options_.start_radius_m, options_.acceptance);
    event.backwards = match.refusal == StrokeRefusal::backwards;
    const bool accepted = match.accepted || (event.backwards && options_.accept_backwards);
    // The expected stroke is done when written, or credited assisted after this miss made
    // `assist_after_misses` misses on it (ActiveStroke::lift, score_trace): the next is expected.
    const auto next_stroke = [&](const QuizEvent& last) {
      misses_on_stroke_ = 0;
      ++current_;
      if (complete()) {
        QuizEvent done = last;
        done.kind = QuizEvent::Kind::character_completed;
        done.backwards = false;
        done.misses_on_stroke = 0;
        out.push_back(done);
      }
    };
    if (accepted) {
      event.kind = QuizEvent::Kind::stroke_accepted;
      event.total_misses = total_misses_;
      out.push_back(event);
      next_stroke(event);
    } else {
      event.kind = QuizEvent::Kind::stroke_missed;
      event.refusal = match.refusal;
      // Another stroke written (a wrong_stroke that set off along the expected one and left it names none).
      if (match.matched_stroke != current_) event.written_stroke = match.matched_stroke;
      // Every mismatch lifted is a miss on the expected stroke, as Hanzi Writer counts them (not the run
      // `finish` judges, which was never lifted); the renderer and score_trace count the same at the
      // default acceptance (StrokeAcceptance::counts_as_miss; see quiz.hpp).
      if (lifted) ++misses_on_stroke_;
      event.misses_on_stroke = misses_on_stroke_;
      event.total_misses = ++total_misses_;
      out.push_back(event);
      QuizEvent shown = event;  // a hint or the assisted credit: the expected stroke shown
      shown.backwards = false;
      shown.refusal = StrokeRefusal::none;
      shown.written_stroke.reset();
      if (const int assist_after = options_.assist_after();
          assist_after > 0 && misses_on_stroke_ >= assist_after) {
        shown.kind = QuizEvent::Kind::stroke_assisted;
        ++strokes_assisted_;
        out.push_back(shown);
        next_stroke(shown);
      } else if (const int hint_after = options_.hint_after();
                 hint_after > 0 && misses_on_stroke_ >= hint_after) {
        shown.kind = QuizEvent::Kind::hint;
        out.push_back(shown);
      }
    }
  }
  segment_.clear();
  events_.insert(events_.end(), out.begin(), out.end());
  return out;
}

std::vector<QuizEvent> QuizSession::feed(const PenSample& sample) {
  const std::size_t index = samples_fed_;
  if (!std::isfinite(sample.time_s) || !sample.position_m.allFinite()) {
    throw InvalidArgument("quiz: pen sample " + std::to_string(index) +
                          " has a time or position that is not finite");
  }
  if (index > 0 && sample.time_s < last_time_s_) {
    throw InvalidArgument("quiz: pen sample " + std::to_string(index) + " goes back in time (" +
                          shortest_decimal(sample.time_s) + " s after " + shortest_decimal(last_time_s_) +
                          " s)");
  }
  ++samples_fed_;
  last_time_s_ = sample.time_s;
  if (complete()) return {};
  if (sample.pen_down) {
    segment_.push_back(sample);
    return {};
  }
  return judge_segment(true);
}

std::vector<QuizEvent> QuizSession::finish() { return judge_segment(false); }

std::vector<QuizEvent> quiz_character(const PlacedCharacter& character, std::span<const PenSample> samples,
                                      const QuizOptions& options) {
  QuizSession quiz(character, options);
  for (const PenSample& s : samples) quiz.feed(s);
  quiz.finish();
  return quiz.events();
}

}  // namespace calligraphy
