// Study protocols: parsing, errors naming the file and JSON pointer, SHA-256, schedules.
#include <algorithm>
#include <catch2/catch.hpp>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/study/curriculum.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/transfer_set.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "protocol_checks.hpp"

using namespace calligraphy;
using protocol_checks::check_error;
using protocol_checks::subject_id;

namespace {

std::string protocol_text(const std::string& order = "fixed", int repetitions = 2,
                          const std::string& extra = "") {
  return R"({"name": "t", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
             {"name": "C", "mode": "quiz", "quiz": {"acceptance": {"corridor_m": 0.008, "shortfall_fraction": 0.3},
                                                  "hint_after_misses": 2}}],
    "practice": {"characters": ["永"], "condition": "B", "repetitions": 2},
    "test": {"characters": ["大", "山", "木"], "conditions": ["A", "B", "C"], "repetitions": )" +
         std::to_string(repetitions) + R"(},
    "order": {"conditions": ")" +
         order + R"(", "characters": "random", "seed": 5},
    "breaks": {"between_blocks_s": 30, "every_trials": 4, "duration_s": 10})" +
         extra + "}";
}

}  // namespace

TEST_CASE("SHA-256 of the FIPS 180-4 examples", "[study][protocol]") {
  CHECK(sha256_hex("") == "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  CHECK(sha256_hex("abc") == "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  CHECK(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq") ==
        "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  CHECK(sha256_hex(std::string(1000000, 'a')) ==
        "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST_CASE("a protocol is read with every field", "[study][protocol]") {
  const StudyProtocol p = parse_study_protocol(protocol_text(), "p.json");
  CHECK(p.name == "t");
  REQUIRE(p.conditions.size() == 3);
  CHECK(condition_mode(p.conditions[2]) == ConditionMode::quiz);
  REQUIRE(p.conditions[2].quiz);
  CHECK(p.conditions[2].quiz->acceptance.corridor_m == 0.008);
  CHECK(p.conditions[2].quiz->acceptance.shortfall_fraction == 0.3);
  CHECK(p.conditions[2].quiz->acceptance.mean_deviation_m == StrokeAcceptance{}.mean_deviation_m);
  CHECK(p.conditions[2].quiz->start_radius_m == SceneLayout{}.start_radius_m);
  CHECK(p.conditions[2].quiz->hint_after_misses == 2);
  REQUIRE(p.phases.size() == 2);
  CHECK(p.phases[0].kind == StudyPhase::practice);
  CHECK(p.phases[0].items == std::vector<std::u32string>{U"永"});
  CHECK(p.phases[1].kind == StudyPhase::test);
  CHECK(p.phases[1].items == std::vector<std::u32string>{U"大", U"山", U"木"});
  CHECK(p.session_count() == 1);
  CHECK(p.item_order == ItemOrder::random);
  CHECK(p.seed == 5);
  CHECK(p.breaks.every_trials == 4);
  CHECK(condition_mode(p.condition("B")) == ConditionMode::haptic);
  CHECK_THROWS_AS(p.condition("D"), InvalidArgument);
}

TEST_CASE("the shipped paper-table5 protocol is valid", "[study][protocol]") {
  const LoadedProtocol loaded =
      load_study_protocol(std::string(CALLIGRAPHY_SOURCE_DIR) + "/examples/protocols/paper-table5.json");
  REQUIRE(loaded.protocol.phases.size() == 2);
  CHECK(loaded.protocol.phases[1].items.size() == 4);
  CHECK(loaded.protocol.phases[1].conditions == std::vector<std::string>{"vision", "haptic"});
  CHECK(loaded.sha256 == sha256_hex(loaded.text));
}

TEST_CASE("a protocol saved with a UTF-8 byte-order mark is read", "[study][protocol]") {
  // As some editors save JSON; nlohmann-json skips the mark (lexer::skip_bom). The SHA-256 is of the bytes.
  const std::string text = "\xEF\xBB\xBF" + protocol_text();
  CHECK(parse_study_protocol(text, "p.json").name == "t");
  const LoadedProtocol loaded = protocol_from_text(text, "p.json");
  CHECK(loaded.protocol.phases.back().items.size() == 3);
  CHECK(loaded.sha256 == sha256_hex(text));
}

TEST_CASE("protocol errors name the file and the JSON pointer", "[study][protocol]") {
  CHECK_THROWS_WITH(parse_study_protocol("{", "p.json"),
                    Catch::StartsWith("p.json: not valid JSON at byte "));
  check_error(protocol_text("latin"), "/order/conditions", "latin_square");
  check_error(protocol_text("abba", 3), "/test/repetitions", "even");
  check_error(protocol_text("fixed", 0), "/test/repetitions", "got 0");
  check_error(protocol_text("fixed", 2, R"(, "colour": 1)"), "/colour", "unknown key");
  check_error(R"({"name": "t", "conditions": [{"name": "A", "mode": "smell"}], "test": {}})",
              "/conditions/0/mode", "vision");
  check_error(R"({"name": "t", "conditions": [{"name": "A", "mode": "vision"}],
                 "test": {"characters": ["大"], "conditions": ["Z"], "repetitions": 1}})",
              "/test/conditions/0", "no condition is called \"Z\"");
  check_error(
      R"({"name": "t", "conditions": [{"name": "A", "mode": "vision"}, {"name": "A", "mode": "haptic"}],
                 "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})",
      "/conditions/1/name", "twice");
  check_error(R"({"name": "t", "conditions": [{"name": "A", "mode": "vision"}],
                 "test": {"characters": [""], "conditions": ["A"], "repetitions": 1}})",
              "/test/characters/0", "1 to 16 characters");
  check_error(
      R"({"name": "t", "conditions": [{"name": "A", "mode": "vision", "guidance_stiffness_n_per_m": 100}],
                 "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})",
      "/conditions/0/guidance_stiffness_n_per_m", "no guidance");
  check_error(R"({"conditions": []})", "/name", "missing");
  CHECK_THROWS_WITH(load_study_protocol("/nonexistent/p.json"), Catch::Contains("/nonexistent/p.json"));
}

