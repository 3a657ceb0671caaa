// The servo-to-display channel: the seqlock never hands out a torn value while another thread writes,
// the SPSC queue keeps order and counts what it refuses, and a trial publishes what the display needs
// (snapshots, trace, the stroke and trial events), also while a display thread reads concurrently.
#include "calligraphy/trial/display.hpp"

#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <thread>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"
#include "embedded_scenes.hpp"

using namespace calligraphy;

namespace {

// Every field derived from one counter, so a torn copy shows as fields that disagree.
struct Stamped {
  std::uint64_t words[24];
  double value;
};

Stamped stamped(std::uint64_t n) {
  Stamped s{};
  for (auto& w : s.words) w = n * 0x9E3779B97F4A7C15ULL;
  s.value = static_cast<double>(n);
  return s;
}

bool consistent(const Stamped& s) {
  for (const auto& w : s.words) {
    if (w != s.words[0]) return false;
  }
  return s.words[0] == static_cast<std::uint64_t>(s.value) * 0x9E3779B97F4A7C15ULL;
}

// The invariants a snapshot of `scene` holds when it was published whole by one tick.
bool snapshot_consistent(const DisplaySnapshot& s, const Scene& scene) {
  const double paper_z = scene.layout.paper_z_m;
  if (s.vtp_m.x != s.hip_m.x || s.vtp_m.y != s.hip_m.y) return false;
  if (s.vtp_m.z != std::max(s.hip_m.z, paper_z)) return false;
  if (s.pen_height_m != s.hip_m.z - paper_z) return false;
  if (s.finished || s.tick == 0) return true;
  const PlacedStroke& stroke = scene.characters.at(s.character).strokes.at(s.stroke);
  return s.hint_m.x == stroke.start().x() && s.hint_m.y == stroke.start().y();
}

}  // namespace

TEST_CASE("A seqlock read while another thread writes is never torn and never goes back", "[display]") {
  Seqlock<Stamped> lock;
  REQUIRE(lock.version() == 0);
  constexpr std::uint64_t kWrites = 200'000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 1; n <= kWrites; ++n) lock.store(stamped(n));
    done.store(true);
  });
  std::uint64_t reads = 0;
  std::uint64_t torn = 0;
  std::uint64_t backwards = 0;
  std::uint64_t last = 0;
  Stamped s{};
  while (!done.load() || reads < 1000) {
    if (!lock.try_load(s, 8)) continue;
    ++reads;
    if (!consistent(s)) ++torn;
    const auto n = static_cast<std::uint64_t>(s.value);
    if (n < last) ++backwards;
    last = n;
  }
  writer.join();
  INFO("reads " << reads);
  CHECK(torn == 0);
  CHECK(backwards == 0);
  CHECK(lock.load().value == static_cast<double>(kWrites));
  CHECK(lock.version() == kWrites);
}

TEST_CASE("The SPSC queue hands every value over in order across threads", "[display]") {
  SpscQueue<std::uint64_t> queue(64);
  REQUIRE(queue.capacity() == 64);
  constexpr std::uint64_t kValues = 500'000;
  std::thread producer([&] {
    for (std::uint64_t n = 1; n <= kValues; ++n) {
      while (!queue.try_push(n)) std::this_thread::yield();
    }
  });
  std::uint64_t expected = 1;
  std::uint64_t out_of_order = 0;
  std::uint64_t value = 0;
  while (expected <= kValues) {
    if (!queue.try_pop(value)) continue;
    if (value != expected) ++out_of_order;
    expected = value + 1;
  }
  producer.join();
  CHECK(out_of_order == 0);
  CHECK_FALSE(queue.try_pop(value));
  // The retries above were counted as drops: a full queue refuses, it does not block.
  const std::uint64_t refused_before = queue.dropped();
  for (std::uint64_t n = 0; n < 64; ++n) REQUIRE(queue.try_push(n));
  CHECK_FALSE(queue.try_push(99));
  CHECK(queue.dropped() == refused_before + 1);
  CHECK(queue.size() == 64);
}

