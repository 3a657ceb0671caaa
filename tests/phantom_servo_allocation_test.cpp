// The Phantom backend's servo path (read_state and write_force, and under them the packet codec and the
// transport) must not allocate, also when it fails: a fault is a code with a fixed message, its detail a
// plain record. Runs the registry's emulated Phantom (calligraphy/testing/emulated_phantom.hpp: the real
// PhantomDevice over the in-memory link to the emulator) for many ticks with bad packets, a clamped
// force, a NaN force, the host watchdog, a stream of bad packets and an unplug injected, and counts the
// calls of malloc, calloc and realloc this thread makes while it is watched (interposed for this test
// program, forwarding to glibc; operator new calls malloc). Sanitizers own malloc, so their builds leave
// this test out.
#include <catch2/catch.hpp>

#if !defined(CALLIGRAPHY_TEST_SANITIZED) && defined(__GLIBC__)
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <vector>

#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "testing/phantom_emulator.hpp"

namespace {
thread_local bool watched = false;  // set by a thread to have its own allocations counted
std::atomic<long> watched_allocations{0};
}  // namespace

extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* __libc_calloc(std::size_t count, std::size_t size);
extern "C" void* __libc_realloc(void* memory, std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (watched) watched_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
extern "C" void* calloc(std::size_t count, std::size_t size) {
  if (watched) watched_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
extern "C" void* realloc(void* memory, std::size_t size) {
  if (watched) watched_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(memory, size);
}

namespace {

using calligraphy::DeviceFault;
using calligraphy::DeviceState;
using calligraphy::HapticDevice;
using calligraphy::Vec3;
using calligraphy::phantom::EmulatedPhantomDevice;

// The servo-path calls, watched. Nothing else runs while `watched` is set (Catch's macros allocate).
DeviceFault watched_read(HapticDevice& device, DeviceState& state) {
  watched = true;
  const DeviceFault fault = device.read_state(state);
  watched = false;
  return fault;
}
DeviceFault watched_write(HapticDevice& device, const Vec3& force_n) {
  watched = true;
  const DeviceFault fault = device.write_force(force_n);
  watched = false;
  return fault;
}

// The registry's emulated Phantom (powered on docked, homed by open(), undocked after 50 ms), and the
// emulator behind it, through which the faults are injected.
struct Rig {
  std::unique_ptr<HapticDevice> device = calligraphy::testing::make_emulated_phantom();
  EmulatedPhantomDevice& emulated = dynamic_cast<EmulatedPhantomDevice&>(*device);
  calligraphy::phantom::PhantomEmulator& emulator = emulated.emulator();
};

// A spring towards `target` [m] with some damping: forces that move the arm, as a renderer's would.
Vec3 spring(const DeviceState& state, const Vec3& target) {
  return 150.0 * (target - state.position_m) - 1.5 * state.velocity_m_s;
}

}  // namespace

TEST_CASE("The Phantom's servo path does not allocate, also when a fault is injected",
          "[phantom][device][allocation]") {
  {  // the counter sees a watched allocation (so the checks below can fail)
    const long before = watched_allocations.load();
    watched = true;
    auto* v = new std::vector<int>(100);
    watched = false;
    delete v;
    REQUIRE(watched_allocations.load() > before);
  }
  Rig rig;
  HapticDevice& device = *rig.device;
  device.open();  // off the servo path: logs, may allocate
  REQUIRE(device.is_calibrated());
  device.enable_forces(true);
  const auto& phantom = rig.emulated.phantom();
  const long before = watched_allocations.load();
  std::array<long, calligraphy::kDeviceFaultCount> read_faults{};
  std::array<long, calligraphy::kDeviceFaultCount> write_faults{};
  const auto tally = [](std::array<long, calligraphy::kDeviceFaultCount>& counts, DeviceFault fault) {
    ++counts[static_cast<std::size_t>(fault)];
  };

  // 1. 5 s of ticks under a spring, with the hand pushing, and every kind of bad packet the emulator
  // sends now and then: counted and survived (the last good state is returned), never a fault.
  DeviceState state;
  REQUIRE(watched_read(device, state) == DeviceFault::none);
  const Vec3 target = state.position_m + Vec3(0.01, 0.0, 0.02);
  rig.emulator.set_external_torque(calligraphy::phantom::JointTorques(0.005, 0.0, 0.0));
  for (int tick = 0; tick < 5000; ++tick) {
    switch (tick % 500) {
      case 100:
        rig.emulator.send_malformed_packets(3);
        break;
      case 200:
        rig.emulator.send_short_packets(2);
        break;
      case 300:
        rig.emulator.send_long_packets(1);
        break;
      case 400:
        rig.emulator.stay_silent(2);
        break;
      default:
        break;
    }
    tally(read_faults, watched_read(device, state));
    tally(write_faults, watched_write(device, tick % 1000 == 999 ? Vec3(20.0, 0.0, -20.0)  // clamped
                                                                 : spring(state, target)));
  }
  CHECK(watched_allocations.load() == before);
  CHECK(read_faults[0] == 5000);  // every tick's read and write: none
  CHECK(write_faults[0] == 5000);
  CHECK(phantom.packet_errors().rejected() == 10 * 6);
  CHECK(phantom.packet_errors().timeouts == 10 * 2);
  CHECK(phantom.safety_events().clamped_commands >= 5);
  CHECK(rig.emulator.forces_active());

  // 2. A NaN force: non_finite_force, zero force sent, forces off; the device stays open.
  REQUIRE(watched_read(device, state) == DeviceFault::none);
  CHECK(watched_write(device, Vec3(0.0, std::nan(""), 0.0)) == DeviceFault::non_finite_force);
  CHECK_FALSE(device.forces_enabled());
  CHECK_FALSE(rig.emulator.forces_active());
  CHECK(device.is_open());
  CHECK(phantom.last_fault().fault == DeviceFault::non_finite_force);

  // 3. The host watchdog: forces on (enable_forces is off the servo path), one force, then reads only:
  // `watchdog` once its 50 ms are over, forces off.
  device.enable_forces(true);
  REQUIRE(watched_read(device, state) == DeviceFault::none);
  REQUIRE(watched_write(device, spring(state, target)) == DeviceFault::none);
  DeviceFault fault = DeviceFault::none;
  int reads = 0;
  while (fault == DeviceFault::none && reads < 200) {
    fault = watched_read(device, state);
    ++reads;
  }
  CHECK(fault == DeviceFault::watchdog);
  CHECK(reads > 45);
  CHECK(reads < 60);
  CHECK_FALSE(device.forces_enabled());
  CHECK(phantom.safety_events().watchdog_trips == 1);
  CHECK(device.is_open());

  // 4. A stream of bad packets: `no_valid_status` after 50 in a row, forces off, the device closed; then
  // `not_open` for reads and writes.
  device.enable_forces(true);
  rig.emulator.send_malformed_packets(50);  // exactly the limit: the emulator is clean again for step 5
  fault = DeviceFault::none;
  reads = 0;
  while (fault == DeviceFault::none && reads < 200) {
    fault = watched_read(device, state);
    if (fault == DeviceFault::none) fault = watched_write(device, Vec3(0.0, 0.0, 0.5));
    ++reads;
  }
  CHECK(fault == DeviceFault::no_valid_status);
  CHECK(reads == 50);
  CHECK(phantom.last_fault().bad_reads == 50);
  CHECK(phantom.last_fault().last_packet_error == calligraphy::phantom::PacketError::bad_potentiometer);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(rig.emulator.forces_active());
  CHECK(watched_read(device, state) == DeviceFault::not_open);
  CHECK(watched_write(device, Vec3::Zero()) == DeviceFault::not_open);

  // 5. Open again (off the servo path), write for a while, then unplug: `link_lost`, then `not_open`.
  device.open();
  device.enable_forces(true);
  for (int tick = 0; tick < 500; ++tick) {
    tally(read_faults, watched_read(device, state));
    tally(write_faults, watched_write(device, spring(state, target)));
  }
  CHECK(read_faults[0] == 5000 + 500);
  CHECK(write_faults[0] == 5000 + 500);
  rig.emulator.disconnect();
  CHECK(watched_read(device, state) == DeviceFault::link_lost);
  CHECK(watched_write(device, Vec3::Zero()) == DeviceFault::not_open);
  CHECK_FALSE(device.is_open());
  CHECK_FALSE(device.forces_enabled());
  CHECK(rig.emulator.motor_torques().isZero());
  CHECK(phantom.last_fault().fault == DeviceFault::not_open);

  CHECK(watched_allocations.load() == before);
  // Off the servo path the code becomes the typed exception (the one mapping), with its message.
  CHECK_THROWS_AS(calligraphy::throw_device_fault(DeviceFault::link_lost, device.info().model),
                  calligraphy::CommunicationError);
  device.close();
}

TEST_CASE("A servo loop on the emulated Phantom stops on an unplug without allocating on its thread",
          "[phantom][servo][allocation]") {
  using namespace calligraphy;
  Rig rig;
  rig.device->open();
  DeviceState first;
  REQUIRE(rig.device->read_state(first) == DeviceFault::none);
  const Vec3 target = first.position_m + Vec3(0.0, 0.0, 0.02);
  ServoLoopOptions options;
  options.lock_memory = false;
  options.priority = kDedicatedServoPriority;  // best-effort SCHED_FIFO: steady counts on a busy machine
  options.stall_timeout_s = 0.0;
  options.max_force_age_s = 1.0;
  long ticks = 0;
  ServoLoop loop(
      *rig.device,
      [&](const DeviceState& state, double) {
        watched = true;  // from the first tick on, everything this thread does is counted
        // The emulator is single-threaded: the loop thread itself pulls the plug, after 400 ticks.
        if (++ticks == 400) rig.emulator.disconnect();
        return ServoCommand{spring(state, target), false};
      },
      options);
  const long before = watched_allocations.load();
  loop.start();
  CHECK_THROWS_MATCHES(
      loop.wait(), CommunicationError,
      Catch::Matchers::Message(device_fault_message(DeviceFault::link_lost, rig.device->info().model)));
  const ServoLoopStats stats = loop.stats();
  CHECK(watched_allocations.load() == before);
  CHECK(stats.fault.kind == LoopFaultKind::device);
  CHECK(stats.fault.device == DeviceFault::link_lost);
  CHECK(stats.ticks == 399);  // the write of tick 400 found the link gone
  CHECK_FALSE(rig.device->is_open());
  CHECK(rig.emulator.motor_torques().isZero());
}
#endif