TEST_CASE("an integer in range but written in exponent form is refused saying why", "[study][protocol]") {
  const auto with_seed = [](const std::string& seed) {
    std::string text = protocol_text();
    text.replace(text.find(R"("seed": 5)"), 9, "\"seed\": " + seed);
    return text;
  };
  // 1e19 is below 2^64 - 1: the message must not merely repeat the range it is in.
  check_error(with_seed("1e19"), "/order/seed", "write it in digits");
  check_error(with_seed("-1"), "/order/seed", "0..18446744073709551615, got -1");
  check_error(with_seed("2.5"), "/order/seed", "got 2.5");
  // An exact integer in exponent form below 2^53 is that integer; the full range in digits is read.
  CHECK(parse_study_protocol(with_seed("1e3"), "p.json").seed == 1000);
  CHECK(parse_study_protocol(with_seed("18446744073709551615"), "p.json").seed == 18446744073709551615ULL);
}

TEST_CASE("a plan over the limit of trials per session is refused with its size", "[study][protocol]") {
  // 1,000 strings x 26 conditions x 1,000 repetitions: within every other bound, 26,000,000 trials.
  std::string conditions;
  std::string names;
  for (char c = 'A'; c <= 'Z'; ++c) {
    conditions +=
        std::string(conditions.empty() ? "" : ", ") + R"({"name": ")" + c + R"(", "mode": "vision"})";
    names += std::string(names.empty() ? "" : ", ") + '"' + c + '"';
  }
  std::string items;
  for (int i = 0; i < 1000; ++i) items += std::string(items.empty() ? "" : ", ") + "\"大\"";
  const auto text = [&](int repetitions) {
    return R"({"name": "huge", "conditions": [)" + conditions + R"(], "test": {"characters": [)" + items +
           R"(], "conditions": [)" + names + R"(], "repetitions": )" + std::to_string(repetitions) + "}}";
  };
  CHECK_THROWS_WITH(parse_study_protocol(text(1000), "huge.json"),
                    Catch::StartsWith("huge.json: /test: 26,000,000 trials planned") &&
                        Catch::Contains("limit of 1,000,000 trials per session"));
  // 38 repetitions: 988,000 trials, within the limit, counted without planning them.
  const StudyProtocol within = parse_study_protocol(text(38), "within.json");
  CHECK(planned_trial_count(within) == 988000);
  CHECK(planned_trial_count(within) <= kMaxPlannedTrials);
  CHECK(thousands(26000000) == "26,000,000");
  CHECK(thousands(999) == "999");
  CHECK(thousands(1000) == "1,000");
}

TEST_CASE("fading and replay conditions are read with their parameters", "[study][protocol]") {
  const StudyProtocol p = parse_study_protocol(
      R"({"name": "f", "conditions": [
            {"name": "fade", "mode": "fading",
             "parameters": {"start_gain": 0.8, "forgetting_factor": 0.5, "error_gain_per_m": 100}},
            {"name": "play", "mode": "replay", "parameters": {"max_lead_m": 0.002},
             "teachers": {"大": "teachers/da.json"}},
            {"name": "fade0", "mode": "fading"}],
          "test": {"characters": ["大", "山"], "conditions": ["fade", "play", "fade0"], "repetitions": 1}})",
      "f.json");
  const StudyCondition& fade = p.condition("fade");
  CHECK(condition_mode(fade) == ConditionMode::fading);
  REQUIRE(fade.guidance);
  REQUIRE(fade.guidance->schedule);
  CHECK(std::get<FadingGuidance>(fade.guidance->law).gain == 0.8);
  CHECK(fade.guidance->schedule->start_gain == 0.8);
  CHECK(fade.guidance->schedule->fading_rule.forgetting_factor == 0.5);
  CHECK(fade.guidance->schedule->fading_rule.error_gain_per_m == 100.0);
  CHECK(fade.guidance_parameters.at("start_gain") == 0.8);
  const StudyCondition& play = p.condition("play");
  REQUIRE(play.guidance);
  CHECK(std::get<ReplayGuidance>(play.guidance->law).max_lead_m == 0.002);
  CHECK(play.teachers.at(U"大") == "teachers/da.json");
  CHECK(play.teachers.count(U"山") == 0);  // recorded by the runner
  const StudyCondition& defaults = p.condition("fade0");
  REQUIRE(defaults.guidance);
  REQUIRE(defaults.guidance->schedule);
  CHECK(defaults.guidance->schedule->start_gain == 1.0);
  CHECK(defaults.guidance->schedule->fading_rule.forgetting_factor == FadingRule{}.forgetting_factor);
}

TEST_CASE("fading and replay parameters and teachers are checked naming the JSON pointer",
          "[study][protocol]") {
  const auto with_condition = [](const std::string& condition) {
    return R"({"name": "t", "conditions": [)" + condition +
           R"(], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})";
  };
  check_error(with_condition(R"({"name": "A", "mode": "fading", "parameters": {"end_gain": 0}})"),
              "/conditions/0/parameters/end_gain", "unknown key");
  check_error(with_condition(R"({"name": "A", "mode": "fading", "parameters": {"start_gain": 1.5}})"),
              "/conditions/0/parameters/start_gain", "1.5");
  check_error(with_condition(R"({"name": "A", "mode": "fading", "parameters": {"forgetting_factor": -1}})"),
              "/conditions/0/parameters/forgetting_factor", "-1");
  check_error(with_condition(R"({"name": "A", "mode": "replay", "parameters": {"start_gain": 1}})"),
              "/conditions/0/parameters/start_gain", "unknown key");
  check_error(with_condition(R"({"name": "A", "mode": "replay", "parameters": {"max_lead_m": 0}})"),
              "/conditions/0/parameters/max_lead_m", "in (0, 0.006] m (ReplayGuidance.max_lead_m");
  // A lead the table allows but a trial refuses (beyond R_res) is refused when the protocol is read.
  check_error(with_condition(R"({"name": "A", "mode": "replay", "parameters": {"max_lead_m": 0.05}})"),
              "/conditions/0/parameters/max_lead_m", "at most ForceLawParameters.constraint_radius_m");
  check_error(with_condition(R"({"name": "A", "mode": "haptic", "teachers": {"大": "t.json"}})"),
              "/conditions/0/teachers", "replay");
  check_error(with_condition(R"({"name": "A", "mode": "replay", "teachers": {"山": "t.json"}})"),
              "/conditions/0/teachers/山", "not an item");
  check_error(with_condition(R"({"name": "A", "mode": "replay", "teachers": {"大": ""}})"),
              "/conditions/0/teachers/大", "empty");
}

