// The trainer's entry points (trainer.hpp): checks before a window opens, the stop signals, and a study
// session's thread beside the window.
#include "trainer/trainer.hpp"

#include <atomic>
#include <exception>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/stop_signals.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "trainer/hosted_session_view.hpp"
#include "trainer/pointer_devices.hpp"
#include "trainer/practice_controller.hpp"
#include "trainer/session_host.hpp"
#include "trainer/stop_reason.hpp"
#include "trainer/trainer_window.hpp"

namespace calligraphy::trainer {

int run_trainer(const TrainerOptions& options) {
  if (options.characters.empty()) throw InvalidArgument("calligraphy train: no characters to practise");
  if (options.registry == nullptr)
    throw InvalidArgument("calligraphy train: no device registry (TrainerOptions::registry)");
  // The device must exist, and a simulated writer can move only a device with a hand port.
  const DeviceListing listing = options.registry->find(options.device);
  const bool hand_port = listing.capabilities.moved_by_simulated_hand;
  if (options.simulated_writer && !hand_port) {
    throw InvalidArgument(
        "--writer simulated needs a device a simulated writer can move (simulated, "
        "emulated-phantom); '" +
        options.device + "' is moved by a person");
  }
  if (!options.simulated_writer && hand_port) {
    throw InvalidArgument("device '" + options.device +
                          "' is moved by the simulated writer: pass --writer simulated, or use mouse, "
                          "mouse-hand or a haptic device");
  }
  // SIGINT, SIGTERM and SIGHUP only set a flag; the window loop ends the trial safely. A command that
  // installed the handlers already (a study session) keeps them.
  std::optional<StopSignals> signals;
  if (!StopSignals::installed()) signals.emplace();
  TrainerApp app(options, options.registry->create(options.device)->info(), listing.capabilities.hardware);
  return app.run();
}

void register_trainer_devices(DeviceRegistry& registry) { register_pointer_devices(registry); }

SessionRunResult run_trainer_session(const TrainerSessionOptions& options) {
  if (options.session == nullptr) throw InvalidArgument("run_trainer_session: no session");
  SessionFolder& folder = *options.session;
  const SessionManifest& manifest = folder.manifest();
  TrainerOptions window;
  std::map<char32_t, bool> seen;
  for (const PlannedTrial& trial : manifest.plan) {
    for (const char32_t c : trial.characters) {
      if (seen[c]) continue;
      seen[c] = true;
      window.characters.push_back(options.load_character(c));
    }
  }
  if (window.characters.empty()) throw InvalidArgument("run_trainer_session: the plan has no characters");
  window.device = manifest.setup.device;
  window.width_px = options.width_px;
  window.height_px = options.height_px;
  window.screenshot = options.screenshot;
  window.quiz_screenshots = options.quiz_screenshots;
  window.exit_after_s = options.exit_after_s;
  window.library_version = options.library_version;
  std::optional<StopSignals> signals;
  if (!StopSignals::installed()) signals.emplace();

  WindowSessionHost host(manifest, options.exit_after_s > 0.0, kAdvanceDelayS);
  SessionRunOptions run = options.run;
  run.host = &host;
  // A window process maps memory all the time (the GL driver): mlockall(MCL_FUTURE) would lock all of it.
  run.lock_memory = false;
  const std::function<bool()> outer_stop = options.run.should_stop;
  run.should_stop = [&host, outer_stop] {
    return host.stop_requested() || StopSignals::received() != 0 || (outer_stop && outer_stop());
  };
  const std::function<std::string()> outer_reason = options.run.stop_reason;
  run.stop_reason = [outer_reason] {
    const std::string reason = stop_reason();
    return !reason.empty() || !outer_reason ? reason : outer_reason();
  };
  std::atomic<bool> done{false};
  std::optional<SessionRunResult> result;
  std::exception_ptr failure;
  const SessionLink link{&host, &done, &manifest};
  // Whether the session's device is felt (a haptic device), for the learner's device line.
  bool hardware = false;
  if (options.run.registry != nullptr) {
    try {
      hardware = options.run.registry->find(window.device).capabilities.hardware;
    } catch (const std::exception&) {  // run_session names an unknown device itself
    }
  }
  window.engineer = options.engineer;
  TrainerApp app(window, DeviceInfo{}, hardware, &link);
  std::thread runner([&] {
    try {
      result = run_session(folder, run);
    } catch (...) {
      failure = std::current_exception();
    }
    host.mark_finished();
    done.store(true);
  });
  try {
    app.run();
  } catch (...) {
    host.request_stop();
    runner.join();
    throw;
  }
  host.request_stop();  // the window is closed: nothing more is shown
  runner.join();
  if (failure) std::rethrow_exception(failure);
  return *result;
}

}  // namespace calligraphy::trainer
