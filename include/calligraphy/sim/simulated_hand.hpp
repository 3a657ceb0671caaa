#pragma once
/// \file simulated_hand.hpp
/// Simulation as an input to a trial: a `SimulatedWriter` holding the stylus of a device it can move (a
/// `HandPort`: the simulated device, the emulated Phantom), given to `run_trial` as its `TrialHand`. The
/// trial itself knows nothing of simulation; tests, experiments and the study's simulated subjects make the
/// hand, run the trial and read the writer's log here.
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "calligraphy/trial/hand.hpp"
#include "calligraphy/trial/runner.hpp"

namespace calligraphy {

/// Who writes in a simulated trial, and on what.
struct SimulationOptions {
  WriterProfile writer = WriterProfile::novice();  ///< the simulated writer
  SimulatedDeviceParameters device{};              ///< the device `run_simulated_trial` creates
  std::uint64_t seed = 0;                          ///< seeds the writer's bias, noise and tremor

  /// Throws InvalidArgument naming the field (WriterProfile::validate, SimulatedDeviceParameters::validate).
  void validate() const;
};

/// A simulated writer on a device's hand port: the hand of a lock-step (or real-time) trial.
class SimulatedHand final : public TrialHand {
 public:
  /// Attaches a `SimulatedWriter(scene, profile, seed)` to `port`; `port` and `scene` must outlive the
  /// hand. Throws InvalidArgument for a bad profile.
  SimulatedHand(HandPort& port, const Scene& scene, const WriterProfile& profile, std::uint64_t seed);
  ~SimulatedHand() override;  ///< lets go of the stylus

  void observe(const RenderOutput& output, const DeviceState& pen) override;
  [[nodiscard]] bool stopped() const noexcept override;
  /// True once stopped: the writer stops only when it has written its plan (it moves on past a stroke it
  /// gives up on, docs/writer.md "Give-up and retries").
  [[nodiscard]] bool finished() const noexcept override;
  void advance(double dt_s) override;
  void release() noexcept override;

  /// What the writer did, attempt by attempt (final once the trial has returned).
  [[nodiscard]] const WriterLog& log() const;
  [[nodiscard]] const SimulatedWriter& writer() const noexcept { return writer_; }

 private:
  HandPort& port_;
  SimulatedWriter writer_;
};

/// A simulated hand for `device` when a writer can move it (it has a `HandPort`), else nullptr (a person
/// moves it). Throws InvalidArgument for a bad profile.
[[nodiscard]] std::unique_ptr<SimulatedHand> simulated_hand_for(HapticDevice& device, const Scene& scene,
                                                                const WriterProfile& profile,
                                                                std::uint64_t seed);

/// The trial on `device`, written by `simulation`'s writer when the device has a hand port (else by a
/// person, in real time; `simulation.device` is not used). `writer_log`, when given, receives the writer's
/// log (reset: no writer wrote). Throws what `run_trial` throws.
TrialResult run_trial(HapticDevice& device, const Scene& scene, const TrialOptions& options,
                      const SimulationOptions& simulation, std::optional<WriterLog>* writer_log = nullptr);

/// The trial on the device called `device_name` in `registry` (e.g. "simulated" in a
/// `standard_device_registry()`), created for this trial, written by `simulation`'s writer when the device
/// has a hand port (else by a person, in real time). `writer_log`, when given, receives the writer's log
/// (reset: no writer wrote). Throws DeviceNotFound naming the devices that exist when there is none of that
/// name, and what `run_trial` throws.
TrialResult run_trial(const DeviceRegistry& registry, std::string_view device_name, const Scene& scene,
                      const TrialOptions& options, const SimulationOptions& simulation = {},
                      std::optional<WriterLog>* writer_log = nullptr);

/// The trial on a `SimulatedDevice` made from `simulation.device`, written by `simulation`'s writer:
/// lock-step by default, or in real time with `TrialPacing::real_time` (the same trial, paced by the wall
/// clock). `writer_log`, when given, receives the writer's log. Throws what `run_trial` throws.
TrialResult run_simulated_trial(const Scene& scene, const TrialOptions& options,
                                const SimulationOptions& simulation = {},
                                std::optional<WriterLog>* writer_log = nullptr);

}  // namespace calligraphy