TEST_CASE("the other guidance schedules are read with their parameters, checked naming the JSON pointer",
          "[study][protocol]") {
  const StudyProtocol p = protocol_from_text(
                              R"({"name": "t", "conditions": [
            {"name": "A", "mode": "assist-as-needed",
             "parameters": {"start_band_m": 0.002, "target_error_m": 0.001, "band_rate": 0.5, "max_band_m": 0.003}},
            {"name": "E", "mode": "error-amplification", "parameters": {"amplification_gain": 0.4, "max_force_n": 0.2}},
            {"name": "S", "mode": "skill-adaptive", "parameters": {"threshold_m": 0.0015}},
            {"name": "T", "mode": "timing", "parameters": {"speed_m_s": 0.02}}],
          "test": {"characters": ["大"], "conditions": ["A", "E", "S", "T"], "repetitions": 1}})",
                              "t.json")
                              .protocol;
  const GuidanceSchedule& band = p.condition("A").guidance.value().schedule.value();
  CHECK(band.start_band_m == 0.002);
  CHECK(band.assist_rule.target_error_m == 0.001);
  CHECK(band.assist_rule.rate == 0.5);
  CHECK(band.assist_rule.max_band_m == 0.003);
  const auto& amplification = std::get<ErrorAmplificationGuidance>(p.condition("E").guidance.value().law);
  CHECK(amplification.gain == 0.4);
  CHECK(amplification.max_force_n == 0.2);
  CHECK(p.condition("S").guidance.value().schedule.value().skill_rule.threshold_m == 0.0015);
  CHECK(std::get<TimingGuidance>(p.condition("T").guidance.value().law).speed_m_s == 0.02);
  for (const ConditionMode mode : condition_modes())
    CHECK(renders_guidance(mode) == (mode != ConditionMode::vision && mode != ConditionMode::quiz));
  const auto with_condition = [](const std::string& condition) {
    return R"({"name": "t", "conditions": [)" + condition +
           R"(], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})";
  };
  check_error(with_condition(R"({"name": "A", "mode": "assist-as-needed", "parameters": {"start_gain": 1}})"),
              "/conditions/0/parameters/start_gain", "unknown key");
  check_error(
      with_condition(
          R"({"name": "A", "mode": "assist-as-needed", "parameters": {"min_band_m": 0.003, "max_band_m": 0.001}})"),
      "/conditions/0/parameters/max_band_m", "min_band_m");
  check_error(with_condition(
                  R"({"name": "A", "mode": "error-amplification", "parameters": {"amplification_gain": 2}})"),
              "/conditions/0/parameters/amplification_gain", "2");
  check_error(with_condition(R"({"name": "A", "mode": "skill-adaptive", "parameters": {"threshold_m": 0}})"),
              "/conditions/0/parameters/threshold_m", "in (0, 0.1] m (SkillAdaptiveRule.threshold_m)");
  check_error(with_condition(R"({"name": "A", "mode": "timing", "parameters": {"speed_m_s": 0}})"),
              "/conditions/0/parameters/speed_m_s", "in (0, 1] m/s (TimingGuidance.speed_m_s)");
  check_error(with_condition(R"({"name": "A", "mode": "haptic", "parameters": {"speed_m_s": 0.1}})"),
              "/conditions/0/parameters", "takes no parameters");
  check_error(with_condition(R"({"name": "A", "mode": "vision", "parameters": {}})"),
              "/conditions/0/parameters", "takes no parameters");
}

TEST_CASE("every mode reads as one display, guidance law and schedule, and spells itself back",
          "[study][protocol][guidance]") {
  struct Case {
    std::string mode;
    std::string fields;  // the condition's keys after its mode
    std::function<void(const StudyCondition&)> check;
  };
  const auto law_of = [](const StudyCondition& c) -> const GuidanceLaw& { return c.guidance.value().law; };
  const auto schedule_of = [](const StudyCondition& c) -> const GuidanceSchedule& {
    return c.guidance.value().schedule.value();
  };
  const std::vector<Case> cases{
      {"vision", "",
       [](const StudyCondition& c) {
         CHECK(!c.quiz);
         CHECK(!c.guidance);
       }},
      {"quiz", R"(, "quiz": {"acceptance": {"corridor_m": 0.007}, "hint_after_misses": 3})",
       [](const StudyCondition& c) {
         REQUIRE(c.quiz);
         CHECK(c.quiz->acceptance.corridor_m == 0.007);
         CHECK(c.quiz->hint_after() == 3);
         CHECK(!c.guidance);
       }},
      {"haptic", R"(, "guidance_stiffness_n_per_m": 300)",
       [&](const StudyCondition& c) {
         CHECK(std::holds_alternative<FixedGuidance>(law_of(c)));
         CHECK(!c.guidance->schedule);
         CHECK(c.guidance->stiffness_n_per_m == std::optional<double>(300.0));
       }},
      {"fading", R"(, "parameters": {"start_gain": 0.7, "forgetting_factor": 0.6, "error_gain_per_m": 120})",
       [&](const StudyCondition& c) {
         CHECK(std::get<FadingGuidance>(law_of(c)).gain == 0.7);
         const GuidanceSchedule& s = schedule_of(c);
         CHECK(s.adapts == AdaptiveGuidance::fading);
         CHECK(s.start_gain == 0.7);
         CHECK(s.fading_rule.forgetting_factor == 0.6);
         CHECK(s.fading_rule.error_gain_per_m == 120.0);
         CHECK(!c.guidance->stiffness_n_per_m);
       }},
      {"replay", R"(, "parameters": {"max_lead_m": 0.002})",
       [&](const StudyCondition& c) {
         const auto& replay = std::get<ReplayGuidance>(law_of(c));
         CHECK(replay.max_lead_m == 0.002);
         CHECK(replay.teacher_trajectory.empty());  // added per trial
         CHECK(!c.guidance->schedule);
         CHECK(replays_teacher(c));
       }},
      {"assist-as-needed", R"(, "parameters": {"start_band_m": 0.0015, "band_rate": 0.4})",
       [&](const StudyCondition& c) {
         CHECK(std::get<AssistAsNeededGuidance>(law_of(c)).band_m == 0.0015);
         const GuidanceSchedule& s = schedule_of(c);
         CHECK(s.adapts == AdaptiveGuidance::assist_as_needed);
         CHECK(s.start_band_m == 0.0015);
         CHECK(s.assist_rule.rate == 0.4);
         CHECK(s.assist_rule.target_error_m == AssistBandRule{}.target_error_m);
       }},
      {"error-amplification", R"(, "parameters": {"amplification_gain": 0.3, "max_force_n": 0.2})",
       [&](const StudyCondition& c) {
         const auto& amplification = std::get<ErrorAmplificationGuidance>(law_of(c));
         CHECK(amplification.gain == 0.3);
         CHECK(amplification.max_force_n == 0.2);
         CHECK(!c.guidance->schedule);
       }},
      {"skill-adaptive",
       R"(, "parameters": {"threshold_m": 0.002, "amplification_gain": 0.35, "max_force_n": 0.25})",
       [&](const StudyCondition& c) {
         CHECK(std::holds_alternative<FixedGuidance>(law_of(c)));
         const GuidanceSchedule& s = schedule_of(c);
         CHECK(s.adapts == AdaptiveGuidance::skill_adaptive);
         CHECK(s.skill_rule.threshold_m == 0.002);
         // The error amplification it chooses carries the protocol's gain and bound.
         RepetitionGuidance amplify = s.start();
         amplify.mode = GuidanceMode::error_amplification;
         const GuidanceLaw chosen = s.law_of(amplify, law_of(c));
         REQUIRE(std::holds_alternative<ErrorAmplificationGuidance>(chosen));
         CHECK(std::get<ErrorAmplificationGuidance>(chosen).gain == 0.35);
         CHECK(std::get<ErrorAmplificationGuidance>(chosen).max_force_n == 0.25);
         CHECK(std::holds_alternative<FixedGuidance>(s.law_of(s.start(), law_of(c))));
       }},
      {"timing", R"(, "parameters": {"speed_m_s": 0.03})",
       [&](const StudyCondition& c) {
         CHECK(std::get<TimingGuidance>(law_of(c)).speed_m_s == 0.03);
         CHECK(!c.guidance->schedule);
       }},
  };
  REQUIRE(cases.size() == condition_modes().size());
  for (const ConditionMode mode : condition_modes()) {
    const auto found =
        std::find_if(cases.begin(), cases.end(), [&](const Case& k) { return k.mode == to_string(mode); });
    REQUIRE(found != cases.end());
    INFO(found->mode);
    const StudyProtocol p = parse_study_protocol(
        R"({"name": "t", "conditions": [{"name": "A", "mode": ")" + found->mode + "\"" + found->fields +
            R"(}], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})",
        "p.json");
    const StudyCondition& read = p.conditions.at(0);
    CHECK(condition_mode(read) == mode);
    CHECK(to_string(condition_mode(read)) == found->mode);
    CHECK(read.guidance.has_value() == renders_guidance(mode));
    found->check(read);
    // The same condition from the mode and the parameters as the protocol gives them.
    const StudyCondition made = condition_from_mode(mode, read.guidance_parameters);
    CHECK(condition_mode(made) == mode);
    CHECK(made.guidance.has_value() == read.guidance.has_value());
    if (made.guidance) {
      CHECK(made.guidance->law == read.guidance->law);
      CHECK(made.guidance->schedule.has_value() == read.guidance->schedule.has_value());
    }
  }
  CHECK_THROWS_WITH(condition_from_mode(ConditionMode::timing, {{"start_gain", 0.5}}),
                    Catch::Contains("start_gain"));
  CHECK_THROWS_WITH(condition_from_mode(ConditionMode::fading, {{"start_gain", 1.5}}),
                    Catch::Contains("FadingGuidance.gain"));
}

