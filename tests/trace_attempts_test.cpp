// A simulated writer's attempts marked in its trace (trace_attempts.hpp): an attempt the writer made again
// at the same stroke is marked rewritten from its start to the next attempt's; its final attempts are not.
#include "calligraphy/sim/trace_attempts.hpp"

#include <catch2/catch.hpp>
#include <vector>

using namespace calligraphy;

TEST_CASE("attempts written again are marked rewritten in the trace, the final ones are not",
          "[sim][trace]") {
  std::vector<TrialSample> trace(100);
  for (std::size_t i = 0; i < trace.size(); ++i) {
    trace[i].time_s = 0.01 * static_cast<double>(i);
    trace[i].attempt = 7;  // the renderer's marks, replaced
    trace[i].rewritten = true;
  }
  WriterLog log;
  const auto attempt = [&log](std::size_t stroke, int number, double start_s) {
    WriterAttempt a;
    a.scene_stroke = stroke;
    a.attempt = number;
    a.start_s = start_s;
    log.attempts.push_back(a);
  };
  attempt(0, 1, 0.10);  // stroke 0 backwards, not taken
  attempt(0, 2, 0.30);  // stroke 0 again: its final writing
  attempt(1, 1, 0.60);  // stroke 1, once
  mark_writer_attempts(trace, log);
  CHECK(trace[5].attempt == 0);  // before the first attempt
  CHECK_FALSE(trace[5].rewritten);
  CHECK(trace[10].attempt == 1);
  CHECK(trace[29].rewritten);
  CHECK(trace[30].attempt == 2);
  CHECK_FALSE(trace[30].rewritten);
  CHECK(trace[60].attempt == 1);
  CHECK_FALSE(trace[99].rewritten);
  std::size_t rewritten = 0;
  for (const TrialSample& s : trace) rewritten += s.rewritten ? 1 : 0;
  CHECK(rewritten == 20);  // 0.10 s to 0.30 s at 0.01 s
}
