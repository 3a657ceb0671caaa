// GuidanceSchedule (include/calligraphy/render/guidance_schedule.hpp): the one schedule of adaptive guidance.
// Its sequence follows the rules' published formulas, and a study's repetition guidance, which reads the
// previous repetition from its record, gives the same sequence as the schedule the trainer steps in memory.
#include "calligraphy/render/guidance_schedule.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "study/trial_guidance.hpp"

using namespace calligraphy;

namespace {

// What a study's repetition guidance makes of a previous repetition that ran `previous` and deviated by
// `deviation_m` (nullopt: wrote nothing), as its saved record states them.
RepetitionGuidance from_record(const StudyCondition& condition, const RepetitionGuidance& previous,
                               std::optional<double> deviation_m) {
  PlannedTrial earlier;
  earlier.condition = condition.name;
  earlier.characters.push_back(U'十');  // appended: GCC 12 warns wrongly on assigning a literal at -O3
  nlohmann::json record = {
      {"guidance", {{"gain", previous.gain}, {"band_m", previous.band_m}}},
      {"mean_deviation_mm", deviation_m ? nlohmann::json(*deviation_m * 1e3) : nlohmann::json()}};
  const study_detail::PreparedGuidance prepared =
      study_detail::repetition_guidance(condition, &earlier, &record, "record.json");
  RepetitionGuidance made = previous;
  made.gain = prepared.guidance.gain;
  made.band_m = prepared.guidance.band_m;
  if (prepared.guidance.mode) made.mode = *prepared.guidance.mode;
  return made;
}

const std::vector<std::optional<double>> kOutcomes = {0.002, 0.001, std::nullopt, 0.0005, 0.004, 0.0001};

}  // namespace

TEST_CASE("fading follows Emken's rule and a repetition with nothing written brings full guidance back",
          "[guidance][schedule]") {
  GuidanceSchedule schedule;
  schedule.start_gain = 0.5;
  RepetitionGuidance g = schedule.start();
  CHECK(g.gain == 0.5);
  CHECK(g.mode == GuidanceMode::fading);
  const double f = schedule.fading_rule.forgetting_factor, k = schedule.fading_rule.error_gain_per_m;
  double expected = 0.5;
  for (const std::optional<double>& e : kOutcomes) {
    g = schedule.next(g, e);
    expected = e ? std::clamp(f * expected + k * *e, 0.0, 1.0) : 1.0;
    CHECK(g.gain == Approx(expected).epsilon(1e-12));
  }
}

TEST_CASE("a study's repetition guidance from its records is the trainer's schedule in memory",
          "[guidance][schedule]") {
  const StudyProtocol protocol = parse_study_protocol(
      R"({"name": "g", "conditions": [
            {"name": "fade", "mode": "fading", "parameters": {"start_gain": 0.6, "forgetting_factor": 0.7}},
            {"name": "band", "mode": "assist-as-needed",
             "parameters": {"start_band_m": 0.002, "target_error_m": 0.001}},
            {"name": "adapt", "mode": "skill-adaptive", "parameters": {"threshold_m": 0.0015}}],
          "test": {"characters": ["十"], "conditions": ["fade", "band", "adapt"], "repetitions": 1}})",
      "g.json");
  for (const StudyCondition& condition : protocol.conditions) {
    const ConditionMode mode = condition_mode(condition);
    REQUIRE(condition.guidance);
    REQUIRE(condition.guidance->schedule);
    const GuidanceSchedule schedule = *condition.guidance->schedule;
    if (mode == ConditionMode::fading) REQUIRE(schedule.start_gain == 0.6);
    if (mode == ConditionMode::fading) REQUIRE(schedule.fading_rule.forgetting_factor == 0.7);
    if (mode == ConditionMode::assist_as_needed) REQUIRE(schedule.start_band_m == 0.002);
    RepetitionGuidance in_memory = schedule.start();
    RepetitionGuidance from_records = in_memory;
    const study_detail::PreparedGuidance first =
        study_detail::repetition_guidance(condition, nullptr, nullptr, "");
    CHECK(first.guidance.gain == in_memory.gain);
    CHECK(first.guidance.band_m == in_memory.band_m);
    std::vector<double> gains, bands;
    for (const std::optional<double>& e : kOutcomes) {
      in_memory = schedule.next(in_memory, e);
      from_records = from_record(condition, from_records, e);
      INFO("mode " << static_cast<int>(mode));
      CHECK(from_records == in_memory);
      gains.push_back(in_memory.gain);
      bands.push_back(in_memory.band_m);
    }
    // The sequence moves: a check that held for constant guidance would prove nothing.
    if (mode == ConditionMode::fading) CHECK(gains.front() != gains.back());
    if (mode == ConditionMode::assist_as_needed) CHECK(bands.front() != bands.back());
  }
}
