// The real-time servo loop: rate, start/stop/restart, fault containment, concurrent statistics, and a
// real-time trial on the simulated device (late ticks and stalls: servo_loop_stall_test.cpp). Timing is
// asserted only as loose properties (tick counts within 20 %), never as benchmarks; `calligraphy bench
// loop` measures jitter.
#include "calligraphy/devices/servo_loop.hpp"

#include <dirent.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/trial/trial.hpp"
#include "devices/latency_histogram.hpp"
#include "embedded_scenes.hpp"
#include "probe_device.hpp"

using namespace calligraphy;

using test::ProbeDevice;

namespace {

// Options for tests: best effort realtime (SCHED_FIFO when permitted keeps the counts steady on a busy
// machine), no process-wide memory locking, no stall bound and a force-age bound loose enough for a
// loaded or sanitized build (the tests of those bounds set them).
ServoLoopOptions test_options(double rate_hz = 1000.0) {
  ServoLoopOptions o;
  o.rate_hz = rate_hz;
  o.realtime = RealtimeMode::ignore;
  o.priority = kDedicatedServoPriority;
  o.lock_memory = false;
  o.stall_timeout_s = 0.0;
  o.max_force_age_s = 1.0;
  return o;
}

std::size_t thread_count() {
  std::size_t n = 0;
  if (DIR* dir = opendir("/proc/self/task")) {
    while (const dirent* entry = readdir(dir)) {
      if (entry->d_name[0] != '.') ++n;
    }
    closedir(dir);
  }
  return n;
}

// The thread count once exited threads are gone: a joined thread can stay listed in /proc for a moment
// after pthread_join returns (the kernel wakes the joiner before it unlists the task).
std::size_t settled_thread_count(std::size_t expected) {
  for (int i = 0; i < 100 && thread_count() != expected; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return thread_count();
}

}  // namespace

TEST_CASE("The servo loop accepts rates from 100 Hz to 10 kHz and nothing else", "[servo]") {
  SimulatedDevice device;
  const auto callback = [](const DeviceState&, double) { return ServoCommand{}; };
  for (double rate : {99.9, 10000.1, 0.0, -1000.0, std::nan("")}) {
    ServoLoopOptions o = test_options(rate);
    CHECK_THROWS_AS(ServoLoop(device, callback, o), InvalidArgument);
  }
  for (double rate : {100.0, 1000.0, 10000.0}) CHECK_NOTHROW(ServoLoop(device, callback, test_options(rate)));
  ServoLoopOptions o = test_options();
  o.realtime = RealtimeMode::enforce;
  o.priority = 0;
  CHECK_THROWS_AS(ServoLoop(device, callback, o), InvalidArgument);
  CHECK_THROWS_AS(ServoLoop(device, ServoCallback{}, test_options()), InvalidArgument);
}

TEST_CASE("The latency histogram's quantiles are bin upper edges capped at the maximum", "[servo]") {
  devices::LatencyHistogram h(1000);  // 1 us bins
  CHECK(h.quantile_ns(0.5) == 0.0);
  for (int i = 0; i < 98; ++i) h.add(2500);  // bin [2, 3) us
  h.add(40'000);                             // bin [40, 41) us
  h.add(5'000'000);                          // 5 ms: a coarse bin (100 us wide)
  CHECK(h.count() == 100);
  CHECK(h.quantile_ns(0.50) == 3000.0);
  CHECK(h.quantile_ns(0.99) == 41000.0);
  CHECK(h.quantile_ns(1.0) == 5'000'000.0);  // the coarse bin's edge 5.1 ms, capped at the exact max
  CHECK(h.max_ns() == 5'000'000);
  CHECK(h.mean_ns() == Approx((98 * 2500.0 + 40'000 + 5'000'000) / 100));
  h.add(-5);  // clock oddities count as zero
  CHECK(h.bin_count(0) == 1);
}

TEST_CASE("The servo loop ticks at its rate", "[servo]") {
  for (double rate : {1000.0, 5000.0}) {
    SimulatedDevice device;
    device.open();
    std::atomic<std::uint64_t> calls{0};
    double dt_sum = 0.0;
    ServoLoop loop(
        device,
        [&](const DeviceState&, double dt_s) {
          dt_sum += dt_s;
          calls.fetch_add(1, std::memory_order_relaxed);
          return ServoCommand{};
        },
        test_options(rate));
    const auto t0 = std::chrono::steady_clock::now();
    loop.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    loop.stop();
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const ServoLoopStats s = loop.stats();
    INFO("rate " << rate << " Hz, elapsed " << elapsed_s << " s, ticks " << s.ticks << ", skipped "
                 << s.skipped_periods);
    CHECK(s.ticks == calls.load());
    // Every period of the run is either a tick or a period skipped after a late tick.
    const double periods = static_cast<double>(s.ticks + s.skipped_periods);
    CHECK(periods == Approx(elapsed_s * rate).epsilon(0.2));
    // The callback's dt adds up to the time between the first and the last tick.
    CHECK(dt_sum == Approx(static_cast<double>(s.ticks + s.skipped_periods) / rate).epsilon(0.2));
    CHECK(s.period_jitter_us_p50 <= s.period_jitter_us_p99);
    CHECK(s.period_jitter_us_p99 <= s.period_jitter_us_max);
    CHECK(s.callback_us_mean <= s.callback_us_max);
    CHECK_FALSE(s.fault);
  }
}

TEST_CASE("Start, stop and restart leave no thread behind and the forces off", "[servo]") {
  SimulatedDevice device;
  const auto callback = [](const DeviceState&, double) { return ServoCommand{Vec3(0.5, 0.0, 0.0), false}; };
  ServoLoop loop(device, callback, test_options());
  CHECK_THROWS_AS(loop.start(), DeviceError);  // the device is not open
  device.open();
  const std::size_t threads_before = thread_count();
  for (int run = 0; run < 3; ++run) {
    loop.start();
    CHECK(loop.running());
    CHECK(device.forces_enabled());
    CHECK_THROWS_AS(loop.start(), Error);  // already running
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    const LoopFault fault = loop.stop();
    CHECK_FALSE(fault);
    CHECK_FALSE(loop.running());
    CHECK_FALSE(device.forces_enabled());
    CHECK(device.applied_force() == Vec3::Zero());
    CHECK(loop.stats().ticks > 5);
    CHECK(settled_thread_count(threads_before) == threads_before);
  }
  loop.stop();  // again: harmless
  {
    ServoLoop scoped(device, callback, test_options());
    scoped.start();
  }  // the destructor stops it
  CHECK(settled_thread_count(threads_before) == threads_before);
  CHECK_FALSE(device.forces_enabled());
}

TEST_CASE("The callback stops the loop through its return value", "[servo]") {
  SimulatedDevice device;
  device.open();
  std::uint64_t n = 0;
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) {
        return ServoCommand{Vec3(0.3, 0, 0), ++n % 40 == 0};
      },
      test_options(2000.0));
  loop.start();
  loop.wait();
  CHECK(loop.stats().ticks == 40);
  CHECK_FALSE(loop.running());
  CHECK_FALSE(device.forces_enabled());
  loop.start();  // restart after a stop from the callback
  loop.wait();
  CHECK(n == 80);
}

TEST_CASE("An exception from the callback is contained: force zeroed, fault reported, loop stopped",
          "[servo]") {
  SimulatedDevice device;
  device.open();
  std::uint64_t n = 0;
  ServoLoop loop(
      device,
      [&](const DeviceState&, double) {
        if (++n == 50) throw std::runtime_error("renderer: something went wrong at tick 50");
        return ServoCommand{Vec3(0.0, 0.7, 0.0), false};
      },
      test_options());
  loop.start();
  CHECK_THROWS_WITH(loop.wait(), "renderer: something went wrong at tick 50");
  const ServoLoopStats s = loop.stats();
  CHECK(s.ticks == 49);
  CHECK(s.fault.kind == LoopFaultKind::callback);
  CHECK(s.fault.message == "renderer: something went wrong at tick 50");
  CHECK_FALSE(s.running);
  CHECK(device.applied_force() == Vec3::Zero());
  CHECK_FALSE(device.forces_enabled());
  CHECK(loop.stop().kind == LoopFaultKind::callback);  // stop() reports the same fault without throwing
}

TEST_CASE("A device fault code mid-run stops the loop and is thrown, typed, on the caller's thread",
          "[servo]") {
  // One taxonomy: the code the device returns is the loop's fault, and wait() throws the exception the
  // one mapping (throw_device_fault) gives it, with the same message.
  struct Case {
    DeviceFault fault;
    bool link;  // CommunicationError, else SafetyFault
  };
  for (const Case c : {Case{DeviceFault::link_lost, true}, Case{DeviceFault::no_valid_status, true},
                       Case{DeviceFault::watchdog, false}, Case{DeviceFault::safety_limit, false}}) {
    INFO(device_fault_name(c.fault));
    ProbeDevice device(/*fail_on_read=*/30, c.fault);
    ServoLoop loop(
        device,
        [](const DeviceState&, double) {
          return ServoCommand{Vec3(ProbeDevice::kMarker, 0, 0), false};
        },
        test_options());
    loop.start();
    const std::string expected = device_fault_message(c.fault, device.info().model);
    if (c.link) {
      CHECK_THROWS_MATCHES(loop.wait(), CommunicationError, Catch::Matchers::Message(expected));
    } else {
      CHECK_THROWS_MATCHES(loop.wait(), SafetyFault, Catch::Matchers::Message(expected));
    }
    const ServoLoopStats s = loop.stats();
    CHECK(s.ticks == 30);
    CHECK(s.fault.kind == LoopFaultKind::device);
    CHECK(s.fault.device == c.fault);
    CHECK(s.fault.message == to_string(c.fault));
    CHECK(loop.stop().device == c.fault);  // stop() reports the same fault without throwing
    CHECK(device.marker_writes_ == 30);    // no force written after the failed read
    CHECK(device.inner_.applied_force() == Vec3::Zero());
    CHECK_FALSE(device.forces_enabled());
  }
}

TEST_CASE("The statistics are readable from another thread while the loop runs", "[servo]") {
  SimulatedDevice device;
  device.open();
  ServoLoop loop(
      device,
      [&](const DeviceState&, double dt) {
        device.advance(dt);
        return ServoCommand{};
      },
      test_options(4000.0));
  loop.start();
  std::uint64_t last = 0;
  bool monotonic = true;
  int snapshots = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
  while (std::chrono::steady_clock::now() < until) {
    const ServoLoopStats s = loop.stats();
    monotonic = monotonic && s.ticks >= last && s.running;
    last = s.ticks;
    ++snapshots;
  }
  loop.stop();
  CHECK(monotonic);
  CHECK(snapshots > 10);
  CHECK(loop.stats().ticks >= last);
  CHECK(last > 100);
}

TEST_CASE("The loop's defaults change nothing process-wide: no SCHED_FIFO, no locked memory", "[servo]") {
  SimulatedDevice device;
  device.open();
  ServoLoopOptions defaults;
  defaults.stall_timeout_s = 0.0;  // a loaded test machine may stall; not what this test is about
  ServoLoop loop(
      device, [](const DeviceState&, double) { return ServoCommand{}; }, defaults);
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  loop.stop();
  const RealtimeStatus realtime = loop.stats().realtime;
  CHECK_FALSE(realtime.fifo_scheduling);
  CHECK(realtime.priority == 0);
  CHECK_FALSE(realtime.memory_locked);
  CHECK(realtime.cpu == -1);
  CHECK(realtime.problems.empty());  // nothing was asked, so nothing failed
}

TEST_CASE("Enforced realtime that cannot be had fails at start with the reason", "[servo]") {
  SimulatedDevice device;
  device.open();
  ServoLoopOptions o = test_options();
  o.realtime = RealtimeMode::enforce;
  o.priority = kDedicatedServoPriority;  // the defaults ask for no priority, which enforce refuses
  o.cpu = 1023;  // no such CPU here: EINVAL (or EPERM for the priority when not privileged)
  const std::size_t threads_before = thread_count();
  ServoLoop loop(
      device, [](const DeviceState&, double) { return ServoCommand{}; }, o);
  try {
    loop.start();
    FAIL("start() did not throw");
  } catch (const RealtimeError& e) {
    const std::string message = e.what();
    CHECK((message.find("EINVAL") != std::string::npos || message.find("EPERM") != std::string::npos));
  }
  CHECK_FALSE(loop.running());
  CHECK_FALSE(device.forces_enabled());
  CHECK(settled_thread_count(threads_before) == threads_before);
}

TEST_CASE("A real-time trial on the simulated device records the lock-step trial's trace", "[servo]") {
  const Scene scene = testing::embedded_scene(U'口');
  TrialOptions trial;
  trial.max_duration_s = 2.5;  // about the first stroke of 口 (a whole trial would take 6 s of wall clock)
  SimulationOptions skilled;
  skilled.writer = WriterProfile::skilled();
  const TrialResult lockstep = run_simulated_trial(scene, trial, skilled);
  trial.pacing = TrialPacing::real_time;
  trial.loop = test_options();
  const TrialResult realtime = run_simulated_trial(scene, trial, skilled);

  CHECK(realtime.end == TrialEnd::time_limit);
  REQUIRE(realtime.loop.has_value());
  CHECK_FALSE(realtime.loop->fault);
  CHECK(realtime.loop->ticks == 2500);
  REQUIRE(realtime.trace.size() == 2500);
  REQUIRE(lockstep.trace.size() >= realtime.trace.size());
  CHECK(realtime.metrics.strokes_completed >= 1);
  bool same = true;
  for (std::size_t i = 0; i < realtime.trace.size(); ++i) {
    const TrialSample& a = realtime.trace[i];
    const TrialSample& b = lockstep.trace[i];
    same = same && a.time_s == b.time_s && a.position_m == b.position_m && a.force_n == b.force_n &&
           a.state == b.state && a.stroke == b.stroke && a.element == b.element;
  }
  CHECK(same);
  const StrokeMetrics& first = realtime.metrics.per_stroke[0];
  CHECK(first.completed);
  CHECK(first.trace_begin == lockstep.metrics.per_stroke[0].trace_begin);
  CHECK(first.trace_end == lockstep.metrics.per_stroke[0].trace_end);
  CHECK(first.mean_deviation_m == lockstep.metrics.per_stroke[0].mean_deviation_m);
}

TEST_CASE("A device fault during a real-time trial keeps the recording and reports the fault", "[servo]") {
  const Scene scene = testing::embedded_scene(U'口');
  ProbeDevice device(/*fail_on_read=*/300);
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.loop = test_options();
  options.max_duration_s = 2.0;
  const TrialResult result = run_trial(device, scene, options, SimulationOptions{});
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.aborted);
  CHECK(result.device_fault == DeviceFault::link_lost);
  CHECK(result.abort_reason == device_fault_message(DeviceFault::link_lost, device.info().model));
  REQUIRE(result.loop.has_value());
  CHECK(result.loop->fault.kind == LoopFaultKind::device);
  CHECK(result.loop->fault.device == DeviceFault::link_lost);
  CHECK(result.trace.size() == 300);
  CHECK(result.trace.back().time_s > result.trace.front().time_s);
  CHECK_FALSE(device.forces_enabled());
}

TEST_CASE("Start, stop and restart under a running trial leave no thread behind", "[servo]") {
  const Scene scene = testing::embedded_scene(U'口');
  SimulatedDevice device;
  SimulatedWriter writer(scene, WriterProfile::skilled(), 0);
  Renderer renderer(scene, ForceLawParameters{}, device.info());
  TrialRecorder recorder(scene, /*keep_trace=*/false);
  device.attach_hand(&writer);
  device.open();
  const double period_s = 1e-3;
  ServoLoop loop(
      device,
      [&](const DeviceState& state, double) {
        const RenderOutput out = renderer.tick(state);
        recorder.record(state, out);
        if (device.write_force(out.force_n) != DeviceFault::none) return ServoCommand{Vec3::Zero(), true};
        writer.observe(out, state);
        device.advance(period_s);
        return ServoCommand{out.force_n, out.finished};
      },
      test_options());
  const std::size_t threads_before = thread_count();
  double last_time_s = 0.0;
  for (int run = 0; run < 3; ++run) {
    loop.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    CHECK_FALSE(loop.stop());
    CHECK(settled_thread_count(threads_before) == threads_before);
    CHECK_FALSE(device.forces_enabled());
    CHECK(device.time() > last_time_s);  // the trial went on in each run
    last_time_s = device.time();
  }
}
