#include "calligraphy/trial/trial_spec_runner.hpp"

#include <algorithm>
#include <memory>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/trial/runner.hpp"

namespace calligraphy {
namespace {

// The force law's default stiffnesses capped at the device's stable maximum (the Phantom Omni's 700 N/m
// against the paper's K_en = 800 N/m); a stiffness set on purpose is kept, and the renderer warns about it.
void fit_default_stiffness(ForceLawParameters& force, const DeviceInfo& device) {
  const double limit = device.max_stiffness_n_per_m;
  if (!(limit > 0.0)) return;  // 0: the device states no limit
  const ForceLawParameters defaults;
  if (force.paper_stiffness_n_per_m == defaults.paper_stiffness_n_per_m) {
    force.paper_stiffness_n_per_m = std::min(force.paper_stiffness_n_per_m, limit);
  }
  if (force.guidance_stiffness_n_per_m == defaults.guidance_stiffness_n_per_m) {
    force.guidance_stiffness_n_per_m = std::min(force.guidance_stiffness_n_per_m, limit);
  }
}

// The specification's mode with the parameters it sets; a replay's teacher is the runner's to add.
GuidanceLaw guidance_law_of(const TrialSpec& spec) {
  switch (spec.guidance_mode) {
    case GuidanceMode::fixed:
      break;
    case GuidanceMode::fading:
      return FadingGuidance{.gain = spec.guidance_gain};
    case GuidanceMode::replay:
      return ReplayGuidance{};
    case GuidanceMode::assist_as_needed:
      return AssistAsNeededGuidance{.band_m = spec.assist_band_m};
    case GuidanceMode::error_amplification:
      return ErrorAmplificationGuidance{.gain = spec.amplification_gain};
    case GuidanceMode::timing:
      return TimingGuidance{.speed_m_s = spec.timing_speed_m_s};
  }
  return FixedGuidance{};
}

// The options `spec` states on `device`. Every value comes from the checked specification (its rate, duration
// and watchdog in the ranges TrialOptions::validate reads, its guidance law's parameter in the law's table)
// or is a default, and a default stiffness is only lowered to the device's positive limit: valid by
// construction, which tests/trial_spec_test.cpp shows on random specifications.
TrialOptions options_stated(const TrialSpec& spec, const DeviceInfo& device) {
  TrialOptions options;
  options.force.guidance = spec.guidance;
  options.force.guidance_law = guidance_law_of(spec);
  options.force.guidance_stiffness_n_per_m = spec.guidance_stiffness_n_per_m;
  fit_default_stiffness(options.force, device);
  options.force.acceptance =
      spec.acceptance;  // checked with the specification (its table's ranges and rules)
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

// The options of `spec` with what `inputs` gives instead, and a replay's teacher: to be checked.
TrialOptions given_options(const TrialSpec& spec, const DeviceInfo& device, const TrialRunInputs& inputs) {
  TrialOptions given = options_stated(spec, device);
  if (inputs.force_law) {
    const bool same_guidance =
        inputs.force_law->guidance == spec.guidance &&
        (!spec.guidance || mode_of(inputs.force_law->guidance_law) == spec.guidance_mode);
    if (!same_guidance) {
      throw InvalidArgument(
          std::string("trial inputs: the force law's guidance (") +
          (inputs.force_law->guidance ? to_string(mode_of(inputs.force_law->guidance_law)) : "off") +
          ") is not the specification's (" + (spec.guidance ? to_string(spec.guidance_mode) : "off") + ")");
    }
    given.force = *inputs.force_law;
  }
  if (auto* law = std::get_if<ReplayGuidance>(&given.force.guidance_law))
    law->teacher_trajectory = inputs.teacher;
  if (inputs.safety) given.safety = *inputs.safety;
  if (inputs.passivity) given.passivity = *inputs.passivity;
  return given;
}

}  // namespace

TrialOptions trial_options(const Checked<TrialSpec>& spec, const DeviceInfo& device) {
  return options_stated(*spec, device);
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

TrialRun run_trial_spec(const Checked<TrialSpec>& checked, const Scene& scene, const TrialRunInputs& inputs) {
  const TrialSpec& spec = *checked;
  require_teacher(spec, inputs);
  TrialRun run;
  std::unique_ptr<HapticDevice> created;
  HapticDevice* device = inputs.device;
  if (device == nullptr) {
    if (inputs.registry == nullptr) {
      throw InvalidArgument("run_trial_spec: no device and no registry to create \"" + spec.device +
                            "\" from (TrialRunInputs::device, TrialRunInputs::registry)");
    }
    created = inputs.registry->create(spec.device);
    device = created.get();
  }
  run.device = device->info();
  // Found once, here: the trial never asks what its device is.
  run.simulated_writer = simulated_writer_writes(spec, device->hand_port() != nullptr);
  if (run.simulated_writer && inputs.hand_maker == nullptr) {
    throw InvalidArgument("run_trial_spec: the simulated writer writes on \"" + spec.device +
                          "\" and no hand maker makes its hand (TrialRunInputs::hand_maker: sim's "
                          "SimulatedWriting)");
  }

  // The specification's values were checked with it: its options are derived, unchecked. What the caller
  // gives instead (a force law, a safety chain, a passivity controller) and a replay's teacher are new
  // values: the options holding them are checked here once.
  const bool replay = spec.guidance && spec.guidance_mode == GuidanceMode::replay;
  const bool given = inputs.force_law || inputs.safety || inputs.passivity || replay;
  Checked<TrialOptions> options =
      given ? Checked<TrialOptions>::check(given_options(spec, run.device, inputs))
            : checked.derive([&](const TrialSpec& stated) { return options_stated(stated, run.device); });
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
  run.options = *options;
  if (hand) inputs.hand_maker->after_trial(run.result);  // the hand has let go (run_trial), and still is
  hand.reset();                                          // before the device goes
  run.options.should_stop = nullptr;
  run.options.display = nullptr;
  run.metrics = trial_writing_metrics(scene, run.result, run.options.force.acceptance);
  return run;
}

}  // namespace calligraphy
