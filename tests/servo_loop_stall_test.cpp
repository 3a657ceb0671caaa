// Late ticks and stalls in the servo loop: a force computed from a state older than max_force_age_s is
// replaced by zero force and the loop goes on; a stall longer than stall_timeout_s ends the run with zero
// force, forces off and the tripping tick counted; after a stall the deadlines restart from the present.
// The stalls are made by a callback that sleeps, so every bound below follows from the sleep's minimum
// length; nothing asserts how fast the machine is.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <limits>
#include <thread>

#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "probe_device.hpp"

using namespace calligraphy;
using Catch::Matchers::Contains;

using test::ProbeDevice;

namespace {

// As the library's tests elsewhere: best-effort realtime, no memory locking; each test sets the bounds.
ServoLoopOptions stall_test_options() {
  ServoLoopOptions o;
  o.realtime = RealtimeMode::ignore;
  o.lock_memory = false;
  return o;
}

void sleep_ms(int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }

}  // namespace

TEST_CASE("The late-tick bounds are validated by name", "[servo]") {
  SimulatedDevice device;
  const auto callback = [](const DeviceState&, double) { return ServoCommand{}; };
  const double inf = std::numeric_limits<double>::infinity();
  for (const double age : {0.0, -0.001, 1.5, inf, std::nan("")}) {
    ServoLoopOptions o = stall_test_options();
    o.max_force_age_s = age;
    CHECK_THROWS_WITH(o.validate(), Contains("max_force_age_s") && Contains("(0, 1] s"));
    CHECK_THROWS_AS(ServoLoop(device, callback, o), InvalidArgument);
  }
  for (const double timeout : {-0.05, 61.0, inf, std::nan("")}) {
    ServoLoopOptions o = stall_test_options();
    o.stall_timeout_s = timeout;
    CHECK_THROWS_WITH(o.validate(), Contains("stall_timeout_s") && Contains("[0, 60] s"));
  }
  ServoLoopOptions o = stall_test_options();
  o.stall_timeout_s = 0.0;  // no stall bound
  CHECK_NOTHROW(o.validate());
  CHECK_NOTHROW(ServoLoopOptions{}.validate());
}

TEST_CASE("A tick that overruns keeps the loop running, and its force is written only while fresh enough",
          "[servo]") {
  constexpr int kOverrunMs = 20;  // 20 periods at 1 kHz, inside the callback of tick 20
  for (const double max_force_age_s : {0.002, 1.0}) {
    INFO("max_force_age_s " << max_force_age_s);
    ProbeDevice device;
    std::uint64_t n = 0;
    double dt_after_overrun_s = 0.0;
    ServoLoopOptions o = stall_test_options();
    o.max_force_age_s = max_force_age_s;
    o.stall_timeout_s = 0.0;  // the stall bound is the next test's subject
    ServoLoop loop(
        device,
        [&](const DeviceState&, double dt_s) {
          ++n;
          if (n == 21) dt_after_overrun_s = dt_s;
          if (n == 20) {
            sleep_ms(kOverrunMs);
            return ServoCommand{Vec3(ProbeDevice::kMarker, 0, 0), false};
          }
          return ServoCommand{Vec3(0.1, 0, 0), n >= 40};
        },
        o);
    loop.start();
    loop.wait();  // no fault: the loop survived the overrun
    const ServoLoopStats s = loop.stats();
    CHECK_FALSE(s.fault);
    CHECK(s.ticks == 40);
    CHECK(n == 40);
    if (max_force_age_s < 0.02) {
      CHECK(device.marker_writes_ == 0);  // computed from a state 20 ms old: never reached the device
      CHECK(s.forces_withheld >= 1);
    } else {
      CHECK(device.marker_writes_ == 1);  // late, but within the configured age: written
    }
    CHECK(s.late_ticks >= 1);
    CHECK(s.missed_deadlines == s.late_ticks);
    // The device held tick 19's force for at least the 20 ms sleep: a stall of at least 19 ms.
    CHECK(s.longest_stall_s >= (kOverrunMs - 1) * 1e-3);
    // The deadlines restarted after the overrun: the ones that passed were dropped, not run back to back,
    // so the next tick came a whole period after the overrunning one ended.
    CHECK(s.deadline_reanchors >= 1);
    CHECK(s.skipped_periods >= kOverrunMs - 1);
    CHECK(dt_after_overrun_s >= (kOverrunMs + 1) * 1e-3);
    CHECK(device.inner_.applied_force() == Vec3::Zero());
    CHECK_FALSE(device.forces_enabled());
  }
}

TEST_CASE("A stall longer than stall_timeout_s ends the run safely and the tripping tick is counted",
          "[servo]") {
  ProbeDevice device;
  std::uint64_t n = 0;
  ServoLoopOptions o = stall_test_options();
  o.stall_timeout_s = 0.080;
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) {
        if (++n == 20) {
          sleep_ms(200);
          return ServoCommand{Vec3(ProbeDevice::kMarker, 0, 0), false};
        }
        return ServoCommand{Vec3(0.1, 0, 0), n >= 400};
      },
      o);
  loop.start();
  CHECK_THROWS_AS(loop.wait(), SafetyFault);
  const ServoLoopStats s = loop.stats();
  CHECK(s.fault.kind == LoopFaultKind::watchdog);
  CHECK(s.fault.message == kStallFaultMessage);
  CHECK(n == 20);
  CHECK(s.ticks == 20);  // the tripping tick is in the statistics
  CHECK(s.late_ticks >= 1);
  CHECK(s.longest_stall_s >= 0.199);
  CHECK(s.forces_withheld >= 1);
  CHECK(device.marker_writes_ == 0);
  CHECK(device.inner_.applied_force() == Vec3::Zero());
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(loop.running());
  CHECK(loop.stop().kind == LoopFaultKind::watchdog);  // stop() reports it without throwing
  // The loop can run again after a stall fault; the statistics start over.
  n = 100;
  loop.start();
  loop.wait();
  const ServoLoopStats again = loop.stats();
  CHECK_FALSE(again.fault);
  CHECK(again.ticks == 300);
  CHECK(again.longest_stall_s <= o.stall_timeout_s);  // a run that did not trip: the 200 ms are forgotten
}

TEST_CASE("A real-time trial ended by a stall keeps every tick recorded, the tripping tick included",
          "[servo]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'口')});
  ProbeDevice device;
  device.stall_at(100, 250);  // the physics step after tick 100 takes 250 ms
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.loop = stall_test_options();
  options.loop.stall_timeout_s = 0.1;
  options.max_duration_s = 2.0;
  const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
  CHECK(result.end == TrialEnd::watchdog);
  CHECK(result.aborted);
  CHECK(device.advances_ == 100);
  REQUIRE(result.loop.has_value());
  CHECK(result.loop->fault.kind == LoopFaultKind::watchdog);
  CHECK(result.trace.size() == 101);  // the tick after the stall tripped the bound and was recorded
  CHECK(result.loop->ticks == result.trace.size());
  CHECK(result.loop->longest_stall_s >= 0.249);
  CHECK_FALSE(device.forces_enabled());
}
