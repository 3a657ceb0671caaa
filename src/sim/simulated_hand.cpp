// A simulated writer as a trial's hand (simulated_hand.hpp).
#include "calligraphy/sim/simulated_hand.hpp"

#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy {

void SimulationOptions::validate() const {
  writer.validate();
  device.validate();
}

SimulatedHand::SimulatedHand(HandPort& port, const Scene& scene, const WriterProfile& profile,
                             std::uint64_t seed)
    : port_(port), writer_(scene, profile, seed) {
  port_.attach_hand(&writer_);
}

SimulatedHand::~SimulatedHand() { release(); }

void SimulatedHand::observe(const RenderOutput& output, const DeviceState& pen) {
  writer_.observe(output, pen);
}

bool SimulatedHand::stopped() const noexcept { return writer_.done(); }

bool SimulatedHand::finished() const noexcept { return writer_.done(); }

void SimulatedHand::advance(double dt_s) { port_.advance(dt_s); }

void SimulatedHand::release() noexcept { port_.attach_hand(nullptr); }

const WriterLog& SimulatedHand::log() const { return writer_.log(); }

std::unique_ptr<SimulatedHand> simulated_hand_for(HapticDevice& device, const Scene& scene,
                                                  const WriterProfile& profile, std::uint64_t seed) {
  // Found once, here: the trial never asks what its device is.
  HandPort* const port = device.hand_port();
  if (port == nullptr) return nullptr;
  return std::make_unique<SimulatedHand>(*port, scene, profile, seed);
}

TrialResult run_trial(HapticDevice& device, const Scene& scene, const TrialOptions& options,
                      const SimulationOptions& simulation, std::optional<WriterLog>* writer_log) {
  simulation.validate();
  const std::unique_ptr<SimulatedHand> hand =
      simulated_hand_for(device, scene, simulation.writer, simulation.seed);
  TrialResult result = run_trial(device, scene, options, hand.get());
  if (writer_log != nullptr) {
    writer_log->reset();
    if (hand) *writer_log = hand->log();
  }
  return result;
}

TrialResult run_trial(const DeviceRegistry& registry, std::string_view device_name, const Scene& scene,
                      const TrialOptions& options, const SimulationOptions& simulation,
                      std::optional<WriterLog>* writer_log) {
  options.validate();  // before a device is created (and possibly opened by its backend)
  simulation.validate();
  const std::unique_ptr<HapticDevice> device = registry.create(device_name);
  return run_trial(*device, scene, options, simulation, writer_log);
}

TrialResult run_simulated_trial(const Scene& scene, const TrialOptions& options,
                                const SimulationOptions& simulation, std::optional<WriterLog>* writer_log) {
  options.validate();
  simulation.validate();
  SimulatedDevice device(simulation.device);
  SimulatedHand hand(device, scene, simulation.writer, simulation.seed);
  TrialResult result = run_trial(device, scene, options, &hand);
  if (writer_log != nullptr) *writer_log = hand.log();
  return result;
}

}  // namespace calligraphy
