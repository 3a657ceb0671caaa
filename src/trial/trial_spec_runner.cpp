#include "calligraphy/trial/trial_spec_runner.hpp"

#include <memory>
#include <string>
#include <utility>
#include <variant>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/trial/runner.hpp"

namespace calligraphy {
namespace {

// The options of the whole trial `trial`. Every value comes from the checked whole trial (its
// specification's rate, duration and watchdog in the ranges TrialOptions::validate reads; its force law,
// safety chain and passivity controller each validated whole), or is a default: valid by construction,
// which tests/trial_spec_test.cpp shows on random specifications.
TrialOptions options_of(const WholeTrial& trial) {
  const TrialSpec& spec = trial.spec;
  TrialOptions options;
  options.force = trial.force_law;
  options.safety = trial.safety;
  options.passivity = trial.passivity;
  options.rate_hz = spec.rate_hz;
  options.pacing = spec.pacing;
  options.loop.realtime = spec.realtime;
  // A real-time schedule asked for needs a priority in its range: the loop's own constant, as a program that
  // exists to run the trial sets (below); so the options stated are valid as they are derived.
  if (spec.realtime == RealtimeMode::enforce) options.loop.priority = kDedicatedServoPriority;
  options.loop.stall_timeout_s = spec.watchdog_s;
  options.max_duration_s = spec.max_duration_s;
  options.keep_trace = true;  // the metrics are taken from the trace (writing_metrics)
  return options;
}

// A replay runs on the teacher's samples, which the caller reads from the specification's file or has.
void require_teacher(const TrialSpec& spec, const TrialRunInputs& inputs) {
  if (spec.guidance && spec.guidance_mode == GuidanceMode::replay && inputs.teacher.empty()) {
    throw InvalidArgument(
        "teacher (--teacher): a replay runs on the teacher's samples (TrialRunInputs::teacher), read from " +
        (spec.teacher.empty() ? std::string("a teacher's recording") : spec.teacher) +
        " by its front-end (read_teacher_recording)");
  }
}

// The device `spec.device` made by `inputs.registry`, for a caller (`who`) that gives none to run on.
std::unique_ptr<HapticDevice> registry_device(const TrialSpec& spec, const TrialRunInputs& inputs,
                                              const char* who) {
  if (inputs.registry == nullptr) {
    throw InvalidArgument(std::string(who) + ": no device and no registry to create \"" + spec.device +
                          "\" from (TrialRunInputs::device, TrialRunInputs::registry)");
  }
  return inputs.registry->create(spec.device);
}

}  // namespace

TrialOptions trial_options(const Checked<TrialSpec>& spec, const DeviceInfo& device) {
  // Unchecked: a replay's options have no teacher yet.
  return options_of(*build_whole_trial(spec, device));
}

Checked<TrialOptions> whole_trial_options(const Checked<WholeTrial>& trial,
                                          const std::vector<TeacherSample>& teacher) {
  const TrialSpec& spec = trial->spec;
  if (!(spec.guidance && spec.guidance_mode == GuidanceMode::replay))
    return trial.derive([](const WholeTrial& whole) { return options_of(whole); });
  // A replay's teacher is a new value: the options holding it are checked once.
  TrialOptions replay = options_of(*trial);
  if (auto* law = std::get_if<ReplayGuidance>(&replay.force.guidance_law)) law->teacher_trajectory = teacher;
  return Checked<TrialOptions>::check(std::move(replay));
}

bool simulated_writer_writes(const TrialSpec& spec, bool simulated_writer_can_move) {
  switch (spec.writer) {
    case TrialWriter::automatic:
      return simulated_writer_can_move;
    case TrialWriter::simulated:
      if (!simulated_writer_can_move) {
        throw InvalidArgument("writer (--writer): 'simulated': the device '" + spec.device +
                              "' is moved by a person (writer 'person'); the simulated writer moves the "
                              "simulated and emulated devices");
      }
      return true;
    case TrialWriter::person:
      if (simulated_writer_can_move) {
        throw InvalidArgument("writer (--writer): 'person': a person cannot hold the device '" + spec.device +
                              "', the simulated writer moves it (writer 'simulated'); a person writes on a "
                              "haptic device, or with the mouse in `calligraphy train`");
      }
      return false;
  }
  return false;
}

TrialRun run_whole_trial(const Checked<WholeTrial>& checked, const Scene& scene,
                         const TrialRunInputs& inputs) {
  const TrialSpec& spec = checked->spec;
  require_teacher(spec, inputs);
  TrialRun run;
  std::unique_ptr<HapticDevice> created;
  HapticDevice* device = inputs.device;
  if (device == nullptr && checked->simulated_device) {
    created = std::make_unique<SimulatedDevice>(*checked->simulated_device);
    device = created.get();
  }
  if (device == nullptr) {
    created = registry_device(spec, inputs, "run_whole_trial");
    device = created.get();
  }
  run.device = device->info();
  // Found once, here: the trial never asks what its device is.
  run.simulated_writer = simulated_writer_writes(spec, device->hand_port() != nullptr);
  if (run.simulated_writer && inputs.hand_maker == nullptr) {
    throw InvalidArgument("run_whole_trial: the simulated writer writes on \"" + spec.device +
                          "\" and no hand maker makes its hand (TrialRunInputs::hand_maker: sim's "
                          "SimulatedWriting)");
  }

  // The whole trial was checked once, by its builder: its options are derived, unchecked. A replay's
  // teacher is a runtime input, a new value: the options holding it are checked here once.
  Checked<TrialOptions> options = whole_trial_options(checked, inputs.teacher);
  // Where the trial runs from (a stop flag, a display, the process's real-time settings): no parameter of
  // the force, and nothing TrialOptions::validate refuses (the priority is the loop's valid constant).
  options = options.derive([&](TrialOptions running) {
    running.display = inputs.display;
    running.should_stop = inputs.should_stop;
    if (!inputs.host_process) {  // a program that exists to run the trial asks for the real-time settings
      running.loop.priority = kDedicatedServoPriority;
      running.loop.lock_memory = inputs.lock_memory;
    }
    return running;
  });

  std::unique_ptr<TrialHand> hand;
  if (run.simulated_writer) hand = inputs.hand_maker->make_hand(*device, scene, spec.seed);
  run.result = run_trial(*device, scene, options, hand.get());
  // The figures of the device as it ran: a device that reads its limits when it is opened (OpenHaptics)
  // knows them only now.
  run.device = device->info();
  run.options = *options;
  if (hand) inputs.hand_maker->after_trial(run.result);  // the hand has let go (run_trial), and still is
  hand.reset();                                          // before the device goes
  run.options.should_stop = nullptr;
  run.options.display = nullptr;
  run.metrics = trial_writing_metrics(scene, run.result, run.options.force.acceptance);
  return run;
}

TrialRun run_trial_spec(const Checked<TrialSpec>& spec, const Scene& scene, const TrialRunInputs& inputs) {
  require_teacher(*spec, inputs);  // before a device is created
  std::unique_ptr<HapticDevice> created;
  TrialRunInputs with_device = inputs;
  if (with_device.device == nullptr) {
    created = registry_device(*spec, inputs, "run_trial_spec");
    with_device.device = created.get();
  }
  // The specification's defaults on this device, through the one builder.
  return run_whole_trial(build_whole_trial(spec, with_device.device->info()), scene, with_device);
}

}  // namespace calligraphy
