#pragma once
/// \file simulated_writing.hpp
/// The simulated writer of a trial specification (calligraphy/trial/trial_spec.hpp), as the runner's hand
/// maker (`TrialRunInputs::hand_maker`): its profile is the specification's, checked here (the trial layer
/// names a profile and settings; the writer knows them), it makes the `SimulatedHand` the trial asks for, and
/// it keeps what the writer did. Every front-end that runs a specification a simulated writer may write
/// gives one.
#include <cstdint>
#include <memory>
#include <optional>

#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/hand.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// The profile `spec` states for the simulated writer: `spec.writer_profile` with `spec.writer_parameters`
/// applied in turn. The one check of the specification's writer part. Throws InvalidArgument naming
/// writer_profile (--writer-profile) for an unknown profile, and writer_parameters (--writer-param) for an
/// unknown key (listing the known ones) or a value its field refuses (ParameterTable<WriterProfile>).
[[nodiscard]] WriterProfile writer_profile_of(const TrialSpec& spec);

/// The simulated writer of one trial at a time.
class SimulatedWriting final : public TrialHandMaker {
 public:
  /// The writer `spec` states (`writer_profile_of`: throws what it throws), or `profile` instead when given
  /// (a WriterProfile object from Python, a record's; validated: InvalidArgument naming the field).
  explicit SimulatedWriting(const TrialSpec& spec,
                            const std::optional<WriterProfile>& profile = std::nullopt);

  [[nodiscard]] std::unique_ptr<TrialHand> make_hand(HapticDevice& device, const Scene& scene,
                                                     std::uint64_t seed) override;
  /// Marks the trace's attempts from the writer's log (`mark_writer_attempts`) and keeps the log.
  void after_trial(TrialResult& result) override;

  /// The profile the writer writes with (after the settings).
  [[nodiscard]] const WriterProfile& profile() const noexcept { return profile_; }
  /// What the writer did in the last trial, attempt by attempt; nullopt before one ended (or when a person
  /// wrote it).
  [[nodiscard]] const std::optional<WriterLog>& log() const noexcept { return log_; }

 private:
  WriterProfile profile_;
  SimulatedHand* hand_ = nullptr;  // the hand last made, owned by the runner until after_trial
  std::optional<WriterLog> log_;
};

/// What `run` ran for `spec` on `scene` (trial/recorded_trial.hpp), written (when the simulated writer
/// wrote) by `writing`; `teacher_sha256` as the other overload's.
[[nodiscard]] RecordedTrial recorded_trial(const TrialSpec& spec, const TrialRun& run,
                                           const SimulatedWriting& writing, const Scene& scene,
                                           const std::string& teacher_sha256 = {});

/// The simulated writer of `recorded` as it wrote (`RecordedTrial::writer`, its traits and what it had
/// learned folded in): `rerun_trial`'s hand maker for a record the simulated writer wrote. Throws
/// InvalidArgument for a profile out of range.
[[nodiscard]] SimulatedWriting recorded_writing(const RecordedTrial& recorded);

}  // namespace calligraphy
