#pragma once
// The schema of session.json (docs/experiments.md, "Sessions"): its parts as the JSON lays them out, from
// which manifest_from_json reads it and `calligraphy schema session` prints its JSON Schema. Internal.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/options.hpp"

namespace calligraphy {

namespace study_detail {

/// The format name and the newest version of session.json. Version 2 counts a planned trial's block and
/// item from 1, as its index and repetition; version 1 (older folders) counted them from 0. Version 3 calls a
/// person writing `person`, as the trial's specification and the options do; versions 1 and 2 said `human`.
inline constexpr const char* kSessionFormat = "calligraphy-study-session";
inline constexpr std::int64_t kSessionVersion = 3;
/// The first version that calls a person writing `person`.
inline constexpr std::int64_t kSessionPersonVersion = 3;

/// Who wrote a session's trials (SessionSetup::writer), as session.json says it: `human` is how versions 1
/// and 2 said `person`, and a version-3 file that says it is refused (manifest_from_json).
enum class WriterKind { simulated, person, human };

struct ManifestSubject {
  std::string id;
  std::int64_t number = 0;
};

/// A planned trial as the plan writes it: every count 1-based.
struct ManifestPlannedTrial {
  std::int64_t index = 1;
  StudyPhase phase = StudyPhase::test;
  std::int64_t block = 1;
  std::string condition;
  std::string characters;
  std::int64_t item = 1;
  std::int64_t repetition = 1;
  double break_before_s = 0.0;
  std::string file;
  std::string item_set;
  std::string sequence;
  std::int64_t period = 0;
  std::string trained_condition;
};

/// The protocol copy a session keeps.
struct ManifestProtocol {
  std::string name;
  std::string path;
  std::string sha256;
  std::string text;
};

/// session.json as its JSON lays it out.
struct ManifestDocument {
  std::string format = kSessionFormat;  // the schema's constant
  std::int64_t version = kSessionVersion;
  std::string created_utc;
  ManifestSubject subject;
  std::int64_t session_number = 1;
  std::string group;
  std::string device;
  WriterKind writer = WriterKind::simulated;
  std::string writer_profile;
  std::uint64_t writer_seed = 0;
  WriterLearning writer_learning = WriterLearning::none;
  bool individual_differences = false;  ///< sessions made before subjects differed: every one its profile
  TrialPacing pacing = TrialPacing::automatic;
  LibraryBuild library;
  ManifestProtocol protocol;
  std::vector<ManifestPlannedTrial> plan;
  PreviousSession previous_session;
  std::string study_id;
};

}  // namespace study_detail

template <>
struct EnumTable<study_detail::WriterKind> {
  static constexpr std::string_view name = "WriterKind";
  static constexpr std::array<EnumEntry<study_detail::WriterKind>, 3> entries{{
      {study_detail::WriterKind::simulated, "simulated", "the simulated writer of writer_profile"},
      {study_detail::WriterKind::person, "person", "a person at the device"},
      {study_detail::WriterKind::human, "human", "a person at the device, in versions 1 and 2 only"},
  }};
};

#define CALLIGRAPHY_SCHEMA_OF(Type) \
  template <>                       \
  struct SchemaOf<Type> {           \
    static const Schema& get();     \
  };
CALLIGRAPHY_SCHEMA_OF(study_detail::ManifestSubject)
CALLIGRAPHY_SCHEMA_OF(study_detail::ManifestPlannedTrial)
CALLIGRAPHY_SCHEMA_OF(study_detail::ManifestProtocol)
CALLIGRAPHY_SCHEMA_OF(LibraryBuild)
CALLIGRAPHY_SCHEMA_OF(PreviousSession)
CALLIGRAPHY_SCHEMA_OF(study_detail::ManifestDocument)
#undef CALLIGRAPHY_SCHEMA_OF

}  // namespace calligraphy
