#pragma once
/// \file whole_trial.hpp
/// The whole trial: its specification (trial_spec.hpp: characters, device, guidance, writer, pacing, rate,
/// watchdog, duration) with every value the renderer and the device run with (the force law with its
/// guidance law, the safety chain, the passivity controller) and what the simulated writer and a simulated
/// device are made of when they are given. One builder makes it (`build_whole_trial`) from a checked
/// specification and the figures of the device it runs on, with the parts a front-end gives instead of the
/// defaults (a study condition's force law, Python's tuning, a record's parts); it checks it once, and
/// `run_whole_trial` (trial_spec_runner.hpp) takes the checked value as it is. What only the caller has
/// (the device, a registry, a replay's teacher samples, the hand maker, a stop flag, a display) is apart
/// from it (`TrialRunInputs`). A trial record is a whole trial with its provenance (`RecordedTrial`,
/// recorded_trial.hpp). Lengths in m, forces in N, times in s.
#include <optional>

#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// Everything that decides what a trial does but the characters' data and the caller's handles.
struct WholeTrial {
  /// The specification. Its `acceptance` is the force law's (a study condition's quiz sets the one the
  /// trial runs with: the builder states it here).
  TrialSpec spec;
  /// The force law the renderer runs: its guidance switch and, with guidance on, its mode are the
  /// specification's. A replay's teacher trajectory is not held here (the builder clears it): it is the
  /// runner's input (`TrialRunInputs::teacher`), named by `spec.teacher` or kept by its front-end.
  ForceLawParameters force_law;
  SafetyChainParameters safety;  ///< 0 peak and continuous forces stand for the device's
  PassivityParameters passivity;
  /// The profile the simulated writer writes with when it is given whole (a record's, for sim's
  /// `recorded_writing`); nullopt: the one the hand maker makes of the specification (or a person writes).
  /// Never given for a trial a person writes (`spec.writer` person).
  std::optional<WriterProfile> writer;
  /// The physics of a simulated device of the caller's own (Python's `simulate_trial(device=...)`, a
  /// record's); nullopt: the device the registry makes of `spec.device`. Given only for `spec.device`
  /// "simulated"; the runner makes that device when its caller gives none.
  std::optional<SimulatedDeviceParameters> simulated_device;

  /// Throws InvalidArgument naming the part at fault ("trial", "force_law", "safety", "passivity",
  /// "writer", "simulated_device") and what its own `validate` says: the specification as
  /// `TrialSpec::validate` checks it (a replay's teacher from the file `spec.teacher` names, or samples when
  /// it names none), each part as its struct validates it (a replay's law with a stand-in teacher: the
  /// teacher is checked when the runner is given it), a force law whose guidance switch or mode is not the
  /// specification's or whose acceptance is not `spec.acceptance`, a writer profile for a person's trial,
  /// and simulated device physics for a device that is not "simulated".
  void validate() const;
};

/// The parts of a whole trial its front-end gives instead of the defaults the specification implies; every
/// member may stay empty.
struct WholeTrialParts {
  /// The force law as given (no stiffness fitted to the device): a study condition's
  /// (`study_detail::condition_force_law`), Python's tuning, a record's. Its acceptance replaces the
  /// specification's; its guidance switch and mode must be the specification's.
  std::optional<ForceLawParameters> force_law{};
  std::optional<SafetyChainParameters> safety{};                ///< instead of the defaults
  std::optional<PassivityParameters> passivity{};               ///< instead of the defaults
  std::optional<WriterProfile> writer{};                        ///< WholeTrial::writer
  std::optional<SimulatedDeviceParameters> simulated_device{};  ///< WholeTrial::simulated_device
};

/// The force law `spec` states on a device with figures `device`: guidance switch, mode and the mode's
/// parameters, guidance stiffness and acceptance from `spec`; the default stiffnesses capped at the device's
/// stable maximum (`DeviceInfo::max_stiffness_n_per_m`, 0: no limit), so that defaults never draw the
/// renderer's over-limit warning; a stiffness set on purpose is kept. Valid as it is but for a replay's law,
/// which has no teacher yet (the runner's to add).
[[nodiscard]] ForceLawParameters stated_force_law(const TrialSpec& spec, const DeviceInfo& device);

/// The one builder of a whole trial: `spec` with the force law it states on the device of figures `device`
/// (`stated_force_law`; the figures of the device the trial will run on: the caller creates it first, or
/// knows it) and the default safety chain and passivity controller, each replaced by the part `parts`
/// gives; a given force law's acceptance becomes the specification's and a replay's teacher trajectory is
/// cleared. Checked once (`WholeTrial::validate`): throws InvalidArgument naming the part at fault before
/// any device is opened; the runner takes the result as it is.
[[nodiscard]] Checked<WholeTrial> build_whole_trial(const Checked<TrialSpec>& spec, const DeviceInfo& device,
                                                    WholeTrialParts parts = {});

}  // namespace calligraphy
