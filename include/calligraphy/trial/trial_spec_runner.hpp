#pragma once
/// \file trial_spec_runner.hpp
/// The one runner of a trial, which `calligraphy trial`, the trainer, study sessions, cohorts and Python
/// call: it takes a checked whole trial (whole_trial.hpp, made by the one builder `build_whole_trial`) as
/// it is, with the runtime handles only its caller has (`TrialRunInputs`: the device or a registry, a
/// replay's teacher samples, the hand maker, a stop flag, a display, the process's real-time settings).
/// When the simulated writer writes, the caller's hand maker (TrialRunInputs::hand_maker: sim's
/// `SimulatedWriting`) makes the hand that `run_trial` (runner.hpp) is given: simulation is an input to the
/// trial, never part of it. `run_trial_spec` is a thin wrapper for a trial of the specification's defaults:
/// it creates the device and builds the whole trial for its figures through the same builder. The result
/// carries the one metrics record (writing_metrics.hpp).
#include <functional>
#include <optional>
#include <vector>

#include "calligraphy/analysis/writing_metrics.hpp"
#include "calligraphy/core/checked.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/trial/hand.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/whole_trial.hpp"

namespace calligraphy {

/// What a trial needs beyond the whole trial: the runtime handles only its caller has, none of them a
/// parameter of the trial (those are the whole trial's, given to its builder). Every member may stay empty.
struct TrialRunInputs {
  /// Where `TrialSpec::device` is created (not owned): its owner's registry, filled with the backends it
  /// offers (standard_device_registry() and its own). Required unless `device` is given or the whole trial
  /// states simulated device physics (WholeTrial::simulated_device).
  const DeviceRegistry* registry = nullptr;
  /// A device the caller made (not owned; opened here when it is not open, closed at the end), used
  /// instead of creating `TrialSpec::device`: the device whose figures the whole trial was built for
  /// (a session's, made before its trial so that a failure is logged; a simulated device with the caller's
  /// parameters).
  HapticDevice* device = nullptr;
  /// A replay's teacher pen, device frame [m], times [s]; required for a replay. The front-end reads it from
  /// the file `TrialSpec::teacher` (`read_teacher_recording`, `require_teacher_for`: teacher_recording.hpp),
  /// or has it (a session keeps its teacher in its folder; Python passes a TeacherRecording).
  std::vector<TeacherSample> teacher;
  /// Makes the simulated writer's hand (not owned): required when the simulated writer writes, i.e. on a
  /// device it can move (`simulated_writer_writes`). sim's `SimulatedWriting` of the specification, which
  /// checks its profile and settings and keeps what the writer did.
  TrialHandMaker* hand_maker = nullptr;
  /// Polled by the thread that runs the trial (TrialOptions::should_stop); may be empty.
  std::function<bool()> should_stop;
  /// False (the command line, study sessions): a real-time trial asks for SCHED_FIFO at
  /// `kDedicatedServoPriority` and locked memory, as a program that exists to run it. True (a window, the
  /// Python module): nothing process-wide, the `ServoLoopOptions` defaults.
  bool host_process = false;
  /// Where the trial publishes what a window shows (TrialOptions::display; not owned); nullptr: nowhere.
  DisplayChannel* display = nullptr;
  /// With `host_process` false: lock the process's memory in a real-time trial
  /// (ServoLoopOptions::lock_memory). A window process maps memory all the time (the GL driver):
  /// mlockall(MCL_FUTURE) would lock all of it, or make its allocations fail under a memory-lock limit, so it
  /// sets false (the trace is touched in advance instead) and keeps the real-time priority.
  bool lock_memory = true;
};

/// What ran, and what it gave.
struct TrialRun {
  TrialResult result;
  TrialOptions options;           ///< the options the trial ran with (should_stop and display cleared)
  DeviceInfo device;              ///< the device's figures as it ran (read when it was opened)
  bool simulated_writer = false;  ///< the simulated writer wrote (the hand maker's hand; else a person)
  WritingMetrics metrics;         ///< the one metrics record of the trace (writing_metrics.hpp)
};

/// The runner's options for the checked `spec` on a device with figures `device`: those of the whole trial
/// `build_whole_trial(spec, device)` makes (the force law `stated_force_law` states, the default safety
/// chain and passivity controller), with guidance, mode, gain, rate, pacing, real-time settings and duration
/// from `spec`. Valid as they are, but for a replay, whose teacher the runner adds (it then checks them).
/// What a front-end shows before its device is open (the trainer's view) and a plan's check read.
[[nodiscard]] TrialOptions trial_options(const Checked<TrialSpec>& spec, const DeviceInfo& device);

/// The runner's options of the checked whole trial `trial`: its force law, safety chain and passivity
/// controller, and the rate, pacing, real-time settings, watchdog and duration of its specification. Derived,
/// unchecked (valid by construction; tests/trial_spec_test.cpp walks that promise), but for a replay: its
/// teacher `teacher` (a runtime input, TrialRunInputs::teacher; pen in the device frame [m], times [s]) joins
/// the force law's replay law and the options holding it are checked (InvalidArgument naming the teacher's
/// fault, e.g. fewer than two samples). `teacher` is not read for another mode.
[[nodiscard]] Checked<TrialOptions> whole_trial_options(const Checked<WholeTrial>& trial,
                                                        const std::vector<TeacherSample>& teacher = {});

/// Who writes `spec` on a device: `TrialWriter::simulated` or `person` as stated, else the simulated writer
/// when `simulated_writer_can_move` (the device has a hand port), a person otherwise. Throws
/// InvalidArgument naming writer (--writer) when the simulated writer is asked to write on a device it
/// cannot move.
[[nodiscard]] bool simulated_writer_writes(const TrialSpec& spec, bool simulated_writer_can_move);

/// Runs the whole trial `trial` on `scene` (laid out from `trial->spec.characters` by the caller, who knows
/// where characters come from), taken as it is: nothing of it is validated again down to the renderer, and
/// nothing in `inputs` replaces a part of it. The device is `inputs.device` (the one the trial was built
/// for), else the simulated device of `trial->simulated_device`'s physics, else `spec.device` created from
/// `inputs.registry` (then the trial must have been built for that device's figures, as `run_trial_spec`
/// builds it). Asks `inputs.hand_maker` for the simulated writer's hand when it writes, runs `run_trial`,
/// lets the hand maker mark the trace, and scores the trace. A replay's teacher samples (`inputs.teacher`,
/// a runtime input) are checked with the options they join. Writes none of the specification's output
/// files (the caller's: they depend on its front-end). Throws InvalidArgument when `inputs` gives no device
/// to run on, no teacher for a replay or teacher samples out of range, or no hand maker when the simulated
/// writer writes; DeviceNotFound; and what `run_trial` throws.
[[nodiscard]] TrialRun run_whole_trial(const Checked<WholeTrial>& trial, const Scene& scene,
                                       const TrialRunInputs& inputs = {});

/// A thin wrapper of `run_whole_trial` for a trial of the specification's defaults: creates the device
/// (unless `inputs.device` is given), builds the whole trial of the checked `spec` for its figures
/// (`build_whole_trial(spec, device.info())`, the one builder) and runs it. `spec` was checked once by its
/// front-end (`Checked<TrialSpec>::check`, or the parsers of trial_spec.hpp). Throws what
/// `build_whole_trial` and `run_whole_trial` throw, and InvalidArgument when `inputs` gives neither a device
/// nor a registry.
[[nodiscard]] TrialRun run_trial_spec(const Checked<TrialSpec>& spec, const Scene& scene,
                                      const TrialRunInputs& inputs = {});

}  // namespace calligraphy