TEST_CASE("Display channel options out of range are refused by name", "[display]") {
  DisplayChannelOptions options;
  options.trace_every_ticks = 0;
  CHECK_THROWS_WITH(DisplayChannel(options), Catch::Contains("trace_every_ticks"));
  options = {};
  options.event_capacity = 0;
  CHECK_THROWS_AS(DisplayChannel(options), InvalidArgument);
  CHECK_THROWS_AS(SpscQueue<int>(0), InvalidArgument);
}

TEST_CASE("A lock-step trial publishes each tick, its trace, and its stroke events in order", "[display]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"十人");
  DisplayChannelOptions channel_options;
  channel_options.trace_capacity = std::size_t{1} << 20;
  DisplayChannel channel(channel_options);
  TrialOptions options;
  options.display = &channel;
  SimulationOptions simulation;
  simulation.seed = 5;
  const TrialResult result = run_simulated_trial(scene, options, simulation);
  REQUIRE(result.end == TrialEnd::completed);
  const std::size_t ticks = result.trace.size();

  const DisplaySnapshot last = channel.latest();
  CHECK(last.tick == ticks);
  CHECK(last.finished);
  CHECK(last.strokes_completed == scene.stroke_count());
  CHECK(last.strokes_total == scene.stroke_count());
  CHECK(last.time_s == result.trace.back().time_s);
  CHECK(snapshot_consistent(last, scene));
  CHECK(channel.publications() == ticks + 1);  // every tick, and once more at the end

  std::uint64_t trace_points = 0;
  std::uint64_t mismatches = 0;
  for (TracePoint p; channel.poll_trace(p); ++trace_points) {
    const TrialSample& sample = result.trace.at(p.tick - 1);
    if (p.hip_m.x != sample.position_m.x() || p.hip_m.z != sample.position_m.z() || p.state != sample.state ||
        p.stroke_index != sample.stroke) {
      ++mismatches;
    }
  }
  CHECK(trace_points == ticks);
  CHECK(mismatches == 0);
  CHECK(channel.dropped_trace_points() == 0);

  std::vector<DisplayEvent> events;
  for (DisplayEvent e; channel.poll_event(e);) events.push_back(e);
  std::vector<DisplayEvent> completed;
  std::vector<DisplayEvent> characters;
  for (const DisplayEvent& e : events) {
    if (e.kind == DisplayEventKind::stroke_completed) completed.push_back(e);
    if (e.kind == DisplayEventKind::character_completed) characters.push_back(e);
  }
  REQUIRE(completed.size() == scene.stroke_count());
  for (std::size_t i = 0; i < completed.size(); ++i) {
    const StrokeMetrics& m = result.metrics.per_stroke[i];
    CHECK(completed[i].stroke_index == i);
    CHECK(completed[i].character == m.character);
    CHECK(completed[i].strokes_completed == i + 1);
    CHECK(completed[i].mean_deviation_m == m.mean_deviation_m);
    CHECK(completed[i].max_deviation_m == m.max_deviation_m);
    CHECK(completed[i].attempts == m.attempts);
    CHECK(completed[i].refusal == StrokeRefusal::none);
  }
  REQUIRE(characters.size() == 2);
  CHECK(characters[0].character == 0);
  CHECK(characters[0].stroke + 1 == scene.characters[0].strokes.size());
  CHECK(characters[1].character == 1);
  REQUIRE_FALSE(events.empty());
  CHECK(events.back().kind == DisplayEventKind::trial_ended);
  CHECK(events.back().end == TrialEnd::completed);
}

