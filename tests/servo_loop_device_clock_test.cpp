// The servo loop on a device's own servo clock (device_servo_clock.hpp): each tick runs inside the
// driver's frame, so the force answers the position of that frame; stop, faults and a driver that stops
// calling end the run with zero force; a trial's times start at 0 whatever the device's clock says.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/trial/runner.hpp"
#include "clocked_device.hpp"

using namespace calligraphy;
using test::ClockedDevice;

namespace {

ServoLoopOptions clock_options() {
  ServoLoopOptions o;
  o.realtime = RealtimeMode::ignore;
  o.lock_memory = false;
  o.priority = kDedicatedServoPriority;  // best-effort SCHED_FIFO: steady counts on a busy machine
  o.stall_timeout_s = 0.0;
  o.max_force_age_s = 1.0;
  return o;
}

constexpr double kStiffness = 300.0;  // N/m: the callback's spring towards x = 0

ServoCommand spring(const DeviceState& state, double) {
  return ServoCommand{Vec3(-kStiffness * state.position_m.x(), 0.0, 0.0), false};
}

}  // namespace

TEST_CASE("On a device's servo clock the force answers the position of the same frame", "[servo]") {
  ClockedDevice device;
  device.open();
  ServoLoop loop(device, spring, clock_options());
  loop.start();
  CHECK(loop.stats().realtime.device_clock);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const LoopFault fault = loop.stop();
  CHECK_FALSE(fault);
  CHECK_FALSE(device.forces_enabled());
  const long frames = device.frames();
  device.close();
  // Every frame that ran a tick sent -k x of its own position: the square wave's steps (every 7 frames)
  // show up in the force in the frame they happen, never one or two frames later.
  long ticked = 0, steps = 0, same_frame = 0, late = 0;
  const auto& log = device.log();
  for (long i = 1; i < std::min<long>(frames, static_cast<long>(log.size())); ++i) {
    const auto& f = log[static_cast<std::size_t>(i)];
    if (!f.force_set) continue;
    ++ticked;
    if (f.position_x_m != log[static_cast<std::size_t>(i - 1)].position_x_m) {
      ++steps;
      if (f.force_x_n == Approx(-kStiffness * f.position_x_m).margin(1e-12)) ++same_frame;
      const double before = log[static_cast<std::size_t>(i - 1)].position_x_m;
      if (f.force_x_n != 0.0 && f.force_x_n == Approx(-kStiffness * before).margin(1e-12)) ++late;
    }
  }
  INFO("frames " << frames << ", ticked " << ticked << ", steps " << steps << ", late " << late);
  CHECK(ticked > 100);
  CHECK(steps > 10);
  CHECK(same_frame >= steps - 1);  // the frame that ended the run sent zero, whatever its position
  CHECK(late == 0);                // no step answered with the previous frame's position
  CHECK(loop.stats().ticks >= static_cast<std::uint64_t>(ticked - 1));
}

TEST_CASE("On a device's servo clock the callback, a stop and a device fault end the run with zero force",
          "[servo]") {
  SECTION("the callback asks to stop") {
    ClockedDevice device;
    device.open();
    std::uint64_t n = 0;
    ServoLoop loop(
        device,
        [&](const DeviceState&, double) {
          return ServoCommand{Vec3(0.2, 0, 0), ++n % 25 == 0};
        },
        clock_options());
    loop.start();
    loop.wait();
    CHECK(loop.stats().ticks == 25);
    CHECK_FALSE(loop.running());
    CHECK_FALSE(device.forces_enabled());
    loop.start();  // a run that ended can start again
    loop.wait();
    CHECK(n == 50);
  }
  SECTION("a link lost in a frame") {
    ClockedDevice device;
    device.open();
    device.fail_at_frame(device.frames() + 40);
    ServoLoop loop(device, spring, clock_options());
    loop.start();
    CHECK_THROWS_AS(loop.wait(), CommunicationError);
    const ServoLoopStats s = loop.stats();
    CHECK(s.fault.kind == LoopFaultKind::device);
    CHECK(s.fault.device == DeviceFault::link_lost);
    CHECK_FALSE(device.forces_enabled());
  }
  SECTION("a rate that is not the device's") {
    ClockedDevice device(500.0);
    device.open();
    ServoLoop loop(device, spring, clock_options());  // 1000 Hz
    CHECK_THROWS_WITH(loop.start(), Catch::Contains("500") && Catch::Contains("1000"));
    CHECK_FALSE(device.forces_enabled());
  }
}

TEST_CASE("A driver that stops calling ends the run as a stall once the silence passes the bound",
          "[servo]") {
  ClockedDevice device;
  device.open();
  ServoLoopOptions options = clock_options();
  options.stall_timeout_s = 0.05;
  ServoLoop loop(device, spring, options);
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  device.pause(true);
  const auto paused_at = std::chrono::steady_clock::now();
  while (loop.running() && std::chrono::steady_clock::now() - paused_at < std::chrono::seconds(5))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  CHECK_FALSE(loop.running());
  const LoopFault fault = loop.stop();
  CHECK(fault.kind == LoopFaultKind::watchdog);
  CHECK_FALSE(device.forces_enabled());
  device.pause(false);
}

TEST_CASE("A trial on a device whose clock starts elsewhere counts its times from its first tick",
          "[servo]") {
  ClockedDevice device;  // its time stamps start at 5000 s
  device.open();
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.max_duration_s = 0.2;
  options.loop.lock_memory = false;
  const TrialResult result = run_trial(device, scene, options);
  REQUIRE(result.trace.size() > 50);
  CHECK(result.trace.front().time_s == 0.0);
  CHECK(result.trace.back().time_s == Approx(0.2).margin(0.02));
  CHECK(result.metrics.time_s < 1.0);
  CHECK(result.device_time_at_start_s >= 5000.0);
  REQUIRE(result.loop);
  CHECK(result.loop->realtime.device_clock);
}
