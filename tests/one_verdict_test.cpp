// One stroke matcher decides acceptance everywhere: a pen trace of person-like paths (sim/person_traces.hpp),
// written stroke after stroke with the pen lifted between them, gets the same verdict and the same refusal
// for every pen-down run from score_trace's segment verdicts, from a QuizSession fed the same samples, and
// from match_stroke called on each run in turn. And score_trace, whose one-to-one matching is built on the
// same pairwise test (attempt_stroke), finds the order and direction of the strokes written.
#include <algorithm>
#include <catch2/catch.hpp>
#include <optional>
#include <random>
#include <set>
#include <vector>

#include "calligraphy/analysis/quiz.hpp"
#include "calligraphy/analysis/score.hpp"
#include "calligraphy/analysis/stroke_matcher.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/person_traces.hpp"
#include "embedded_scenes.hpp"

using namespace calligraphy;

namespace {

const PlacedCharacter& character_of(char32_t c) { return testing::embedded_scene(c).characters.front(); }

// The runs as a pen trace at 1 kHz: each run's points pen down, then the pen lifted for 100 ms (samples at
// the run's last point).
std::vector<PenSample> pen_trace(const std::vector<std::vector<Vec2>>& runs) {
  std::vector<PenSample> trace;
  double t = 0.0;
  for (const std::vector<Vec2>& run : runs) {
    for (const Vec2& p : run) {
      trace.push_back({t, p, true});
      t += 1e-3;
    }
    for (int k = 0; k < 100; ++k) {
      trace.push_back({t, run.back(), false});
      t += 1e-3;
    }
  }
  return trace;
}

// One run per stroke, in stroke order, each of `kind` where it applies to the stroke and `human` otherwise.
std::vector<std::vector<Vec2>> runs_of_kind(const PlacedCharacter& c, TraceKind kind,
                                            std::mt19937_64& random) {
  std::vector<std::vector<Vec2>> runs;
  for (std::size_t s = 0; s < c.strokes.size(); ++s)
    runs.push_back(person_trace(c, s, trace_applies(c, s, kind) ? kind : TraceKind::human, random));
  return runs;
}

bool judged(QuizEvent::Kind kind) {
  return kind == QuizEvent::Kind::stroke_accepted || kind == QuizEvent::Kind::stroke_missed ||
         kind == QuizEvent::Kind::too_short;
}

}  // namespace

TEST_CASE("The score and the quiz give match_stroke's verdict and refusal for every pen-down run",
          "[score][quiz]") {
  std::mt19937_64 random(20260611);
  std::size_t accepted = 0, refused = 0, runs_judged = 0, assisted = 0;
  std::set<StrokeRefusal> reasons;
  for (const char32_t code_point : {U'十', U'口', U'人', U'永', U'我'}) {
    const PlacedCharacter& c = character_of(code_point);
    for (const TraceKind kind : kTraceKinds) {
      const std::vector<PenSample> trace = pen_trace(runs_of_kind(c, kind, random));
      INFO("character U+" << std::hex << static_cast<unsigned>(code_point) << std::dec << ", paths "
                          << to_string(kind));
      // At the default credit: the quiz counts every mismatch lifted as a miss (Hanzi Writer), the score
      // as the renderer does (StrokeAcceptance::counts_as_miss: any refused pen-down that moved), the same.
      const ScoreOptions with_credit;
      const CharacterScore score = score_trace(c, trace, with_credit);

      QuizOptions quiz_options;
      quiz_options.acceptance = with_credit.acceptance;
      QuizSession quiz(c, quiz_options);
      for (const PenSample& s : trace) quiz.feed(s);
      quiz.finish();
      std::vector<QuizEvent> events;
      for (const QuizEvent& e : quiz.events()) {
        if (judged(e.kind)) events.push_back(e);
      }

      // The renderer's reading, run by run: the expected stroke advances with each acceptance, and with
      // each credit after assist_after_misses misses of it.
      std::size_t expected = 0;
      std::size_t next_event = 0;
      std::size_t misses = 0;
      std::size_t credited = 0;
      for (std::size_t k = 0; k < score.segments.size(); ++k) {
        const WrittenSegment& segment = score.segments[k];
        INFO("run " << k << ", stroke " << expected << " expected");
        if (expected == c.strokes.size()) {  // every stroke accepted: nothing more is judged
          CHECK_FALSE(segment.verdict);
          continue;
        }
        REQUIRE(next_event < events.size());
        const QuizEvent& event = events[next_event++];
        CHECK(event.stroke == expected);
        if (segment.ignored) {
          CHECK_FALSE(segment.verdict);
          CHECK(event.kind == QuizEvent::Kind::too_short);
          continue;
        }
        std::vector<Vec2> path;
        for (std::size_t i = segment.begin; i < segment.end; ++i) path.push_back(trace[i].position_m);
        const StrokeMatch direct = match_stroke(c, expected, path, SceneLayout{}.start_radius_m);
        REQUIRE(segment.verdict);
        const StrokeMatch& verdict = *segment.verdict;
        CHECK(verdict.accepted == direct.accepted);
        CHECK(verdict.refusal == direct.refusal);
        CHECK(verdict.matched_stroke == direct.matched_stroke);
        CHECK((event.kind == QuizEvent::Kind::stroke_accepted) == direct.accepted);
        CHECK(event.refusal == direct.refusal);
        CHECK(event.backwards == (direct.refusal == StrokeRefusal::backwards));
        if (direct.matched_stroke != expected) {
          CHECK(event.written_stroke == std::optional<std::size_t>(direct.matched_stroke));
        } else {
          CHECK_FALSE(event.written_stroke);
        }
        ++runs_judged;
        if (direct.accepted) {
          ++expected;
          ++accepted;
          misses = 0;
        } else {
          ++refused;
          reasons.insert(direct.refusal);
          const bool lifted = segment.end < trace.size();
          misses += lifted ? 1 : 0;
          CHECK(static_cast<std::size_t>(event.misses_on_stroke) == misses);
          if (static_cast<double>(misses) >= with_credit.acceptance.assist_after_misses) {
            CHECK(segment.assists_due);
            CHECK(score.strokes[expected].assisted);
            ++expected;
            ++credited;
            misses = 0;
          }
        }
      }
      CHECK(next_event == events.size());  // every run the quiz judged is a segment of the score
      CHECK(score.strokes_accepted + score.strokes_assisted == expected);
      CHECK(score.strokes_assisted == credited);
      CHECK(quiz.strokes_assisted() == credited);
      CHECK(quiz.current_stroke() == expected);
      assisted += credited;
      const auto with_verdict = std::count_if(score.segments.begin(), score.segments.end(),
                                              [](const WrittenSegment& s) { return s.verdict.has_value(); });
      CHECK(score.refusals.total() + score.strokes_accepted == static_cast<std::size_t>(with_verdict));
    }
  }
  // The agreement is on verdicts of every sort, not only on easy acceptances.
  CHECK(runs_judged > 150);
  CHECK(accepted > 50);
  CHECK(refused > 50);
  CHECK(reasons.size() >= 4);
  CHECK(assisted > 0);  // and on the credit, where runs of a negative kind leave a stroke refused five times
}