TEST_CASE("a quiz condition's acceptance is checked naming the key, and leniency is refused",
          "[study][protocol]") {
  const auto with_quiz = [](const std::string& quiz) {
    return R"({"name": "t", "conditions": [{"name": "A", "mode": "quiz", "quiz": )" + quiz +
           R"(}], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})";
  };
  check_error(with_quiz(R"({"leniency": 1.5})"), "/conditions/0/quiz/leniency", "replaced by \"acceptance\"");
  check_error(with_quiz(R"({"acceptance": {"corridor": 0.005}})"), "/conditions/0/quiz/acceptance/corridor",
              "unknown key");
  check_error(with_quiz(R"({"acceptance": {"mean_deviation_m": 0}})"),
              "/conditions/0/quiz/acceptance/mean_deviation_m", "in (0, 0.1] m");
  check_error(with_quiz(R"({"acceptance": {"corridor_m": 2}})"), "/conditions/0/quiz/acceptance/corridor_m",
              "2");
  check_error(with_quiz(R"({"acceptance": {"shortfall_fraction": 1}})"),
              "/conditions/0/quiz/acceptance/shortfall_fraction", "(0, 1)");
  check_error(with_quiz(R"({"acceptance": {"max_gain_ratio": 0.5}})"),
              "/conditions/0/quiz/acceptance/max_gain_ratio", "0.5");
  check_error(with_quiz(R"({"acceptance": 3})"), "/conditions/0/quiz/acceptance", "object");
  // The miss counts are whole numbers, as the specification's and the schema's integers.
  check_error(with_quiz(R"({"acceptance": {"hint_after_misses": 2.5}})"),
              "/conditions/0/quiz/acceptance/hint_after_misses", "integer");
  check_error(with_quiz(R"({"acceptance": {"assist_after_misses": 1001}})"),
              "/conditions/0/quiz/acceptance/assist_after_misses", "0..1000");
  // Every key a trial record writes is read.
  const StudyProtocol p = parse_study_protocol(
      with_quiz(R"({"acceptance": {"corridor_m": 0.007, "mean_deviation_m": 0.0035, "shortfall_m": 0.005,
        "shortfall_fraction": 0.4, "displacement_m": 0.002, "follow_through_m": 0.009, "max_gain_ratio": 3,
        "lookahead_m": 0.005}, "accept_backwards": true})"),
      "p.json");
  REQUIRE(p.conditions[0].quiz);
  const StrokeAcceptance& a = p.conditions[0].quiz->acceptance;
  CHECK(a.corridor_m == 0.007);
  CHECK(a.mean_deviation_m == 0.0035);
  CHECK(a.shortfall_m == 0.005);
  CHECK(a.shortfall_fraction == 0.4);
  CHECK(a.displacement_m == 0.002);
  CHECK(a.follow_through_m == 0.009);
  CHECK(a.max_gain_ratio == 3.0);
  CHECK(a.lookahead_m == 0.005);
  CHECK(p.conditions[0].quiz->accept_backwards);
}