TEST_CASE("Lifting the pen while writing publishes the abandoned stroke and why", "[display]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"十");
  DisplayChannel channel;
  TrialSession session(scene, simulated_phantom_desktop_info(), TrialOptions{});
  session.attach_display(&channel);
  const Vec2 start = scene.characters[0].strokes[0].start();
  const Vec2 end = scene.characters[0].strokes[0].end();
  DeviceState state;
  double t = 0.0;
  const auto at = [&](const Vec2& p, double z) {
    state.position_m = Vec3(p.x(), p.y(), z);
    state.time_s = (t += 1e-3);
    (void)session.step(state);
  };
  for (int i = 0; i < 20; ++i) at(start, 0.01);    // above the paper: SS
  for (int i = 0; i < 20; ++i) at(start, -0.002);  // down at the start: WS
  CHECK(channel.latest().state == InteractionState::writing);
  for (int i = 0; i < 20; ++i) at(start + 0.3 * (i / 19.0) * (end - start), -0.002);  // a third along
  for (int i = 0; i < 20; ++i) at(start + 0.3 * (end - start), 0.01);                 // lifted: abandoned
  const DisplaySnapshot lifted = channel.latest();
  CHECK(lifted.state == InteractionState::separation);
  CHECK(lifted.pen_height_m == Approx(0.01));
  CHECK(lifted.strokes_completed == 0);
  std::vector<DisplayEvent> events;
  for (DisplayEvent e; channel.poll_event(e);) events.push_back(e);
  REQUIRE(events.size() == 1);
  CHECK(events[0].kind == DisplayEventKind::stroke_abandoned);
  CHECK(events[0].stroke_index == 0);
  CHECK(events[0].tick == 61);
  CHECK(events[0].refusal == StrokeRefusal::too_short);  // the renderer's reason, for the learner

  session.attach_display(nullptr);  // detached: nothing more is published
  at(start, 0.01);
  CHECK(channel.latest().tick == 80);
  const TrialResult result = session.finish(TrialEnd::interrupted);
  DisplayEvent e;
  CHECK_FALSE(channel.poll_event(e));
  CHECK(result.trace.size() == 81);
}

TEST_CASE("A display thread reads a real-time trial while it runs and sees whole snapshots", "[display]") {
  const Scene scene = calligraphy::testing::scene_of_text(U"人");
  DisplayChannel channel;
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.loop.lock_memory = false;
  options.loop.priority = 0;
  // Without real-time rights on a machine busy with other tests a tick can wait past the 50 ms watchdog:
  // what is tested here is the display's view of the trial, so the trial must not end on a stall.
  options.loop.stall_timeout_s = 0.0;
  options.display = &channel;
  SimulationOptions simulation;
  simulation.seed = 2;
  std::atomic<bool> trial_done{false};
  TrialResult result;
  std::thread trial([&] {
    result = run_simulated_trial(scene, options, simulation);
    trial_done.store(true);
  });
  std::uint64_t reads = 0;
  std::uint64_t inconsistent = 0;
  std::uint64_t backwards = 0;
  std::uint64_t last_tick = 0;
  std::uint64_t trace_points = 0;
  std::uint64_t last_trace_tick = 0;
  std::uint64_t trace_backwards = 0;
  std::vector<DisplayEvent> events;
  bool ended = false;
  while (!ended) {
    DisplaySnapshot s;
    if (channel.try_latest(s)) {
      ++reads;
      if (!snapshot_consistent(s, scene)) ++inconsistent;
      if (s.tick < last_tick) ++backwards;
      last_tick = s.tick;
    }
    for (TracePoint p; channel.poll_trace(p); ++trace_points) {
      if (p.tick <= last_trace_tick) ++trace_backwards;
      last_trace_tick = p.tick;
    }
    for (DisplayEvent e; channel.poll_event(e);) {
      events.push_back(e);
      ended = ended || e.kind == DisplayEventKind::trial_ended;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  trial.join();
  REQUIRE(trial_done.load());
  INFO("reads " << reads << ", ticks " << result.trace.size());
  CHECK(result.end == TrialEnd::completed);
  CHECK(reads > 10);
  CHECK(inconsistent == 0);
  CHECK(backwards == 0);
  CHECK(trace_backwards == 0);
  CHECK(trace_points + channel.dropped_trace_points() == result.trace.size());
  std::size_t strokes = 0;
  for (const DisplayEvent& e : events) strokes += e.kind == DisplayEventKind::stroke_completed ? 1 : 0;
  CHECK(strokes == scene.stroke_count());
  CHECK(events.back().end == TrialEnd::completed);
}
