// The servo loop thread must not allocate while it runs a renderer (an allocation can block for longer
// than a servo period). Counts calls of malloc made by a thread that has asked to be watched: malloc
// is interposed for this test binary and forwards to glibc's __libc_malloc (operator new, replaced in
// nearest_point_allocation_test.cpp, calls malloc). Sanitizers own malloc, so their builds leave this
// test out.
#include <catch2/catch.hpp>

#if !defined(CALLIGRAPHY_TEST_SANITIZED) && defined(__GLIBC__)
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <thread>
#include <vector>

#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"
#include "probe_device.hpp"

namespace {
thread_local bool watched = false;  // set by a thread to have its own allocations counted
std::atomic<long> watched_allocations{0};
}  // namespace

extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (watched) watched_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}

namespace {
// A hand that needs no memory: a spring to a target that presses into the paper and sweeps across the
// character, so the renderer goes through its states.
class SweepingHand final : public calligraphy::HandModel {
 public:
  calligraphy::Vec3 hand_force(double t, const calligraphy::Vec3& x, const calligraphy::Vec3& v) override {
    const calligraphy::Vec3 target(0.02 * std::sin(2.0 * std::numbers::pi * 1.5 * t),
                                   0.01 * std::cos(3.0 * t), -0.004);
    return 200.0 * (target - x) - 3.0 * v;  // [N/m], [N s/m]
  }
};
}  // namespace

TEST_CASE("The servo loop thread does not allocate while it renders and records", "[servo]") {
  using namespace calligraphy;
  {  // the counter sees a watched allocation (so the check below can fail)
    const long before = watched_allocations.load();
    watched = true;
    std::vector<int>* v = new std::vector<int>(100);
    watched = false;
    delete v;
    REQUIRE(watched_allocations.load() > before);
  }
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'口')});
  SimulatedDevice device;
  SweepingHand hand;
  device.attach_hand(&hand);
  device.open();
  Renderer renderer(scene, ForceLawParameters{}, device.info());
  TrialRecorder recorder(scene, /*keep_trace=*/false);
  std::size_t transitions = 0;
  ServoLoopOptions options;
  options.lock_memory = false;
  options.priority = kDedicatedServoPriority;  // best-effort SCHED_FIFO: steady counts on a busy machine
  options.stall_timeout_s = 0.0;
  ServoLoop loop(
      device,
      [&](const DeviceState& state, double) {
        watched = true;  // from the first tick on, everything this thread does is counted
        const RenderOutput out = renderer.tick(state);
        recorder.record(state, out);
        transitions += out.state_changed ? 1 : 0;
        if (device.write_force(out.force_n) != DeviceFault::none) return ServoCommand{Vec3::Zero(), true};
        device.advance(1e-3);
        return ServoCommand{out.force_n, false};
      },
      options);
  const long before = watched_allocations.load();
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  loop.stop();
  INFO("transitions " << transitions << ", ticks " << loop.stats().ticks);
  CHECK(loop.stats().ticks > 200);
  CHECK_FALSE(loop.stats().fault);
  CHECK(transitions > 0);
  CHECK(watched_allocations.load() == before);
}

TEST_CASE("A device fault ends the loop without an allocation on the servo thread", "[servo]") {
  // The fault is a code from read_state: the loop records it (code and fixed message), zeroes the force,
  // disables forces and ends, all without allocating or building a string; the typed exception is made
  // only by wait(), on this thread.
  using namespace calligraphy;
  for (const DeviceFault fault : {DeviceFault::link_lost, DeviceFault::watchdog}) {
    test::ProbeDevice device(/*fail_on_read=*/300, fault);
    ServoLoopOptions options;
    options.lock_memory = false;
    options.priority = kDedicatedServoPriority;  // best-effort SCHED_FIFO: steady counts on a busy machine
    options.stall_timeout_s = 0.0;
    options.max_force_age_s = 1.0;
    ServoLoop loop(
        device,
        [&](const DeviceState& state, double) {
          watched = true;  // from the first tick on, everything this thread does is counted
          return ServoCommand{Vec3(0.1 * state.position_m.x(), 0.0, 0.0), false};
        },
        options);
    const long before = watched_allocations.load();
    loop.start();
    if (fault == DeviceFault::link_lost) {
      CHECK_THROWS_AS(loop.wait(), CommunicationError);
    } else {
      CHECK_THROWS_AS(loop.wait(), SafetyFault);
    }
    CHECK(loop.stats().ticks == 300);
    CHECK(loop.stats().fault.device == fault);
    CHECK(watched_allocations.load() == before);
    CHECK(device.inner_.applied_force() == Vec3::Zero());
  }
}

TEST_CASE("A trial session publishing to a display does not allocate on the servo thread",
          "[servo][display]") {
  using namespace calligraphy;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'口')});
  SimulatedDevice device;
  SweepingHand hand;
  device.attach_hand(&hand);
  device.open();
  DisplayChannel channel;
  TrialOptions trial_options;
  trial_options.max_duration_s = 2.0;
  trial_options.display = &channel;
  TrialSession session(scene, device.info(), trial_options);
  session.reserve_trace();
  ServoLoopOptions options;
  options.lock_memory = false;
  options.priority = kDedicatedServoPriority;  // best-effort SCHED_FIFO: steady counts on a busy machine
  options.stall_timeout_s = 0.0;
  ServoLoop loop(
      device,
      [&](const DeviceState& state, double) {
        watched = true;
        const ServoCommand command = session.step(state);
        if (device.write_force(command.force_n) != DeviceFault::none) return ServoCommand{Vec3::Zero(), true};
        device.advance(1e-3);
        return command;
      },
      options);
  const long before = watched_allocations.load();
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  loop.stop();
  INFO("ticks " << loop.stats().ticks);
  CHECK(loop.stats().ticks > 200);
  CHECK(channel.latest().tick == session.ticks());
  CHECK(watched_allocations.load() == before);
}
#endif