TEST_CASE("a quiz condition's hint is its acceptance's hint_after_misses unless the quiz overrides it",
          "[study][protocol][quiz]") {
  const auto quiz_of = [](const std::string& quiz) {
    return parse_study_protocol(
               R"({"name": "t", "conditions": [{"name": "A", "mode": "quiz", "quiz": )" + quiz +
                   R"(}], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})",
               "p.json")
        .conditions[0]
        .quiz.value();
  };
  CHECK(quiz_of("{}").hint_after() == static_cast<int>(StrokeAcceptance{}.hint_after_misses));
  CHECK(!quiz_of("{}").hint_after_misses.has_value());
  CHECK(quiz_of(R"({"acceptance": {"hint_after_misses": 5}})").hint_after() == 5);
  CHECK(quiz_of(R"({"acceptance": {"hint_after_misses": 5}, "hint_after_misses": 1})").hint_after() == 1);
  CHECK(quiz_of(R"({"hint_after_misses": 0})").hint_after() == 0);
  // The override's range is the acceptance table's, as the acceptance's own key.
  const auto high = static_cast<long long>(parameter_field(&StrokeAcceptance::hint_after_misses).range.high);
  CHECK(quiz_of(R"({"hint_after_misses": )" + std::to_string(high) + "}").hint_after() == high);
  const auto with_quiz = [](const std::string& quiz) {
    return R"({"name": "t", "conditions": [{"name": "A", "mode": "quiz", "quiz": )" + quiz +
           R"(}], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})";
  };
  check_error(with_quiz(R"({"hint_after_misses": )" + std::to_string(high + 1) + "}"),
              "/conditions/0/quiz/hint_after_misses", "0..1000");
  check_error(with_quiz(R"({"acceptance": {"hint_after_misses": )" + std::to_string(high + 1) + "}}"),
              "/conditions/0/quiz/acceptance/hint_after_misses", "0..1000");
}

TEST_CASE("a balanced Latin square: each condition once per row, every ordered pair equally often",
          "[study][schedule]") {
  for (const int n : {2, 3, 4, 5}) {
    StudyProtocol p;
    p.name = "l";
    ProtocolPhase test;
    for (int k = 0; k < n; ++k) {
      StudyCondition condition;
      condition.name = std::string(1, static_cast<char>('A' + k));
      p.conditions.push_back(condition);
      test.conditions.push_back(p.conditions.back().name);
    }
    test.items = {U"大"};
    p.phases = {test};
    p.condition_order = ConditionOrder::latin_square;
    const std::size_t rows = n % 2 == 0 ? static_cast<std::size_t>(n) : static_cast<std::size_t>(2 * n);
    std::map<std::pair<std::string, std::string>, int> pairs;
    std::map<std::pair<std::string, std::size_t>, int> positions;
    for (std::size_t subject = 1; subject <= rows; ++subject) {
      const auto blocks = block_conditions(p, p.phases[0], {subject_id(subject), subject});
      REQUIRE(blocks.size() == static_cast<std::size_t>(n));
      CHECK(std::set<std::string>(blocks.begin(), blocks.end()).size() == static_cast<std::size_t>(n));
      for (std::size_t j = 0; j < blocks.size(); ++j) ++positions[{blocks[j], j}];
      for (std::size_t j = 1; j < blocks.size(); ++j) ++pairs[{blocks[j - 1], blocks[j]}];
      // The next cycle of subjects repeats the rows.
      CHECK(block_conditions(p, p.phases[0], {"T", subject + rows}) == blocks);
    }
    CHECK(pairs.size() == static_cast<std::size_t>(n * (n - 1)));
    for (const auto& [pair, count] : pairs) CHECK(count == pairs.begin()->second);
    for (const auto& [position, count] : positions) CHECK(count == positions.begin()->second);
  }
}

TEST_CASE("a session plan: practice, blocks, repetitions, ABBA and breaks", "[study][schedule]") {
  const StudyProtocol abba = parse_study_protocol(protocol_text("abba", 4), "p.json");
  const auto odd = block_conditions(abba, abba.phases.back(), {"S1", 1});
  const auto even = block_conditions(abba, abba.phases.back(), {"S2", 2});
  CHECK(odd == std::vector<std::string>{"A", "B", "C", "C", "B", "A"});
  CHECK(even == std::vector<std::string>{"C", "B", "A", "A", "B", "C"});
  CHECK_THROWS_AS(block_conditions(abba, abba.phases.back(), {"anonymous", 0}), InvalidArgument);

  const std::vector<PlannedTrial> plan = plan_session(abba, {"S1", 1});
  REQUIRE(plan.size() == 2 + 3 * 3 * 4);
  CHECK(plan[0].phase == StudyPhase::practice);
  CHECK(plan[1].repetition == 2);
  std::map<std::pair<std::string, std::size_t>, std::vector<int>> repetitions;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    CHECK(plan[i].index == i);
    if (plan[i].phase == StudyPhase::test)
      repetitions[{plan[i].condition, plan[i].item}].push_back(plan[i].repetition);
    const bool block_start = i > 0 && plan[i].block != plan[i - 1].block;
    const bool every = i > 0 && i % 4 == 0;
    CHECK(plan[i].break_before_s == (block_start ? 30.0 : every ? 10.0 : 0.0));
  }
  for (const auto& [key, seen] : repetitions) CHECK(seen == std::vector<int>{1, 2, 3, 4});

  // Random orders are reproducible per subject and differ between subjects.
  const StudyProtocol random = parse_study_protocol(protocol_text("random", 2), "p.json");
  const auto a = plan_session(random, {"S1", 1});
  CHECK(plan_session(random, {"S1", 0}).size() == a.size());
  std::set<std::vector<std::string>> orders;
  for (int s = 1; s <= 12; ++s)
    orders.insert(
        block_conditions(random, random.phases.back(), {subject_id(static_cast<std::size_t>(s)), 0}));
  CHECK(orders.size() > 1);
  CHECK(block_conditions(random, random.phases.back(), {"S1", 0}) ==
        block_conditions(random, random.phases.back(), {"S1", 9}));
  CHECK(trailing_number("S07") == 7);
  CHECK(trailing_number("anna") == 0);
  CHECK_THROWS_AS(plan_session(random, {"bad id", 1}), InvalidArgument);
}

namespace {

// Pre-test, training between subjects, post-test, then a second session a day later: retention and transfer.
std::string phases_text(const std::string& retention = R"("delay_s": 86400)",
                        const std::string& transfer = R"(["大"])", const std::string& extra_phase = "") {
  return R"({"name": "r", "conditions": [{"name": "free", "mode": "vision"}, {"name": "fixture", "mode": "haptic"},
             {"name": "fading", "mode": "fading"}],
    "phases": [
      {"phase": "pre-test", "condition": "free", "characters": ["十", "人"]},)" +
         extra_phase + R"(
      {"phase": "training", "conditions": ["fixture", "fading"], "assignment": "between-subjects",
       "characters": ["十", "人"], "repetitions": 3},
      {"phase": "post-test", "condition": "free", "characters": ["十", "人"], "delay_s": 60},
      {"phase": "retention", "condition": "free", "characters": ["十", "人"], "session": 2, )" +
         retention + R"(},
      {"phase": "transfer", "condition": "free", "characters": )" +
         transfer + R"(, "session": 2}
    ]})";
}

}  // namespace

