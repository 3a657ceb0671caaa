// TrialSession from an application's own loop, and the runner's endings: one force write per tick,
// the loop statistics kept, an interrupt, the time limit, a writer that gives up.
#include <catch2/catch.hpp>

#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "calligraphy/trial/trial.hpp"
#include "embedded_scenes.hpp"
#include "probe_device.hpp"

using namespace calligraphy;

using test::ProbeDevice;

namespace {}  // namespace

TEST_CASE("A session stepped from the application's own loop records the runner's trial", "[trial]") {
  const Scene scene = testing::embedded_scene(U'九');
  TrialOptions options;
  SimulationOptions simulation;
  simulation.seed = 3;
  const TrialResult by_runner = run_simulated_trial(scene, options, simulation);

  SimulatedDevice device(simulation.device);
  SimulatedWriter writer(scene, simulation.writer, simulation.seed);
  device.attach_hand(&writer);
  device.open();
  device.enable_forces(true);
  TrialSession session(scene, device.info(), options);
  session.reserve_trace();
  while (true) {
    DeviceState state;
    REQUIRE(device.read_state(state) == DeviceFault::none);
    const ServoCommand command = session.step(state);
    REQUIRE(device.write_force(command.force_n) == DeviceFault::none);
    if (command.stop) break;
    writer.observe(session.last_output(), state);
    if (writer.done()) break;
    device.advance(1.0 / options.rate_hz);
  }
  const TrialResult by_hand = session.finish(session.finished() ? TrialEnd::completed : TrialEnd::time_limit);
  CHECK(by_hand.end == TrialEnd::completed);
  CHECK_FALSE(by_hand.aborted);
  CHECK(by_hand.trace.size() == by_runner.trace.size());
  CHECK(by_hand.metrics.mean_deviation_m == by_runner.metrics.mean_deviation_m);
  CHECK(by_hand.metrics.time_s == by_runner.metrics.time_s);
  CHECK(by_hand.metrics.completed_in_order);
}

TEST_CASE("Every tick writes the force once, lock-step and in real time", "[trial][servo]") {
  const Scene scene = testing::embedded_scene(U'乙');
  for (const TrialPacing pacing : {TrialPacing::lock_step, TrialPacing::real_time}) {
    ProbeDevice device;
    TrialOptions options;
    options.pacing = pacing;
    options.max_duration_s = 0.3;  // a short stretch of the trial is enough
    options.loop.realtime = RealtimeMode::ignore;
    options.loop.priority = 0;
    options.loop.lock_memory = false;
    const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
    INFO("pacing " << static_cast<int>(pacing));
    CHECK(result.end == TrialEnd::time_limit);
    CHECK(result.aborted);
    CHECK(static_cast<long>(result.trace.size()) == device.reads_);
    // The runner writes once per tick and one zero force at the end (in real time the loop writes it).
    CHECK(device.writes_ == device.reads_ + 1);
    CHECK(device.last_force_.isZero());
    CHECK_FALSE(device.forces_enabled());
    CHECK(result.loop.has_value() == (pacing == TrialPacing::real_time));
    if (result.loop) CHECK(result.loop->ticks == result.trace.size());
    CHECK_FALSE(device.is_open());
  }
}

TEST_CASE("should_stop ends a trial as interrupted with the ticks kept", "[trial][servo]") {
  const Scene scene = testing::embedded_scene(U'永');
  for (const TrialPacing pacing : {TrialPacing::lock_step, TrialPacing::real_time}) {
    TrialOptions options;
    options.pacing = pacing;
    options.loop.realtime = RealtimeMode::ignore;
    options.loop.priority = 0;
    options.loop.lock_memory = false;
    // Lock-step: stopped 3 s in, while the writer presses on stroke 2 (the force is not zero); real
    // time: 0.2 s of polls.
    const long stop_after = pacing == TrialPacing::lock_step ? 3000 : 200;
    long polls = 0;
    options.should_stop = [&polls, stop_after] { return ++polls > stop_after; };
    ProbeDevice device;
    const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
    INFO("pacing " << static_cast<int>(pacing));
    CHECK(result.end == TrialEnd::interrupted);
    // Zero force commanded, forces disabled and the device closed before the result is returned.
    CHECK(device.last_force_.isZero());
    CHECK_FALSE(device.forces_enabled());
    CHECK_FALSE(device.is_open());
    CHECK(result.aborted);
    CHECK_FALSE(result.trace.empty());
    CHECK(result.metrics.strokes_completed < result.metrics.strokes_total);
    if (pacing == TrialPacing::lock_step) {
      REQUIRE(result.trace.size() == 3000);
      CHECK_FALSE(result.trace.back().force_n.isZero());  // the force the shutdown had to zero
    }
  }
}

namespace {

// A hand that stops at once without having written anything: it gave up.
class QuittingHand final : public TrialHand {
 public:
  void observe(const RenderOutput&, const DeviceState&) override {}
  [[nodiscard]] bool stopped() const noexcept override { return true; }
  void advance(double) override {}
  void release() noexcept override {}
};

}  // namespace

TEST_CASE("A writer that stops early ends the trial as writer_finished, a hand that quits as gave_up",
          "[trial]") {
  const Scene scene = testing::embedded_scene(U'口');
  TrialOptions options;
  options.rate_hz = 100.0;  // too coarse a tick for this writer: the display takes none of its strokes
  options.force.acceptance.assist_after_misses = 0;  // no stroke credited as assisted
  const TrialResult result = run_simulated_trial(scene, options);
  CHECK(result.metrics.strokes_completed == 0);
  // It gave up on each stroke in turn, moved on, and stopped having written them all.
  CHECK(result.end == TrialEnd::writer_finished);
  CHECK(std::string(to_string(result.end)) == "writer_finished");
  CHECK(result.aborted);
  // With the assisted credit (the default) the strokes it cannot write are credited, not left: no dead end.
  options.force.acceptance.assist_after_misses = StrokeAcceptance{}.assist_after_misses;
  const TrialResult assisted = run_simulated_trial(scene, options);
  CHECK(assisted.metrics.strokes_completed == 0);
  CHECK(assisted.metrics.strokes_assisted > 0);

  SimulatedDevice device;
  QuittingHand quitter;
  const TrialResult quit = run_trial(device, scene, TrialOptions{}, &quitter);
  CHECK(quit.end == TrialEnd::gave_up);
  CHECK(std::string(to_string(quit.end)) == "gave_up");
  CHECK(quit.aborted);
}

TEST_CASE("The rate is checked against the pacing", "[trial]") {
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.rate_hz = 20000.0;
  CHECK_THROWS_AS(options.validate(), InvalidArgument);
  options.pacing = TrialPacing::lock_step;
  CHECK_NOTHROW(options.validate());
  options.rate_hz = 50.0;
  CHECK_THROWS_WITH(options.validate(), Catch::Contains("TrialOptions.rate_hz"));
}
