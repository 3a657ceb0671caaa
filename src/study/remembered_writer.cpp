#include "study/remembered_writer.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/study/guidance_share.hpp"
#include "core/json_reader.hpp"
#include "study/names.hpp"
#include "study/record_metrics.hpp"
#include "study/saved_sessions.hpp"

namespace calligraphy::study_detail {
namespace fs = std::filesystem;
namespace {

using nlohmann::json;

// The subject's saved trials of one session folder as practice, in planned order.
void practise_session(WriterMemory& memory, const fs::path& folder, const SessionManifest& manifest) {
  const TwoStateRates rates = subject_traits(manifest.setup).learning;
  for (const PlannedTrial& trial : manifest.plan) {
    const fs::path file = SessionLayout::record(folder, trial);
    std::error_code error;
    if (!fs::exists(file, error)) break;  // trials are saved in order: the rest are not yet
    practise_record(memory, read_trial_record(file), file.string(), rates);
  }
}

void remember(WriterMemory& memory, const fs::path& folder, const SessionManifest& manifest, int depth) {
  if (manifest.previous && depth < 20) {
    const fs::path before = beside_session(folder, manifest.previous->session_id);
    remember(memory, before, read_previous_session(folder, manifest), depth + 1);
    consolidate(memory);  // hours or days between the sessions
  }
  practise_session(memory, folder, manifest);
}

}  // namespace

SubjectTraits subject_traits(const SessionSetup& setup) {
  if (setup.writer != TrialWriter::simulated || !setup.individual_differences) return SubjectTraits{};
  return draw_subject_traits(setup.writer_seed);
}

WriterProfile subject_profile(const SessionSetup& setup) {
  return individual_profile(writer_profile(setup.writer_profile), subject_traits(setup));
}

std::vector<WriterSetting> individual_parameters(const SessionSetup& setup) {
  const SubjectTraits traits = subject_traits(setup);
  if (!traits.drawn) return {};
  const WriterProfile own = individual_profile(writer_profile(setup.writer_profile), traits);
  std::vector<WriterSetting> parameters;
  for (const std::string& field : individual_profile_fields())
    parameters.push_back(WriterSetting{field, writer_parameter(own, field)});
  return parameters;
}

void practise_record(WriterMemory& memory, const json& document, const std::string& source,
                     const TwoStateRates& rates) {
  const json_detail::JsonView record(document, "", source);
  std::vector<int> ids;
  std::u32string characters;
  const json_detail::JsonView placed = record.object("scene").array("characters");
  for (std::size_t c = 0; c < placed.size(); ++c) {
    const json_detail::JsonView character = placed.object_at(c);
    const std::u32string decoded = decode_utf8(character.string_or("character", ""));
    if (decoded.size() != 1)
      json_detail::fail(source, character.pointer() + "/character", "expected one character");
    characters += decoded;
    const json_detail::JsonView strokes = character.array("strokes");
    for (std::size_t s = 0; s < strokes.size(); ++s)
      ids.push_back(static_cast<int>(strokes.object_at(s).integer_or("typical_id", 0, 0, 39)));
  }
  if (ids.empty()) json_detail::fail(source, "/scene", "no strokes: the trial's characters are not recorded");
  const json_detail::JsonView force_law = record.object("force_law");
  AssistanceShares shares;
  if (force_law.boolean_or("guidance", false)) {
    const double hand =
        record.object("writer").object("profile").number_or("hand_stiffness_n_per_m", 0.0, -1e12, 1e12);
    if (!(hand > 0.0))
      json_detail::fail(source, "/writer/profile/hand_stiffness_n_per_m",
                        "expected the hand's stiffness > 0");
    // The mode's parameters as recorded (records from before a mode existed hold the defaults).
    ForceLawParameters force;
    const std::string mode = force_law.string_or("guidance_mode", "fixed");
    const std::optional<GuidanceMode> parsed = guidance_mode_from_string(mode);
    if (!parsed)
      json_detail::fail(source, "/force_law/guidance_mode", "unknown guidance mode \"" + mode + "\"");
    constexpr double kLimit = 1e12;  // far beyond any parameter; the force law's validation bounds each
    const auto number = [&](const char* key, double fallback) {
      return force_law.number_or(key, fallback, -kLimit, kLimit);
    };
    force.guidance_stiffness_n_per_m = number("guidance_stiffness_n_per_m", 0.0);
    switch (*parsed) {
      case GuidanceMode::fixed:
        break;
      case GuidanceMode::fading:
        force.guidance_law = FadingGuidance{.gain = number("guidance_gain", 1.0)};
        break;
      case GuidanceMode::replay:
        // A replay's teacher is not in the record; its shares do not depend on it, so a stand-in of two
        // samples passes the parameters' validation.
        force.guidance_law = ReplayGuidance{.teacher_trajectory = {TeacherSample{}, TeacherSample{}}};
        break;
      case GuidanceMode::assist_as_needed:
        force.guidance_law =
            AssistAsNeededGuidance{.band_m = number("assist_band_m", AssistAsNeededGuidance{}.band_m)};
        break;
      case GuidanceMode::error_amplification: {
        const ErrorAmplificationGuidance defaults;
        force.guidance_law = ErrorAmplificationGuidance{
            .gain = number("amplification_gain", defaults.gain),
            .max_force_n = number("amplification_max_force_n", defaults.max_force_n)};
        break;
      }
      case GuidanceMode::timing:
        force.guidance_law =
            TimingGuidance{.speed_m_s = number("timing_speed_m_s", TimingGuidance{}.speed_m_s)};
        break;
    }
    const double deviation_m = study_detail::record_metric(record, "mean_deviation_m").value_or(std::nan(""));
    try {
      shares = guidance_shares(force, hand, deviation_m);
    } catch (const InvalidArgument& e) {
      json_detail::fail(source, "/force_law", e.what());
    }
  }
  practise(memory, ids, characters, shares, rates);
}

WriterMemory remembered(const SessionFolder& session) {
  WriterMemory memory;
  remember(memory, session.path(), session.manifest(), 0);
  return memory;
}

std::vector<int> typical_ids(const Scene& scene) {
  std::vector<int> ids;
  for (const PlacedCharacter& character : scene.characters) {
    for (const PlacedStroke& stroke : character.strokes) ids.push_back(stroke.typical_id);
  }
  return ids;
}

std::vector<WriterSetting> learned_parameters(const WriterMemory& memory, const WriterProfile& own,
                                              const std::vector<int>& ids, const std::u32string& characters) {
  const WriterProfile learned =
      learned_profile(own, WriterProfile::skilled(), writer_skills(memory, ids, characters));
  std::vector<WriterSetting> parameters;
  for (const std::string& field : learned_profile_fields())
    parameters.push_back(WriterSetting{field, writer_parameter(learned, field)});
  return parameters;
}

WriterSkills learn_into(TrialSpec& spec, const WriterMemory& memory, const WriterProfile& own,
                        const Scene& scene, const std::u32string& characters) {
  const std::vector<int> ids = typical_ids(scene);
  for (WriterSetting& parameter : learned_parameters(memory, own, ids, characters))
    spec.writer_parameters.push_back(std::move(parameter));
  return writer_skills(memory, ids, characters);
}

}  // namespace calligraphy::study_detail