TEST_CASE("score_trace finds the order and direction of person-like strokes", "[score]") {
  std::mt19937_64 random(7);
  for (const char32_t code_point : {U'十', U'口', U'人', U'永'}) {
    const PlacedCharacter& c = character_of(code_point);
    const std::size_t n = c.strokes.size();
    INFO("character U+" << std::hex << static_cast<unsigned>(code_point));
    const std::vector<std::vector<Vec2>> human = runs_of_kind(c, TraceKind::human, random);

    const CharacterScore in_order = score_trace(c, pen_trace(human));
    CHECK(in_order.strokes_written == n);
    CHECK(in_order.order_errors == 0);
    CHECK(in_order.backwards_strokes == 0);
    CHECK(in_order.completed_in_order);
    CHECK(in_order.strokes_accepted == n);
    for (std::size_t s = 0; s < n; ++s) CHECK(in_order.segments[s].matched_stroke == s);

    // The first two strokes swapped: one order error; the renderer refuses the first as out of order.
    std::vector<std::vector<Vec2>> swapped = human;
    std::swap(swapped[0], swapped[1]);
    const CharacterScore out_of_order = score_trace(c, pen_trace(swapped));
    CHECK(out_of_order.strokes_written == n);
    CHECK(out_of_order.order_errors == 1);
    CHECK_FALSE(out_of_order.strokes_in_order);
    CHECK(out_of_order.segments[0].matched_stroke == 1u);
    CHECK(out_of_order.segments[1].matched_stroke == 0u);
    REQUIRE(out_of_order.segments[0].verdict);
    CHECK(out_of_order.segments[0].verdict->refusal == StrokeRefusal::wrong_order);
    CHECK(out_of_order.segments[0].verdict->matched_stroke == 1u);
    CHECK(out_of_order.refusals.wrong_order >= 1);

    // The second stroke written from its end: matched backwards, and refused as backwards in turn.
    std::vector<std::vector<Vec2>> reversed = human;
    std::reverse(reversed[1].begin(), reversed[1].end());
    const CharacterScore backwards = score_trace(c, pen_trace(reversed));
    CHECK(backwards.strokes_written == n);
    CHECK(backwards.backwards_strokes == 1);
    CHECK(backwards.strokes[1].backwards);
    CHECK(backwards.segments[1].backwards);
    CHECK(backwards.order_errors == 0);
    REQUIRE(backwards.segments[1].verdict);
    CHECK(backwards.segments[1].verdict->refusal == StrokeRefusal::backwards);
    CHECK(backwards.refusals.backwards == 1);
    CHECK(backwards.strokes_accepted == 1);  // the renderer waits at stroke 2 for the rest of the trace
  }
}
