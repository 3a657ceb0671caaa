#include "study/manifest_schema.hpp"

#include <nlohmann/json.hpp>
#include <vector>

namespace calligraphy {
namespace {

// The most trials a plan holds (protocol.hpp), the range of a planned trial's counts.
constexpr auto kMaxTrials = static_cast<std::int64_t>(kMaxPlannedTrials);
// A protocol's names of sets and conditions: 1 to 32 letters, digits, '_' or '-'.
constexpr std::string_view kLabelPattern = "^[A-Za-z0-9_-]{1,32}$";

}  // namespace

const Schema& SchemaOf<study_detail::ManifestSubject>::get() {
  using S = study_detail::ManifestSubject;
  static const std::vector<SchemaField> fields{
      with_pattern(
          "^[A-Za-z0-9_-]{1,64}$",
          string_field<&S::id>("id", {.doc = "the subject's id: 1 to 64 letters, digits, '_' or '-'"})),
      integer_field<&S::number>("number", 0, 1000000000,
                                {.doc = "1-based number for the counterbalancing; 0: unknown"}),
  };
  static const Schema schema{
      .name = "SessionSubject", .doc = "who the session is of", .fields = fields, .defaults = default_of<S>};
  return schema;
}

const Schema& SchemaOf<study_detail::ManifestPlannedTrial>::get() {
  using T = study_detail::ManifestPlannedTrial;
  // The item's set and the crossover keys are written only when they have a value (plan_session): a plan
  // made before item sets, or of a protocol without them, lacks them in any version.
  static const std::vector<SchemaField> fields{
      integer_field<&T::index>("index", 1, kMaxTrials, {.doc = "1-based position in the session"}),
      enum_field<&T::phase>("phase", {.doc = "the phase the trial belongs to"}),
      integer_field<&T::block>("block", 1, kMaxTrials,
                               {.doc = "1-based block of the session (version 1: 0-based)"}),
      string_field<&T::condition>("condition", {.doc = "a condition of the protocol"}),
      with_min_length(1, string_field<&T::characters>(
                             "characters", {.doc = "the characters written (UTF-8), at least one"})),
      integer_field<&T::item>("item", 1, kMaxTrials,
                              {.doc = "1-based item of its phase's list (version 1: 0-based)"}),
      integer_field<&T::repetition>("repetition", 1, kMaxTrials,
                                    {.doc = "1-based: the how-many-th time the item is written"}),
      omissible(number_field<&T::break_before_s>("break_before_s", {.low = 0.0, .high = 86400.0},
                                                 {.unit = "s", .doc = "rest before the trial"})),
      omissible(string_field<&T::file>("file", {.doc = "the trial's file stem in trials/ (as written)"})),
      omissible(with_pattern(
          kLabelPattern,
          string_field<&T::item_set>("item_set", {.doc = "the item's set: 1 to 32 letters, digits, "
                                                         "'_' or '-'; absent: no set"}))),
      omissible(with_pattern(
          "^[A-Z]{1,26}$",
          string_field<&T::sequence>(
              "sequence", {.doc = "the subject's crossover: 1 to 26 letters A-Z, the conditions in period "
                                  "order; absent: no crossover"}))),
      omissible(integer_field<&T::period>(
          "period", 1, 26, {.doc = "the crossover period training the item's set; absent (0): none"})),
      omissible(with_pattern(
          kLabelPattern,
          string_field<&T::trained_condition>(
              "trained_condition", {.doc = "the condition the item is trained under; absent: none"}))),
  };
  static const Schema schema{.name = "PlannedTrial",
                             .doc = "one planned trial (the plan a resumed session follows)",
                             .fields = fields,
                             .defaults = default_of<T>};
  return schema;
}

const Schema& SchemaOf<study_detail::ManifestProtocol>::get() {
  using P = study_detail::ManifestProtocol;
  static const std::vector<SchemaField> fields{
      string_field<&P::name>("name", {.doc = "the protocol's name (as in its copy)"}),
      string_field<&P::path>("path", {.doc = "where the protocol was read from"}),
      string_field<&P::sha256>("sha256",
                               {.doc = "lower-case hex SHA-256 of the copy", .source = "FIPS 180-4"}),
      string_field<&P::text>("text", {.doc = "the protocol file's text, the session's copy"}),
  };
  static const Schema schema{.name = "SessionProtocol",
                             .doc = "the protocol the session follows, kept whole",
                             .fields = fields,
                             .defaults = default_of<P>};
  return schema;
}

const Schema& SchemaOf<LibraryBuild>::get() {
  static const std::vector<SchemaField> fields{
      string_field<&LibraryBuild::version>("version", {.doc = "the project's version"}),
      string_field<&LibraryBuild::build_type>("build_type", {.doc = "CMake build type"}),
      string_field<&LibraryBuild::compiler>("compiler", {.doc = "the compiler and its version"}),
      string_field<&LibraryBuild::cxx_standard>("cxx_standard", {.doc = "the value of __cplusplus"}),
  };
  static const Schema schema{.name = "LibraryBuild",
                             .doc = "the library build that made the session",
                             .fields = fields,
                             .defaults = default_of<LibraryBuild>};
  return schema;
}

const Schema& SchemaOf<PreviousSession>::get() {
  using P = PreviousSession;
  static const std::vector<SchemaField> fields{
      string_field<&P::session_id>("session_id", {.doc = "its folder's name, beside this one"}),
      string_field<&P::ended_utc>("ended_utc", {.doc = "when its last trial ended (ISO 8601, UTC)",
                                                .format = StringFormat::utc_time}),
      number_field<&P::delay_s>("delay_s", {.low = 0.0, .high = 1e9},
                                {.unit = "s", .doc = "the protocol's delay before this session"}),
      // Any finite time: a clock that differs between the sessions is recorded as it was measured.
      number_field<&P::elapsed_s>("elapsed_s", {.low = -1e15, .high = 1e15},
                                  {.unit = "s", .doc = "from ended_utc to this session's creation"}),
      enum_field<&P::delay>("delay", {.doc = "how the protocol's delay before this session was kept"}),
      omissible(string_field<&P::session_sha256>(
          "session_sha256", {.doc = "lower-case hex SHA-256 of its session.json when this session was made; "
                                    "absent in sessions made before it was recorded",
                             .source = "FIPS 180-4"})),
  };
  static const Schema schema{.name = "PreviousSession",
                             .doc = "the session before this one in the subject's series",
                             .fields = fields,
                             .defaults = default_of<P>};
  return schema;
}

const Schema& SchemaOf<study_detail::ManifestDocument>::get() {
  using D = study_detail::ManifestDocument;
  // Keys added since the first folders without a new version (the session number, the group, the study id,
  // writer learning, individual differences) are omissible: a folder made before them lacks them and reads
  // as it meant. `previous_session` is written for a session after the first alone, `study_id` only when the
  // study folder has an identity.
  static const std::vector<SchemaField> fields{
      string_field<&D::format>("format", {.doc = "the format's name", .format = StringFormat::constant}),
      integer_field<&D::version>("version", 1, study_detail::kSessionVersion,
                                 {.doc = "the format's version"}),
      string_field<&D::created_utc>("created_utc", {.doc = "when the session was made (ISO 8601, UTC)",
                                                    .format = StringFormat::utc_time}),
      object_field<&D::subject>("subject", {.doc = "the subject"}),
      omissible(integer_field<&D::session_number>(
          "session_number", 1, 20, {.doc = "which of the protocol's sessions this one is (1-based)"})),
      omissible(string_field<&D::group>("group", {.doc = "the subject's group; \"\" within subjects"})),
      string_field<&D::device>("device", {.doc = "the device's name in the device registry"}),
      enum_field<&D::writer>("writer", {.doc = "who wrote the trials (human: versions 1 and 2's person)"}),
      string_field<&D::writer_profile>("writer_profile", {.doc = "the simulated writer's profile"}),
      omissible(unsigned_field<&D::writer_seed>("writer_seed", {.doc = "the simulated subject's seed"})),
      omissible(enum_field<&D::writer_learning>("writer_learning",
                                                {.doc = "how a simulated subject learns between trials"})),
      omissible(boolean_field<&D::individual_differences>(
          "individual_differences", {.doc = "a simulated subject differs from the others of its profile"})),
      enum_field<&D::pacing>("pacing", {.doc = "how the trials' ticks are paced"}),
      object_field<&D::library>("library", {.doc = "the library build that made the session"}),
      object_field<&D::protocol>("protocol", {.doc = "the protocol's copy, path and SHA-256"}),
      with_item_count(
          1, kMaxPlannedTrials,
          object_list_field<&D::plan>("plan", {.doc = "the planned trials, in order (at least one)"})),
      omissible(object_field<&D::previous_session>(
          "previous_session", {.doc = "the session before this one; exactly for a session after the first"})),
      omissible(with_pattern(
          "^[0-9a-f]{32}$",
          string_field<&D::study_id>("study_id", {.doc = "the study folder's identity: 32 "
                                                         "lower-case hex digits; absent: none"}))),
  };
  static const Schema schema{.name = "SessionManifest",
                             .doc = "a session folder's session.json",
                             .fields = fields,
                             .defaults = default_of<D>};
  return schema;
}

const Schema& session_manifest_schema() { return SchemaOf<study_detail::ManifestDocument>::get(); }

std::string session_manifest_json_schema_text() {
  nlohmann::ordered_json root = nlohmann::ordered_json::parse(
      json_schema_text(session_manifest_schema(), "https://calligraphy.invalid/schema/session.json",
                       "calligraphy session.json (docs/experiments.md, \"Sessions\")", true));
  // The rules between values (a plan's indexes in order, its conditions the protocol's, the copy's SHA-256,
  // the previous session exactly after the first) are the reader's alone.
  auto& planned = root["$defs"]["PlannedTrial"]["properties"];
  // Version 1 counted a planned trial's block and item from 0: each range by the document's version.
  nlohmann::ordered_json from_zero = nlohmann::ordered_json::object();
  nlohmann::ordered_json from_one = nlohmann::ordered_json::object();
  for (const char* key : {"block", "item"}) {
    planned[key]["minimum"] = 0;
    from_zero[key] = {{"maximum", kMaxTrials - 1}};
    from_one[key] = {{"minimum", 1}};
  }

  nlohmann::ordered_json by_version = nlohmann::ordered_json::array();
  by_version.push_back({{"if", {{"properties", {{"version", {{"const", 1}}}}}, {"required", {"version"}}}},
                        {"then", {{"properties", {{"plan", {{"items", {{"properties", from_zero}}}}}}}}},
                        {"else", {{"properties", {{"plan", {{"items", {{"properties", from_one}}}}}}}}}});
  // Versions 1 and 2 called a person `human`; version 3 says `person` only.
  nlohmann::ordered_json spellings = nlohmann::ordered_json::array();
  for (const std::string_view spelling : enum_spellings<study_detail::WriterKind>()) {
    if (spelling != enum_spelling(study_detail::WriterKind::human))
      spellings.push_back(std::string(spelling));
  }
  by_version.push_back({{"if",
                         {{"properties", {{"version", {{"minimum", study_detail::kSessionPersonVersion}}}}},
                          {"required", {"version"}}}},
                        {"then", {{"properties", {{"writer", {{"enum", std::move(spellings)}}}}}}}});
  root["allOf"] = std::move(by_version);
  return root.dump(2) + "\n";
}

}  // namespace calligraphy
