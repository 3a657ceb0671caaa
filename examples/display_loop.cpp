// An application that owns its display: the trial runs in real time on the servo loop's thread (the
// simulated device, written by the simulated writer), and this thread is the "display". It never waits
// on the servo thread: at about 60 frames a second it copies the latest snapshot, drains the trace and
// the events, and "draws" by printing what changed (state, active stroke, results). A window would draw
// the same things (calligraphy train does).
//
// Usage: example_display_loop [CHARACTER [SEED]]   (a character of the embedded set, default 十)
#include <algorithm>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/sim/simulated_hand.hpp>
#include <calligraphy/trial/trial.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>
#include <vector>

namespace {

// The first code point of a UTF-8 string (no validation beyond the lead byte: an example).
char32_t first_code_point(const std::string& text) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text.at(i)); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return lead;
  if ((lead & 0xE0) == 0xC0) return static_cast<char32_t>(((lead & 0x1F) << 6) | (byte(1) & 0x3F));
  if ((lead & 0xF0) == 0xE0) {
    return static_cast<char32_t>(((lead & 0x0F) << 12) | ((byte(1) & 0x3F) << 6) | (byte(2) & 0x3F));
  }
  return static_cast<char32_t>(((lead & 0x07) << 18) | ((byte(1) & 0x3F) << 12) | ((byte(2) & 0x3F) << 6) |
                               (byte(3) & 0x3F));
}

}  // namespace

int main(int argc, char** argv) {
  using namespace calligraphy;
  try {
    const char32_t code_point = argc > 1 ? first_code_point(argv[1]) : U'十';
    const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(code_point)});

    DisplayChannel channel;
    TrialOptions options;
    options.pacing = TrialPacing::real_time;  // the simulated writer writes at the wall clock's pace
    options.keep_trace = true;
    // As the trainer's window does: SCHED_FIFO for the loop thread when the system allows it (a busy desktop
    // stalls a thread of normal priority for tens of ms), and no memory locking, the loop's default (an
    // application with a display maps memory all the time, which mlockall(MCL_FUTURE) would lock too); the
    // trial touches its trace in advance instead.
    options.loop.priority = kDedicatedServoPriority;
    options.display = &channel;
    TrialResult result;
    std::exception_ptr failure;
    std::thread servo_side([&] {
      try {
        SimulationOptions simulation;
        simulation.seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 0;
        result = run_trial(standard_device_registry(), "simulated", scene, options, simulation);
      } catch (...) {
        failure = std::current_exception();
        channel.push_event(
            DisplayEvent{.kind = DisplayEventKind::trial_ended, .end = TrialEnd::device_fault});
      }
    });

    // The display loop.
    DisplaySnapshot shown;
    bool ended = false;
    std::size_t frames = 0;
    std::size_t trace_points = 0;
    double latency_sum_ms = 0.0;
    double latency_max_ms = 0.0;
    std::size_t latency_count = 0;
    InteractionState last_state = InteractionState::separation;
    std::uint32_t last_stroke = 0;
    while (!ended) {
      std::this_thread::sleep_for(std::chrono::microseconds(16'667));
      ++frames;
      channel.try_latest(shown);  // keeps the last frame's snapshot when a publish overlapped every try
      if (shown.tick > 0) {
        const auto now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::steady_clock::now().time_since_epoch())
                                .count();
        const double latency_ms = static_cast<double>(now_ns - shown.published_ns) * 1e-6;
        latency_sum_ms += latency_ms;
        latency_max_ms = std::max(latency_max_ms, latency_ms);
        ++latency_count;
        if (shown.state != last_state || shown.stroke_index != last_stroke) {
          std::printf("%7.3f s  %s  stroke %u/%u  pen %+6.1f mm  |F| %.2f N\n", shown.time_s,
                      to_string(shown.state), std::min(shown.stroke_index + 1, shown.strokes_total),
                      shown.strokes_total, shown.pen_height_m * 1e3,
                      std::hypot(shown.force_n.x, shown.force_n.y, shown.force_n.z));
          last_state = shown.state;
          last_stroke = shown.stroke_index;
        }
      }
      for (TracePoint p; channel.poll_trace(p);) ++trace_points;  // a window would extend its polyline
      for (DisplayEvent e; channel.poll_event(e);) {
        switch (e.kind) {
          case DisplayEventKind::stroke_completed:
            std::printf("          stroke %u written: mean %.2f mm, max %.2f mm, %.2f s, %d attempt(s)\n",
                        e.stroke_index + 1, e.mean_deviation_m * 1e3, e.max_deviation_m * 1e3,
                        e.stroke_time_s, e.attempts);
            break;
          case DisplayEventKind::stroke_abandoned:
            std::printf("          stroke %u abandoned: its trace is cleared\n", e.stroke_index + 1);
            break;
          case DisplayEventKind::character_completed:
            std::printf("          character %u written\n", e.character + 1);
            break;
          case DisplayEventKind::trial_ended:
            std::printf("          trial ended: %s\n", to_string(e.end));
            ended = true;
            break;
          case DisplayEventKind::stroke_assisted:
            std::printf("          stroke %u shown and counted as assisted\n", e.stroke_index + 1);
            break;
        }
      }
    }
    servo_side.join();
    if (failure) std::rethrow_exception(failure);

    std::printf(
        "\n%zu frames, %zu trace points drawn (%llu dropped), display latency mean %.2f ms, max %.2f ms\n",
        frames, trace_points, static_cast<unsigned long long>(channel.dropped_trace_points()),
        latency_count ? latency_sum_ms / static_cast<double>(latency_count) : 0.0, latency_max_ms);
    if (result.loop) {
      const ServoLoopStats& loop = *result.loop;
      std::printf("servo loop: %llu ticks, %llu late, period jitter p50 %.1f us, p99 %.1f us, max %.1f us\n",
                  static_cast<unsigned long long>(loop.ticks),
                  static_cast<unsigned long long>(loop.late_ticks), loop.period_jitter_us_p50,
                  loop.period_jitter_us_p99, loop.period_jitter_us_max);
    }
    std::printf("%zu/%zu strokes in order, %s\n", result.metrics.strokes_completed,
                result.metrics.strokes_total, to_string(result.end));
    return result.metrics.completed_in_order ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "example_display_loop: %s\n", e.what());
    return 1;
  }
}
