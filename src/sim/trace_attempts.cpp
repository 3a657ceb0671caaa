#include "calligraphy/sim/trace_attempts.hpp"

#include <algorithm>
#include <cstddef>

namespace calligraphy {

void mark_writer_attempts(std::vector<TrialSample>& trace, const WriterLog& log) {
  for (TrialSample& sample : trace) {
    sample.attempt = 0;
    sample.rewritten = false;
  }
  const std::vector<WriterAttempt>& attempts = log.attempts;
  const auto first_at = [&trace](double time_s) {
    return static_cast<std::size_t>(
        std::lower_bound(trace.begin(), trace.end(), time_s,
                         [](const TrialSample& sample, double t) { return sample.time_s < t; }) -
        trace.begin());
  };
  for (std::size_t a = 0; a < attempts.size(); ++a) {
    const WriterAttempt& attempt = attempts[a];
    const bool written_again =
        std::any_of(attempts.begin() + static_cast<std::ptrdiff_t>(a) + 1, attempts.end(),
                    [&](const WriterAttempt& later) { return later.scene_stroke == attempt.scene_stroke; });
    const std::size_t begin = first_at(attempt.start_s);
    const std::size_t end = a + 1 < attempts.size() ? first_at(attempts[a + 1].start_s) : trace.size();
    for (std::size_t i = begin; i < end && i < trace.size(); ++i) {
      trace[i].attempt = attempt.attempt;
      trace[i].rewritten = written_again;
    }
  }
}

}  // namespace calligraphy
