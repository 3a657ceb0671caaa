#include "calligraphy/study/quiz.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// The judgement needs the matching and the mean distance only, not fine curve distances: a coarse
// comparison keeps each judgement within milliseconds.
constexpr std::size_t kQuizCurvePoints = 64;

}  // namespace

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

QuizSession::Verdict QuizSession::judge(std::size_t stroke, double leniency) const {
  PlacedCharacter alone = character_;  // the expected stroke alone: the match is against it only
  alone.strokes = {character_.strokes[stroke]};
  ScoreOptions options;
  options.leniency = leniency;
  options.metrics.curves.max_points = kQuizCurvePoints;
  const CharacterScore score = score_trace(alone, segment_, options);
  Verdict verdict;
  verdict.too_short = score.segments.size() == 1 && score.segments.front().ignored;
  const StrokeScore& result = score.strokes.front();
  verdict.matched = result.written;
  verdict.backwards = result.backwards;
  if (result.metrics) verdict.mean_distance_m = result.metrics->deviation.mean_m;
  return verdict;
}

std::vector<QuizEvent> QuizSession::judge_segment() {
  std::vector<QuizEvent> out;
  if (segment_.empty() || complete()) {
    segment_.clear();
    return out;
  }
  QuizEvent event;
  event.stroke = current_;
  event.time_s = segment_.back().time_s;
  event.samples = segment_.size();
  Verdict verdict = judge(current_, options_.leniency);
  if (verdict.too_short) {
    event.kind = QuizEvent::Kind::too_short;
    event.misses_on_stroke = misses_on_stroke_;
    event.total_misses = total_misses_;
    out.push_back(event);
  } else {
    if (verdict.matched && !verdict.backwards) {
      // A later stroke matched more closely: the writer probably wrote that one (Hanzi Writer's check).
      double closest = verdict.mean_distance_m;
      for (std::size_t later = current_ + 1; later < character_.strokes.size(); ++later) {
        const Verdict other = judge(later, options_.leniency);
        if (other.matched && !other.backwards && other.mean_distance_m < closest) {
          closest = other.mean_distance_m;
          event.closer_later_stroke = later;
        }
      }
      if (event.closer_later_stroke && verdict.mean_distance_m > 0.0) {
        verdict = judge(current_,
                        options_.leniency * closer_stroke_leniency_factor(closest, verdict.mean_distance_m));
      }
    }
    const bool accepted = verdict.matched && (!verdict.backwards || options_.accept_backwards);
    event.backwards = verdict.matched && verdict.backwards;
    if (accepted) {
      event.kind = QuizEvent::Kind::stroke_accepted;
      misses_on_stroke_ = 0;
      ++current_;
      event.total_misses = total_misses_;
      out.push_back(event);
      if (complete()) {
        QuizEvent done = event;
        done.kind = QuizEvent::Kind::character_completed;
        done.backwards = false;
        done.closer_later_stroke.reset();
        out.push_back(done);
      }
    } else {
      event.kind = QuizEvent::Kind::stroke_missed;
      event.misses_on_stroke = ++misses_on_stroke_;
      event.total_misses = ++total_misses_;
      out.push_back(event);
      if (options_.hint_after_misses > 0 && misses_on_stroke_ >= options_.hint_after_misses) {
        QuizEvent hint = event;
        hint.kind = QuizEvent::Kind::hint;
        hint.backwards = false;
        hint.closer_later_stroke.reset();
        out.push_back(hint);
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
                          std::to_string(sample.time_s) + " s after " + std::to_string(last_time_s_) + " s)");
  }
  ++samples_fed_;
  last_time_s_ = sample.time_s;
  if (complete()) return {};
  if (sample.pen_down) {
    segment_.push_back(sample);
    return {};
  }
  return judge_segment();
}

std::vector<QuizEvent> QuizSession::finish() { return judge_segment(); }

}  // namespace calligraphy
