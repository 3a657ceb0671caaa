#include "calligraphy/sim/simulated_writing.hpp"

#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/sim/trace_attempts.hpp"

namespace calligraphy {
namespace {

// The writer's setting names, for an error about one: "hand_stiffness_n_per_m, ...".
std::string writer_keys() {
  std::string keys;
  for (const std::string& key : writer_parameter_names()) keys += (keys.empty() ? "" : ", ") + key;
  return keys;
}

}  // namespace

WriterProfile writer_profile_of(const TrialSpec& spec) {
  WriterProfile profile;
  try {
    profile = writer_profile(spec.writer_profile);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(std::string("writer_profile (--writer-profile): ") + e.what());
  }
  for (const WriterSetting& setting : spec.writer_parameters) {
    try {
      set_writer_parameter(profile, setting.key, setting.value);
    } catch (const InvalidArgument& e) {
      std::string message = e.what();
      if (message.find("known:") == std::string::npos) message += "; known keys: " + writer_keys();
      throw InvalidArgument("writer_parameters (--writer-param): '" + writer_setting_text(setting) +
                            "': " + message);
    }
  }
  return profile;
}

SimulatedWriting::SimulatedWriting(const TrialSpec& spec, const std::optional<WriterProfile>& profile)
    : profile_(profile ? *profile : writer_profile_of(spec)) {
  profile_.validate();
}

std::unique_ptr<TrialHand> SimulatedWriting::make_hand(HapticDevice& device, const Scene& scene,
                                                       std::uint64_t seed) {
  log_.reset();
  std::unique_ptr<SimulatedHand> hand = simulated_hand_for(device, scene, profile_, seed);
  if (!hand) {
    throw InvalidArgument("the simulated writer cannot move the device '" + device.info().model +
                          "' (it has no hand port)");
  }
  hand_ = hand.get();
  return hand;
}

void SimulatedWriting::after_trial(TrialResult& result) {
  if (hand_ == nullptr) return;
  log_ = hand_->log();
  hand_ = nullptr;
  // The writer knows which stroke each pen-down segment meant, and which it wrote again.
  mark_writer_attempts(result.trace, *log_);
}

RecordedTrial recorded_trial(const TrialSpec& spec, const TrialRun& run, const SimulatedWriting& writing,
                             const Scene& scene, const std::string& teacher_sha256) {
  return recorded_trial(spec, run.options, run.simulated_writer ? &writing.profile() : nullptr, scene,
                        teacher_sha256);
}

SimulatedWriting recorded_writing(const RecordedTrial& recorded) {
  return SimulatedWriting(recorded.spec, recorded.writer);
}

}  // namespace calligraphy
