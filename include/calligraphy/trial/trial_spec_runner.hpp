#pragma once
/// \file trial_spec_runner.hpp
/// The one runner of a trial specification (trial_spec.hpp), which `calligraphy trial`, the trainer, study
/// sessions and Python call: the checked specification becomes the runner's `TrialOptions`
/// (`trial_options`), its device is created from a registry (or given), and when the simulated writer writes,
/// the caller's hand maker (TrialRunInputs::hand_maker: sim's `SimulatedWriting`) makes the hand that
/// `run_trial` (runner.hpp) is given: simulation is an input to the trial, never part of it. The result
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

namespace calligraphy {

/// What a trial needs beyond its specification: what only its caller has. Every member may stay empty.
struct TrialRunInputs {
  /// Where `TrialSpec::device` is created (not owned): its owner's registry, filled with the backends it
  /// offers (standard_device_registry() and its own). Required unless `device` is given.
  const DeviceRegistry* registry = nullptr;
  /// A device the caller made (not owned; opened here when it is not open, closed at the end), used
  /// instead of creating `TrialSpec::device` (e.g. a simulated device with the caller's parameters).
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
  /// The force law to run with instead of the one made from the specification (its default stiffnesses
  /// fitted to the device): a study condition's (condition_force_law), or Python's tuning; taken as given.
  /// Its guidance switch, and with guidance on its mode, must be the specification's (InvalidArgument
  /// otherwise); a replay's teacher is the runner's to set (above).
  std::optional<ForceLawParameters> force_law;
  std::optional<SafetyChainParameters> safety;   ///< instead of the defaults
  std::optional<PassivityParameters> passivity;  ///< instead of the defaults
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
  DeviceInfo device;              ///< the device's figures
  bool simulated_writer = false;  ///< the simulated writer wrote (the hand maker's hand; else a person)
  WritingMetrics metrics;         ///< the one metrics record of the trace (writing_metrics.hpp)
};

/// The runner's options for the checked `spec` on a device with figures `device`: guidance, mode, gain, rate,
/// pacing, real-time settings and duration from `spec`; the force law's default stiffnesses capped at the
/// device's stable maximum (`DeviceInfo::max_stiffness_n_per_m`), so that defaults never draw the renderer's
/// over-limit warning. Valid as they are, but for a replay, whose teacher the runner adds (it then checks
/// them); `run_trial_spec` takes them unchecked otherwise (tests/trial_spec_test.cpp walks that promise).
[[nodiscard]] TrialOptions trial_options(const Checked<TrialSpec>& spec, const DeviceInfo& device);

/// Who writes `spec` on a device: `TrialWriter::simulated` or `person` as stated, else the simulated writer
/// when `simulated_writer_can_move` (the device has a hand port), a person otherwise. Throws
/// InvalidArgument naming writer (--writer) when the simulated writer is asked to write on a device it
/// cannot move.
[[nodiscard]] bool simulated_writer_writes(const TrialSpec& spec, bool simulated_writer_can_move);

/// Runs the trial `spec` states on `scene` (laid out from `spec.characters` by the caller, who knows where
/// characters come from). `spec` was checked once by its front-end (`Checked<TrialSpec>::check`, or the
/// parsers of trial_spec.hpp); nothing of it is validated again down to the renderer. Creates the device
/// (unless given), asks `inputs.hand_maker` for the simulated writer's hand when it writes, runs `run_trial`,
/// lets the hand maker mark the trace, and scores the trace. What `inputs` gives instead of the
/// specification's (a force law, a safety chain, a passivity controller) and a replay's teacher are checked
/// here. Writes none of `spec`'s output files (the caller's: they depend on its front-end). Throws
/// InvalidArgument when `inputs` gives neither a device nor a registry, no teacher for a replay, or no hand
/// maker when the simulated writer writes, or a part of `inputs` out of range; DeviceNotFound; and what
/// `run_trial` throws.
[[nodiscard]] TrialRun run_trial_spec(const Checked<TrialSpec>& spec, const Scene& scene,
                                      const TrialRunInputs& inputs = {});

}  // namespace calligraphy