TEST_CASE("a protocol of phases: pre-test, training, post-test, retention after a delay, transfer",
          "[study][protocol][phases]") {
  const StudyProtocol p = parse_study_protocol(phases_text(), "p.json");
  REQUIRE(p.phases.size() == 5);
  CHECK(p.phases[0].kind == StudyPhase::pre_test);
  CHECK(p.phases[1].assignment == ConditionAssignment::between_subjects);
  CHECK(p.phases[3].kind == StudyPhase::retention);
  CHECK(p.phases[3].delay_s == 86400.0);
  CHECK(p.phases[4].pointer == "/phases/4");
  CHECK(p.session_count() == 2);
  CHECK(p.trained_characters() == U"十人");
  // The largest session: 2 pre-test + 2 x 3 training (one condition: between subjects) + 2 post-test.
  CHECK(planned_trial_count(p) == 10);

  // Groups alternate by subject number; each subject trains in its group's condition only.
  CHECK(subject_group(p, {"S1", 1}) == "fixture");
  CHECK(subject_group(p, {"S2", 2}) == "fading");
  CHECK(subject_group(p, {"S3", 3}) == "fixture");
  CHECK_THROWS_WITH(subject_group(p, {"anna", 0}), Catch::Contains("number"));
  const std::vector<PlannedTrial> first = plan_session(p, {"S2", 2}, 1);
  REQUIRE(first.size() == 10);
  std::vector<std::string> phases;
  for (const PlannedTrial& t : first) {
    if (phases.empty() || phases.back() != to_string(t.phase)) phases.push_back(to_string(t.phase));
    if (t.phase == StudyPhase::training) CHECK(t.condition == "fading");
  }
  CHECK(phases == std::vector<std::string>{"pre-test", "training", "post-test"});
  CHECK(first[2].repetition == 1);
  CHECK(first[7].repetition == 3);
  // The post-test's delay within the session is a rest before its first trial.
  CHECK(first[8].break_before_s == 60.0);
  const std::vector<PlannedTrial> second = plan_session(p, {"S2", 2}, 2);
  REQUIRE(second.size() == 3);
  CHECK(second[0].phase == StudyPhase::retention);
  CHECK(second[0].break_before_s == 0.0);  // the day between sessions is the sessions' link, not a rest
  CHECK(second[2].phase == StudyPhase::transfer);
  CHECK(second[2].characters == U"大");
  CHECK_THROWS_WITH(plan_session(p, {"S2", 2}, 3), Catch::Contains("sessions 1 to 2"));
}

TEST_CASE("a protocol of phases that makes no sense is refused, naming the phase",
          "[study][protocol][phases]") {
  check_error(phases_text(R"("delay_s": 0)"), "/phases/3/delay_s", "after a stated delay");
  check_error(phases_text(R"("delay_s": 1)", R"(["十"])"), "/phases/4/characters/0", "is trained");
  check_error(phases_text(R"("delay_s": 1)", R"({"choose": 1, "from": ["大", "人"]})"),
              "/phases/4/characters/from/1", "is trained");
  check_error(phases_text(R"("delay_s": 1)", R"({"choose": 3, "from": ["大", "天"]})"),
              "/phases/4/characters/choose", "more characters to choose");
  const std::string untrained_retention = R"({"name": "b", "conditions": [{"name": "A", "mode": "vision"}],
      "phases": [{"phase": "training", "condition": "A", "characters": ["十"]},
                 {"phase": "retention", "condition": "A", "characters": ["十", "十口"], "delay_s": 600}]})";
  check_error(untrained_retention, "/phases/1/characters/1", "\"口\" is not trained");
  check_error(phases_text(R"("delay_s": 1)", R"(["大"])",
                          R"({"phase": "post-test", "condition": "free", "characters": ["十"]},)"),
              "/phases/1/phase", "comes after the training");
  check_error(
      phases_text(R"("delay_s": 1)", R"(["大"])",
                  R"({"phase": "training", "condition": "free", "characters": ["十"], "session": 3},)"),
      "/phases/1/session", "without gaps");
  check_error(phases_text(R"("delay_s": 1)", R"(["大"])",
                          R"({"phase": "training", "conditions": ["free"], "assignment": "between-subjects",
                              "characters": ["十"]},)"),
              "/phases/1/assignment", "two or more");
  check_error(
      phases_text(
          R"("delay_s": 1)", R"(["大"])",
          R"({"phase": "pre-test", "condition": "free", "characters": {"choose": 1, "from": ["大"]}},)"),
      "/phases/1/characters", "only a transfer phase chooses");
  check_error(phases_text(R"("delay_s": 1)", R"(["大"])",
                          R"({"phase": "warm-up", "condition": "free", "characters": ["十"]},)"),
              "/phases/1/phase", R"(expected one of "practice", "test", "pre-test")");
  const std::string both = R"({"name": "b", "conditions": [{"name": "A", "mode": "vision"}],
      "test": {"characters": ["十"], "conditions": ["A"], "repetitions": 1},
      "phases": [{"phase": "test", "condition": "A", "characters": ["十"]}]})";
  check_error(both, "/phases", "not both");
  const std::string late_pre_test = R"({"name": "b", "conditions": [{"name": "A", "mode": "vision"}],
      "phases": [{"phase": "training", "condition": "A", "characters": ["十"]},
                 {"phase": "pre-test", "condition": "A", "characters": ["十"]}]})";
  check_error(late_pre_test, "/phases/1/phase", "before the training");
  const std::string no_training = R"({"name": "b", "conditions": [{"name": "A", "mode": "vision"}],
      "phases": [{"phase": "post-test", "condition": "A", "characters": ["十"]}]})";
  check_error(no_training, "/phases/0/phase", "needs a training phase");
  // A null is not a missing value that falls back to a default.
  check_error(R"({"name": "b", "conditions": [{"name": "A", "mode": null}],
      "phases": [{"phase": "test", "condition": "A", "characters": ["十"]}]})",
              "/conditions/0/mode", "(ConditionMode), got null");
  check_error(R"({"name": "b", "conditions": [{"name": "A", "mode": "vision"}],
      "phases": [{"phase": null, "condition": "A", "characters": ["十"]}]})",
              "/phases/0/phase", "(StudyPhase), got null");
  // Nor is it for a condition's optional keys and a quiz's.
  check_error(
      R"({"name": "b", "conditions": [{"name": "A", "mode": "haptic", "guidance_stiffness_n_per_m": null}],
      "phases": [{"phase": "test", "condition": "A", "characters": ["十"]}]})",
      "/conditions/0/guidance_stiffness_n_per_m", "null");
  check_error(R"({"name": "b", "conditions": [{"name": "A", "mode": "quiz", "quiz": {"acceptance": null}}],
      "phases": [{"phase": "test", "condition": "A", "characters": ["十"]}]})",
              "/conditions/0/quiz/acceptance", "null");
}

