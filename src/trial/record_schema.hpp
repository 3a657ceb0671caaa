#pragma once
// The schema of a trial record's specification object (recorded_trial.hpp: format, version, the trial, the
// force law with its guidance law, the safety chain, passivity, the writer, the simulated device and the
// scene), from which `calligraphy schema record` prints its JSON Schema. Internal.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

namespace trial_detail {

/// The scene as a record states it.
struct RecordedScene {
  SceneLayout layout;
  std::string sha256;  ///< scene_sha256 of the placed characters
};

/// The specification object of a trial record as its JSON lays it out.
struct RecordDocument {
  std::string format = std::string(kRecordedTrialFormat);  // the schema's constant and default
  std::int64_t version = kRecordedTrialVersion;
  TrialSpec trial;
  ForceLawParameters force_law;
  SafetyChainParameters safety;
  PassivityParameters passivity;
  std::optional<WriterProfile> writer;
  std::optional<SimulatedDeviceParameters> simulated_device;
  RecordedScene scene;
  std::string library_version;
  std::string teacher_sha256;  ///< a replay's teacher recording's SHA-256; empty: none read
};

/// The first version of a trial record whose force law's acceptance has the StrokeAcceptance field `name`
/// (4 for the fields after the eighth, 5 for the end gap's floor, 7 for the centred rule, 8 for the miss's
/// least path); an older record runs without it (recorded_trial.cpp).
[[nodiscard]] int acceptance_field_version(std::string_view name);

/// The first version of a trial record whose simulated device states its figures (`info`).
inline constexpr int kDeviceInfoRecordVersion = 9;

}  // namespace trial_detail

#define CALLIGRAPHY_SCHEMA_OF(Type) \
  template <>                       \
  struct SchemaOf<Type> {           \
    static const Schema& get();     \
  };
CALLIGRAPHY_SCHEMA_OF(FixedGuidance)
CALLIGRAPHY_SCHEMA_OF(FadingGuidance)
CALLIGRAPHY_SCHEMA_OF(ReplayGuidance)
CALLIGRAPHY_SCHEMA_OF(AssistAsNeededGuidance)
CALLIGRAPHY_SCHEMA_OF(ErrorAmplificationGuidance)
CALLIGRAPHY_SCHEMA_OF(TimingGuidance)
CALLIGRAPHY_SCHEMA_OF(StrokeAcceptance)
CALLIGRAPHY_SCHEMA_OF(NearestPointOptions)
CALLIGRAPHY_SCHEMA_OF(ForceLawParameters)
CALLIGRAPHY_SCHEMA_OF(SafetyChainParameters)
CALLIGRAPHY_SCHEMA_OF(PassivityParameters)
CALLIGRAPHY_SCHEMA_OF(WriterProfile)
CALLIGRAPHY_SCHEMA_OF(DeviceInfo)
CALLIGRAPHY_SCHEMA_OF(SimulatedDeviceParameters)
CALLIGRAPHY_SCHEMA_OF(SceneLayout)
CALLIGRAPHY_SCHEMA_OF(trial_detail::RecordedScene)
CALLIGRAPHY_SCHEMA_OF(trial_detail::RecordDocument)
#undef CALLIGRAPHY_SCHEMA_OF

}  // namespace calligraphy
