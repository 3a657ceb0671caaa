// The one trial runner for every device and pacing (runner.hpp).
#include "calligraphy/trial/runner.hpp"

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/trial/session.hpp"

namespace calligraphy {
namespace {

// Zero force, forces off, the hand let go and the link closed on every way out of a trial; never throws
// (the link may be gone).
class DeviceShutdown {
 public:
  DeviceShutdown(HapticDevice& device, TrialHand* hand) : device_(device), hand_(hand) {}
  DeviceShutdown(const DeviceShutdown&) = delete;
  DeviceShutdown& operator=(const DeviceShutdown&) = delete;
  ~DeviceShutdown() {
    try {
      // The last tick's force must not outlive the trial (the real-time loop has zeroed and disabled it).
      // A fault code here is ignored: disabling and closing still follow.
      if (device_.is_open() && device_.forces_enabled()) static_cast<void>(device_.write_force(Vec3::Zero()));
    } catch (...) {
      // The link may be gone (the trial may be ending because of it); disabling and closing still follow.
    }
    try {
      device_.enable_forces(false);
    } catch (...) {
      // Disabling is documented not to throw; a broken backend must still get close().
    }
    if (hand_ != nullptr) hand_->release();
    device_.close();
  }

 private:
  HapticDevice& device_;
  TrialHand* hand_;
};

// Lock-step: each tick reads the device, steps the session, commands the force, lets the hand see the
// output and advances the device's time by one period. No wall clock.
TrialResult run_lock_step(HapticDevice& device, TrialHand& hand, TrialSession& session,
                          const TrialOptions& options) {
  const double period_s = 1.0 / options.rate_hz;
  double end_time_s = -1.0;
  TrialEnd end = TrialEnd::time_limit;
  DeviceFault fault = DeviceFault::none;  // the device's calls return codes: nothing to catch here
  while (true) {
    if (options.should_stop && options.should_stop()) {
      end = TrialEnd::interrupted;
      break;
    }
    DeviceState state;
    if (fault = device.read_state(state); fault != DeviceFault::none) break;
    const ServoCommand command = session.step(state);
    if (fault = device.write_force(command.force_n); fault != DeviceFault::none) break;
    end_time_s = state.time_s;
    if (session.finished()) {
      end = TrialEnd::completed;
      break;
    }
    hand.observe(session.last_output(), state);
    if (hand.stopped()) {
      end = hand.finished() ? TrialEnd::writer_finished : TrialEnd::gave_up;
      break;
    }
    if (command.stop) {  // out of time after this tick: the trial lasted until the next would start
      end_time_s = state.time_s + period_s;
      break;
    }
    hand.advance(period_s);
  }
  if (fault == DeviceFault::none) return session.finish(end, {}, end_time_s);
  // Link lost, safety fault: the code's message, built now that the loop has ended.
  TrialResult result =
      session.finish(TrialEnd::device_fault, device_fault_message(fault, device.info().model), end_time_s);
  result.device_fault = fault;
  return result;
}

// Real time on the ServoLoop: the loop thread steps the session (and a hand, which sees the output and
// moves the device right after the force write); this thread polls `should_stop`.
TrialResult run_real_time(HapticDevice& device, TrialHand* hand, TrialSession& session,
                          const TrialOptions& options) {
  ServoLoopOptions loop_options = options.loop;
  loop_options.rate_hz = options.rate_hz;
  const double period_s = 1.0 / options.rate_hz;
  std::atomic<bool> hand_stopped{false};
  session.reserve_trace();
  // Carries the session's rate to the loop, which refuses a device clock at another rate at start.
  ServoLoop loop(device,
                 ticking(session,
                         [&, step = session.servo_callback()](const DeviceState& state,
                                                              double dt_s) mutable -> ServoCommand {
                           ServoCommand command = step(state, dt_s);
                           if (hand != nullptr && !command.stop) {
                             hand->observe(session.last_output(), state);
                             if (hand->stopped()) {
                               hand_stopped.store(true, std::memory_order_relaxed);
                               command.stop = true;
                             }
                           }
                           return command;
                         }),
                 loop_options,
                 // A hand's world steps right after each force write, so that the force acts during the step.
                 hand != nullptr ? ServoLoop::AfterForceWrite([hand, period_s] { hand->advance(period_s); })
                                 : ServoLoop::AfterForceWrite());

  loop.start();
  bool interrupted = false;
  while (loop.running()) {
    if (options.should_stop && options.should_stop()) {
      interrupted = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const LoopFault fault = loop.stop();  // joined; forces are zero and disabled
  TrialEnd end = TrialEnd::interrupted;
  if (fault) {
    end = fault.kind == LoopFaultKind::watchdog ? TrialEnd::watchdog : TrialEnd::device_fault;
  } else if (session.finished()) {
    end = TrialEnd::completed;
  } else if (hand_stopped.load(std::memory_order_relaxed)) {
    end = hand->finished() ? TrialEnd::writer_finished : TrialEnd::gave_up;
  } else if (!interrupted && session.out_of_time()) {
    end = TrialEnd::time_limit;
  }
  // A device fault is the device's code (the loop recorded it without building a string): its message
  // is built here, off the loop thread, by the one mapping from codes to messages.
  TrialResult result = session.finish(end, fault.kind == LoopFaultKind::device
                                               ? device_fault_message(fault.device, device.info().model)
                                               : fault.message);
  result.device_fault = fault.device;
  result.loop = loop.stats();
  return result;
}

}  // namespace

TrialResult run_trial(HapticDevice& device, const Scene& scene, const TrialOptions& options,
                      TrialHand* hand) {
  return run_trial(device, scene, Checked<TrialOptions>::check(options), hand);
}

TrialResult run_trial(HapticDevice& device, const Scene& scene, const Checked<TrialOptions>& checked,
                      TrialHand* hand) {
  const TrialOptions& options = *checked;
  if (hand == nullptr && options.pacing == TrialPacing::lock_step) {
    throw InvalidArgument("lock-step pacing needs a hand that moves the device (a simulated writer); '" +
                          device.info().model + "' is moved by a person: use real-time pacing");
  }
  const bool real_time = hand == nullptr || options.pacing == TrialPacing::real_time;
  const DeviceShutdown shutdown(device, hand);
  try {
    if (!device.is_open()) device.open();
    if (!device.is_calibrated()) device.calibrate();
  } catch (const DeviceError&) {
    // A stop asked for while the device was opening (a driver waited for, e.g. OpenHaptics' scheduler,
    // gives up on it): an interrupted trial with nothing recorded, written like any other, not an error.
    if (!options.should_stop || !options.should_stop()) throw;
    TrialSession stopped(scene, device.info(), checked);
    return stopped.finish(TrialEnd::interrupted);
  }
  // After open(): some devices know their limits only then (OpenHaptics reads them from the driver).
  TrialSession session(scene, device.info(), checked);
  if (real_time) return run_real_time(device, hand, session, options);
  device.enable_forces(true);
  return run_lock_step(device, *hand, session, options);
}

}  // namespace calligraphy