TEST_CASE("a transfer set: untrained characters made of trained typical strokes, most coverage first",
          "[study][protocol][phases]") {
  // Made-up characters (code points 0x4E00 + k) with random typical strokes: the rule, not any real
  // character.
  std::mt19937 random(7);
  for (int round = 0; round < 200; ++round) {
    std::map<char32_t, std::vector<int>> strokes;
    std::uniform_int_distribution<int> id(1, 8), length(1, 5);
    for (char32_t c = 0x4E00; c < 0x4E00 + 30; ++c) {
      const int n = length(random);
      for (int k = 0; k < n; ++k) strokes[c].push_back(id(random));
    }
    const auto ids = [&strokes](char32_t c) { return strokes.at(c); };
    const std::u32string trained = {0x4E00, 0x4E01, 0x4E02, 0x4E03};
    std::u32string candidates;
    for (char32_t c = 0x4E00; c < 0x4E00 + 30; ++c) candidates.push_back(c);
    std::set<int> trained_ids;
    for (const char32_t c : trained) trained_ids.insert(strokes[c].begin(), strokes[c].end());
    std::vector<char32_t> eligible;
    for (const char32_t c : candidates) {
      const bool covered =
          std::all_of(strokes[c].begin(), strokes[c].end(), [&](int i) { return trained_ids.count(i) > 0; });
      if (trained.find(c) == std::u32string::npos && covered) eligible.push_back(c);
    }
    if (eligible.size() < 2) {
      CHECK_THROWS_WITH(choose_transfer_characters(trained, candidates, 2, ids), Catch::Contains("2 asked"));
      continue;
    }
    const std::u32string chosen = choose_transfer_characters(trained, candidates, 2, ids);
    REQUIRE(chosen.size() == 2);
    CHECK(chosen[0] != chosen[1]);
    for (const char32_t c : chosen) {
      CHECK(std::find(eligible.begin(), eligible.end(), c) != eligible.end());
    }
    // The first covers at least as many distinct typical strokes as any other eligible character.
    const auto distinct = [&](char32_t c) {
      return std::set<int>(strokes[c].begin(), strokes[c].end()).size();
    };
    for (const char32_t c : eligible) CHECK(distinct(chosen[0]) >= distinct(c));
  }
}

TEST_CASE("a curriculum proposes new typical strokes first, then weak ones, over characters not written",
          "[study][curriculum]") {
  // Made-up characters and strokes: the rule, not any real character.
  const std::map<char32_t, std::vector<int>> strokes{{U'a', {1, 2}},   {U'b', {1, 8, 9}},  {U'c', {3}},
                                                     {U'd', {8}},      {U'e', {4, 5}},     {U'f', {1, 2, 3}},
                                                     {U'g', {10, 11}}, {U'h', {10, 11, 1}}};
  const auto ids = [&strokes](char32_t c) { return strokes.at(c); };
  // Written: 1 (3 mm), 2 (1 mm), 3 (2 mm), 4 (0.5 mm); 5 seen but never matched. Median 1.5 mm: 1 and 3 weak.
  std::vector<TypicalStrokeRecord> record{
      {1, 4, 3e-3}, {2, 4, 1e-3}, {3, 2, 2e-3}, {4, 1, 0.5e-3}, {5, 0, {}}};
  const std::vector<ProposedCharacter> proposed = propose_characters(record, U"a", U"abcdefgh", 10, ids);
  std::u32string order;
  for (const ProposedCharacter& p : proposed) order.push_back(p.character);
  // b brings 8 and 9 new (2 each) and 1 weak (1): 5; then g brings 10 and 11 new: 4, as h does (its 1 is
  // covered now) with more strokes; then e brings 5 (never matched: new); then c brings 3 (weak), as f does
  // with more strokes; d and h add nothing left.
  CHECK(order == U"bgec");
  CHECK(proposed[0].new_strokes == std::vector<int>{8, 9});
  CHECK(proposed[0].weak_strokes == std::vector<int>{1});
  CHECK(proposed[1].new_strokes == std::vector<int>{10, 11});
  CHECK(proposed[2].new_strokes == std::vector<int>{5});
  CHECK(proposed[3].weak_strokes == std::vector<int>{3});
  CHECK(propose_characters(record, U"a", U"abcdefgh", 2, ids).size() == 2);
  CHECK(propose_characters(record, U"abcdefgh", U"abcdefgh", 5, ids).empty());  // all written

  StudyTables tables;
  StrokeRow row;
  row.subject = "S1";
  row.typical_id = 7;
  row.written = true;
  row.metrics.set("mean_deviation_m", 2e-3);
  tables.strokes.push_back(row);
  row.metrics.set("mean_deviation_m", 4e-3);
  tables.strokes.push_back(row);
  row.typical_id = 9;
  row.written = false;
  row.metrics.set("mean_deviation_m", std::monostate{});
  tables.strokes.push_back(row);
  const std::vector<TypicalStrokeRecord> read = typical_stroke_record(tables, "S1");
  REQUIRE(read.size() == 2);
  CHECK(read[0].typical_id == 7);
  CHECK(read[0].written == 2);
  CHECK(*read[0].mean_deviation_m == Approx(3e-3));
  CHECK(read[1].written == 0);
  CHECK_FALSE(read[1].mean_deviation_m);
  CHECK_THROWS_WITH(typical_stroke_record(tables, "S2"), Catch::Contains("'S2' has no saved trial"));
}

namespace {

// A protocol's guidance parameter and the table entry (parameter_table.hpp) whose range it is read with.
struct TabledKey {
  std::string mode;
  std::string key;
  ParameterRange range;
  std::string unit;
  std::string field;  ///< "Struct.field", which an error names
};

template <typename S>
TabledKey tabled(std::string mode, std::string key, double S::*member) {
  const ParameterField<S>& entry = parameter_field(member);
  return {std::move(mode), std::move(key), entry.range, std::string(entry.unit),
          std::string(ParameterTable<S>::name) + "." + std::string(entry.name)};
}

std::string number_text(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

}  // namespace

TEST_CASE("a protocol's guidance parameters are read with their laws' and rules' ranges, defined once",
          "[study][protocol]") {
  const std::vector<TabledKey> keys{
      tabled("fading", "start_gain", &FadingGuidance::gain),
      tabled("fading", "forgetting_factor", &FadingRule::forgetting_factor),
      tabled("fading", "error_gain_per_m", &FadingRule::error_gain_per_m),
      tabled("replay", "max_lead_m", &ReplayGuidance::max_lead_m),
      tabled("assist-as-needed", "start_band_m", &AssistAsNeededGuidance::band_m),
      tabled("assist-as-needed", "target_error_m", &AssistBandRule::target_error_m),
      tabled("assist-as-needed", "band_rate", &AssistBandRule::rate),
      tabled("assist-as-needed", "min_band_m", &AssistBandRule::min_band_m),
      tabled("assist-as-needed", "max_band_m", &AssistBandRule::max_band_m),
      tabled("error-amplification", "amplification_gain", &ErrorAmplificationGuidance::gain),
      tabled("error-amplification", "max_force_n", &ErrorAmplificationGuidance::max_force_n),
      tabled("skill-adaptive", "threshold_m", &SkillAdaptiveRule::threshold_m),
      tabled("skill-adaptive", "max_force_n", &ErrorAmplificationGuidance::max_force_n),
      tabled("timing", "speed_m_s", &TimingGuidance::speed_m_s),
  };
  for (TabledKey k : keys) {
    INFO(k.mode << " " << k.key);
    // A replay's lead: the table's range narrowed to the trial's R_res, as the trial checks it.
    if (k.key == "max_lead_m") k.range = protocol_max_lead_range();
    const auto protocol = [&](double value) {
      // The widest band alongside, so that the narrowest may take its whole range (max >= min).
      const std::string widest = k.key == "min_band_m" ? R"(, "max_band_m": 0.1)" : "";
      return R"({"name": "t", "conditions": [{"name": "A", "mode": ")" + k.mode + R"(", "parameters": {")" +
             k.key + R"(": )" + number_text(value) + widest +
             R"(}}], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1}})";
    };
    const ParameterRange& r = k.range;
    const double lowest = r.low_open ? std::nextafter(r.low, INFINITY) : r.low;
    CHECK_NOTHROW(parse_study_protocol(protocol(lowest), "p.json"));
    check_error(protocol(r.low_open ? r.low : std::nextafter(r.low, -INFINITY)),
                "/conditions/0/parameters/" + k.key, k.field);
    if (std::isfinite(r.high)) {
      const double highest = r.high_open ? std::nextafter(r.high, -INFINITY) : r.high;
      CHECK_NOTHROW(parse_study_protocol(protocol(highest), "p.json"));
      check_error(protocol(r.high_open ? r.high : std::nextafter(r.high, INFINITY)),
                  "/conditions/0/parameters/" + k.key, r.text(k.unit));
    }
  }
}

TEST_CASE("a protocol's trial settings, breaks and guidance stiffness take the trial's ranges when read",
          "[study][protocol]") {
  const auto with = [](const std::string& condition, const std::string& tail) {
    return R"({"name": "t", "conditions": [)" + condition +
           R"(], "test": {"characters": ["大"], "conditions": ["A"], "repetitions": 1})" + tail + "}";
  };
  const std::string haptic = R"({"name": "A", "mode": "haptic"})";
  // max_duration_s: TrialSpec's range, (0, 86400] s; a trial of 1 h 40 min at 1000 Hz is 6,000,000 ticks.
  const ParameterRange duration = SchemaOf<TrialSpec>::get().field("max_duration_s")->range;
  CHECK(SchemaOf<ProtocolTrialSettings>::get().field("max_duration_s")->range.high == duration.high);
  CHECK(parse_study_protocol(with(haptic, R"(, "trial": {"max_duration_s": 6000})"), "p.json")
            .trial.max_duration_s == 6000.0);
  CHECK(parse_study_protocol(with(haptic, R"(, "trial": {"max_duration_s": 0.0001, "rate_hz": 10000})"),
                             "p.json")
            .trial.max_duration_s == 0.0001);
  check_error(with(haptic, R"(, "trial": {"max_duration_s": 0})"), "/trial/max_duration_s", "(0, 86400]");
  check_error(with(haptic, R"(, "trial": {"max_duration_s": 86401, "rate_hz": 100})"),
              "/trial/max_duration_s", "(0, 86400]");
  check_error(with(haptic, R"(, "trial": {"rate_hz": 10001})"), "/trial/rate_hz", "[100, 10000]");
  check_error(with(haptic, R"(, "trial": {"rate": 1000})"), "/trial/rate", "unknown key");
  check_error(with(haptic, R"(, "trial": {"rate_hz": null})"), "/trial/rate_hz", "null");
  check_error(with(haptic, R"(, "trial": {"rate_hz": "1000"})"), "/trial/rate_hz", "number");
  check_error(with(haptic, R"(, "breaks": {"every_trials": -1, "duration_s": 1})"), "/breaks/every_trials",
              "0");
  check_error(with(haptic, R"(, "breaks": {"every_trials": 2})"), "/breaks/duration_s", "missing");
  check_error(with(haptic, R"(, "breaks": {"pause_s": 2})"), "/breaks/pause_s", "unknown key");
  // The guidance stiffness: the force law's range (>= 0 N/m), not a copy of it.
  const auto stiff = [&](const std::string& value) {
    return with(R"({"name": "A", "mode": "haptic", "guidance_stiffness_n_per_m": )" + value + "}", "");
  };
  CHECK(parse_study_protocol(stiff("0"), "p.json").conditions[0].guidance.value().stiffness_n_per_m ==
        std::optional<double>(0.0));
  CHECK(parse_study_protocol(stiff("2e5"), "p.json").conditions[0].guidance.value().stiffness_n_per_m ==
        std::optional<double>(2e5));
  check_error(stiff("-1"), "/conditions/0/guidance_stiffness_n_per_m",
              "ForceLawParameters.guidance_stiffness_n_per_m");
}
