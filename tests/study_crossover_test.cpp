// Within-subjects crossover on item sets: the protocol's "item_sets" and a phase's "sets" read with errors
// naming the JSON pointer, each subject's sequence and set rotation counterbalanced by number, every trial
// naming the condition its item is trained under, kept in session.json and the tidy tables.
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "protocol_checks.hpp"
#include "study/manifest_json.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"
#include "temporary_files.hpp"

using namespace calligraphy;
using protocol_checks::check_error;
using protocol_checks::subject_id;
namespace fs = std::filesystem;

namespace {

// Conditions A, B, C; sets s1..s3 (one character each unless `sets` is given) and a transfer set of s1;
// `phases` as given.
std::string crossover_text(const std::string& phases, const std::string& sets = "") {
  return R"({"name": "xo", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
             {"name": "C", "mode": "fading"}],
    "item_sets": )" +
         (sets.empty()
              ? std::string(
                    R"([{"name": "s1", "characters": ["十", "口"]}, {"name": "s2", "characters": ["人"]},
                       {"name": "s3", "characters": ["山"]}, {"name": "t1", "characters": ["中"], "transfer_of": "s1"}])")
              : sets) +
         R"(, "phases": )" + phases + R"(, "trial": {"max_duration_s": 30}})";
}

// Pre-test on every trained set, a crossover training of `conditions` on as many sets, post-test, retention
// (session 2) and transfer on t1.
std::string design(int k) {
  const std::string conditions = k == 2 ? R"(["A", "B"])" : R"(["A", "B", "C"])";
  const std::string sets = k == 2 ? R"(["s1", "s2"])" : R"(["s1", "s2", "s3"])";
  return crossover_text(R"([{"phase": "pre-test", "condition": "A", "sets": )" + sets + R"(},
      {"phase": "training", "conditions": )" +
                        conditions + R"(, "assignment": "crossover", "sets": )" + sets +
                        R"(, "repetitions": 2},
      {"phase": "post-test", "condition": "A", "sets": )" +
                        sets + R"(},
      {"phase": "retention", "condition": "A", "sets": )" +
                        sets + R"(, "session": 2, "delay_s": 86400},
      {"phase": "transfer", "condition": "A", "sets": ["t1"], "session": 2}])");
}

std::vector<PlannedTrial> whole_plan(const StudyProtocol& protocol, std::size_t number) {
  std::vector<PlannedTrial> trials;
  for (int session = 1; session <= protocol.session_count(); ++session) {
    for (PlannedTrial& t : plan_session(protocol, {subject_id(number), number}, session)) trials.push_back(t);
  }
  return trials;
}

}  // namespace

TEST_CASE("crossover protocol: item sets and a crossover phase are read", "[study][protocol][crossover]") {
  const StudyProtocol p = parse_study_protocol(design(2), "p.json");
  REQUIRE(p.item_sets.size() == 4);
  CHECK(p.item_sets[0].name == "s1");
  CHECK(p.item_sets[0].items == std::vector<std::u32string>{U"十", U"口"});
  CHECK(p.item_sets[0].transfer_of.empty());
  CHECK(p.item_sets[3].transfer_of == "s1");
  REQUIRE(p.phases.size() == 5);
  const ProtocolPhase& training = p.phases[1];
  CHECK(training.assignment == ConditionAssignment::crossover);
  CHECK(std::string(to_string(training.assignment)) == "crossover");
  CHECK(training.sets == std::vector<std::string>{"s1", "s2"});
  CHECK(training.items == std::vector<std::u32string>{U"十", U"口", U"人"});
  CHECK(training.item_sets == std::vector<std::string>{"s1", "s1", "s2"});
  CHECK(p.crossover_phase() == &training);
  CHECK(p.item_set("t1") == &p.item_sets[3]);
  CHECK(p.item_set("nope") == nullptr);
  // A phase of characters has no sets.
  const StudyProtocol plain = parse_study_protocol(
      crossover_text(R"([{"phase": "test", "conditions": ["A", "B"], "characters": ["大"]}])"), "p.json");
  CHECK(plain.phases[0].sets.empty());
  CHECK(plain.phases[0].item_sets.empty());
  CHECK(plain.crossover_phase() == nullptr);
  // Session 1: pre-test 3 + training 3 items x 2 repetitions (each set in one condition) + post-test 3.
  CHECK(planned_trial_count(p) == 3 + 6 + 3);
}

TEST_CASE("crossover protocol: errors name the pointer", "[study][protocol][crossover]") {
  const std::string training = R"({"phase": "training", "conditions": ["A", "B"], "assignment": "crossover",
                                   "sets": ["s1", "s2"]})";
  check_error(crossover_text(R"([{"phase": "pre-test", "condition": "A", "sets": ["s1"]},
      {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["x", "s2"]}])"),
              "/phases/1/sets/0", R"(no item set "x"; defined: s1, s2, s3, t1)");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十"]},
                                                      {"name": "s1", "characters": ["人"]}])"),
              "/item_sets/1/name", R"(the item set "s1" is defined twice)");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十", "口"]},
                                                      {"name": "s2", "characters": ["人", "中口"]}])"),
              "/item_sets/1/characters/1", R"("口" is also in the item set "s1")");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十"], "colour": 1}])"),
              "/item_sets/0/colour", "");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s 1", "characters": ["十"]}])"),
              "/item_sets/0/name", "expected 1 to 32 letters");
  check_error(crossover_text("[" + training + "]", "[]"), "/item_sets",
              "expected a list of 1 to 26 item sets");
  check_error(crossover_text(R"([{"phase": "training", "conditions": ["A", "B"], "assignment": "crossover",
                                  "characters": ["十"]}])"),
              "/phases/0/assignment", R"(crossover needs "sets")");
  check_error(crossover_text(R"([{"phase": "training", "conditions": ["A", "B"], "assignment": "crossover",
                                  "sets": ["s1", "s2", "s3"]}])"),
              "/phases/0/sets", "expected 2 sets, got 3");
  check_error(crossover_text(R"([{"phase": "training", "condition": "A", "assignment": "crossover",
                                  "sets": ["s1"]}])"),
              "/phases/0/assignment", "two or more");
  check_error(crossover_text("[" + training + R"(, {"phase": "training", "conditions": ["A", "B"],
                                  "assignment": "crossover", "sets": ["s3", "s1"]}])"),
              "/phases/1/assignment", "a second crossover phase (the first: /phases/0)");
  check_error(crossover_text(R"([{"phase": "practice", "conditions": ["A", "B"], "assignment": "crossover",
                                  "sets": ["s1", "s2"]}, )" +
                             training + "]"),
              "/phases/0/assignment", "a practice phase");
  check_error(crossover_text(R"([{"phase": "training", "conditions": ["A", "B"], "assignment": "crossover",
                                  "sets": ["s1", "t1"]}])"),
              "/phases/0/sets/1", R"("t1" is a transfer set (of "s1"))");
  check_error(crossover_text(R"([{"phase": "training", "condition": "A", "sets": ["s1", "s1"]}])"),
              "/phases/0/sets/1", "listed twice");
  check_error(
      crossover_text(R"([{"phase": "training", "condition": "A", "sets": ["s1"], "characters": ["大"]}])"),
      "/phases/0/characters", R"(give either "characters" or "sets")");
  check_error(crossover_text(R"([{"phase": "training", "condition": "A"}])"), "/phases/0/characters",
              R"(give either "characters" or "sets")");
  // transfer_of: another set, not itself, not a transfer set.
  check_error(
      crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十"], "transfer_of": "s1"},
                                                      {"name": "s2", "characters": ["人"]}])"),
      "/item_sets/0/transfer_of", "not a transfer set of itself");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十"]},
                                                      {"name": "s2", "characters": ["人"], "transfer_of": "s9"}])"),
              "/item_sets/1/transfer_of", R"(no item set "s9"; defined: s1, s2)");
  check_error(crossover_text("[" + training + "]", R"([{"name": "s1", "characters": ["十"]},
                                                      {"name": "s2", "characters": ["人"]},
                                                      {"name": "t1", "characters": ["山"], "transfer_of": "s1"},
                                                      {"name": "t2", "characters": ["中"], "transfer_of": "t1"}])"),
              "/item_sets/3/transfer_of", R"("t1" is itself a transfer set (of "s1"))");
  // A retention test on a set not trained is named where the set lists the character.
  check_error(
      crossover_text("[" + training +
                     R"(, {"phase": "retention", "condition": "A", "sets": ["s1", "t1"], "delay_s": 60}])"),
      "/item_sets/3/characters/0", "is not trained");
  // A transfer test on a trained set.
  check_error(
      crossover_text("[" + training + R"(, {"phase": "transfer", "condition": "A", "sets": ["s2"]}])"),
      "/item_sets/1/characters/0", "is trained");
}

TEST_CASE("crossover protocol: order.conditions does not apply to the crossover phase",
          "[study][protocol][crossover]") {
  // abba's even repetitions are not asked of a crossover phase (it is not split), and its order is its own.
  std::string text =
      crossover_text(R"([{"phase": "training", "conditions": ["A", "B"], "assignment": "crossover",
                                         "sets": ["s1", "s2"], "repetitions": 3}])");
  text.insert(text.rfind('}'), R"(, "order": {"conditions": "abba"})");
  const StudyProtocol p = parse_study_protocol(text, "p.json");
  const std::vector<PlannedTrial> plan = plan_session(p, {"S2", 2}, 1);
  std::vector<std::string> training;
  for (const PlannedTrial& t : plan) {
    if (t.phase == StudyPhase::training && (training.empty() || training.back() != t.condition))
      training.push_back(t.condition);
  }
  CHECK(training == std::vector<std::string>{"B", "A"});
  CHECK(block_conditions(p, p.phases[0], {"S2", 2}) == std::vector<std::string>{"B", "A"});
  CHECK(std::count_if(plan.begin(), plan.end(), [](const PlannedTrial& t) { return t.condition == "A"; }) ==
        2 * 3);  // s1's two items, three rounds, in one block
}

TEST_CASE("crossover protocol: a subject without a number is refused, naming it",
          "[study][protocol][crossover]") {
  const StudyProtocol p = parse_study_protocol(design(2), "p.json");
  CHECK_THROWS_WITH(crossover_assignment(p, {"P", 0}),
                    Catch::Contains("subject 'P'") && Catch::Contains("number"));
  CHECK_THROWS_AS(plan_session(p, {"P", 0}, 2), InvalidArgument);
  const StudyProtocol plain = parse_study_protocol(
      crossover_text(R"([{"phase": "test", "conditions": ["A", "B"], "characters": ["大"]}])"), "p.json");
  const CrossoverAssignment none = crossover_assignment(plain, {"P", 0});
  CHECK(none.sequence.empty());
  CHECK(none.trained.empty());
  for (const PlannedTrial& t : plan_session(plain, {"P", 0})) {
    CHECK(t.item_set.empty());
    CHECK(t.sequence.empty());
    CHECK(t.period == 0);
    CHECK(t.trained_condition.empty());
  }
}

TEST_CASE("crossover protocol: subjects 1, 2, 3, 4 of two conditions get AB and BA on both pairings",
          "[study][protocol][crossover]") {
  const StudyProtocol p = parse_study_protocol(design(2), "p.json");
  const std::vector<std::pair<std::string, std::size_t>> expected{{"AB", 0}, {"BA", 0}, {"AB", 1}, {"BA", 1}};
  for (std::size_t number = 1; number <= 8; ++number) {
    INFO("subject " << number);
    const CrossoverAssignment a = crossover_assignment(p, {subject_id(number), number});
    CHECK(a.sequence == expected[(number - 1) % 4].first);
    CHECK(a.rotation == expected[(number - 1) % 4].second);
  }
  // Subject 1: A on s1 in period 1, B on s2 in period 2; subject 3: A on s2 in period 1, B on s1 in period 2.
  const CrossoverAssignment s1 = crossover_assignment(p, {"S1", 1});
  CHECK(s1.conditions == std::vector<std::string>{"A", "B"});
  CHECK(s1.sets == std::vector<std::string>{"s1", "s2"});
  CHECK(s1.trained.at("s1").condition == "A");
  CHECK(s1.trained.at("s1").period == 1);
  CHECK(s1.trained.at("t1").condition == "A");  // the transfer set takes its source's training
  CHECK(s1.trained.at("t1").period == 1);
  CHECK(s1.trained.count("s3") == 0);
  const CrossoverAssignment s2 = crossover_assignment(p, {"S2", 2});
  CHECK(s2.conditions == std::vector<std::string>{"B", "A"});
  CHECK(s2.sets == std::vector<std::string>{"s2", "s1"});
  const CrossoverAssignment s3 = crossover_assignment(p, {"S3", 3});
  CHECK(s3.conditions == std::vector<std::string>{"A", "B"});
  CHECK(s3.sets == std::vector<std::string>{"s2", "s1"});
  CHECK(s3.trained.at("t1").condition == "B");
  CHECK(s3.trained.at("t1").period == 2);
}

TEST_CASE("crossover protocol: plans are balanced and every trial names its item's training",
          "[study][protocol][crossover]") {
  for (const int k : {2, 3}) {
    const StudyProtocol p = parse_study_protocol(design(k), "p.json");
    const std::size_t rows = k % 2 == 0 ? static_cast<std::size_t>(k) : 2 * static_cast<std::size_t>(k);
    const std::size_t cycle = rows * static_cast<std::size_t>(k);  // every (sequence, rotation) once
    const std::size_t subjects = std::max<std::size_t>(8, 2 * cycle);
    std::map<std::pair<std::string, std::size_t>, int> combinations;
    std::map<std::pair<std::string, int>, int> condition_period;
    std::map<std::pair<std::string, std::string>, int> condition_set;
    for (std::size_t number = 1; number <= subjects; ++number) {
      INFO("k " << k << ", subject " << number);
      const std::vector<PlannedTrial> plan = whole_plan(p, number);
      const CrossoverAssignment a = crossover_assignment(p, {subject_id(number), number});
      // The crossover's blocks: k, in period order, each one condition on one set's items.
      std::vector<std::pair<std::string, std::set<std::string>>> blocks;
      std::size_t last_block = SIZE_MAX;
      for (const PlannedTrial& t : plan) {
        CHECK(t.sequence == a.sequence);
        if (t.phase != StudyPhase::training) continue;
        if (t.block != last_block) blocks.push_back({t.condition, {}});
        last_block = t.block;
        blocks.back().second.insert(t.item_set);
        CHECK(t.trained_condition == t.condition);
        CHECK(t.period == static_cast<int>(blocks.size()));
        CHECK(p.phases[1].items[t.item] == t.characters);
      }
      REQUIRE(blocks.size() == static_cast<std::size_t>(k));
      std::set<std::string> conditions;
      std::set<std::string> sets;
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        REQUIRE(blocks[b].second.size() == 1);  // one set a block
        conditions.insert(blocks[b].first);
        sets.insert(*blocks[b].second.begin());
        CHECK(a.sequence[b] == blocks[b].first[0]);  // the conditions are called A, B, C as listed
      }
      CHECK(conditions.size() == static_cast<std::size_t>(k));  // every condition trained once
      CHECK(sets.size() == static_cast<std::size_t>(k));        // on its own set
      // Training: each item x repetitions once in its condition.
      CHECK(std::count_if(plan.begin(), plan.end(), [](const PlannedTrial& t) {
              return t.phase == StudyPhase::training;
            }) == static_cast<std::ptrdiff_t>(p.phases[1].items.size()) * 2);
      // Tests before, after and a day after: the same item set, period and condition as in the training.
      for (const PlannedTrial& t : plan) {
        if (t.phase == StudyPhase::training) continue;
        if (t.item_set == "t1") {  // transfer: its source's
          CHECK(t.trained_condition == a.trained.at("s1").condition);
          CHECK(t.period == a.trained.at("s1").period);
          continue;
        }
        const auto trained = std::find_if(plan.begin(), plan.end(), [&](const PlannedTrial& u) {
          return u.phase == StudyPhase::training && u.characters == t.characters;
        });
        REQUIRE(trained != plan.end());
        CHECK(t.item_set == trained->item_set);
        CHECK(t.trained_condition == trained->condition);
        CHECK(t.period == trained->period);
      }
      ++combinations[{a.sequence, a.rotation}];
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        ++condition_period[{blocks[b].first, static_cast<int>(b + 1)}];
        ++condition_set[{blocks[b].first, *blocks[b].second.begin()}];
      }
      if (number % rows == 0) {  // whole Williams squares: each condition in each period equally often
        CHECK(condition_period.size() == static_cast<std::size_t>(k * k));
        for (const auto& [key, count] : condition_period) CHECK(count == static_cast<int>(number) / k);
      }
      if (number % cycle ==
          0) {  // every rotation too: each (sequence, rotation) and condition x set balanced
        CHECK(combinations.size() == cycle);
        for (const auto& [key, count] : combinations) CHECK(count == static_cast<int>(number / cycle));
        CHECK(condition_set.size() == static_cast<std::size_t>(k * k));
        for (const auto& [key, count] : condition_set) CHECK(count == static_cast<int>(number) / k);
      }
    }
  }
}

TEST_CASE("crossover protocol: session.json keeps each trial's set and crossover, and older plans read",
          "[study][protocol][crossover]") {
  TempFolder temp;
  const LoadedProtocol protocol = protocol_from_text(design(2), "xo.json");
  SessionSetup setup;
  setup.subject = {"S3", 3};
  SessionFolder session = SessionFolder::create(temp.path / "S3", setup, protocol);
  const std::string text = calligraphy::testing_files::contents(session.path() / "session.json");
  nlohmann::json document = nlohmann::json::parse(text);
  const nlohmann::json& first = document["plan"][0];  // pre-test on 十 of s1, trained second under B
  CHECK(first["item_set"] == "s1");
  CHECK(first["sequence"] == "AB");
  CHECK(first["period"] == 2);
  CHECK(first["trained_condition"] == "B");
  const SessionManifest read = study_detail::manifest_from_json(text, "session.json");
  REQUIRE(read.plan.size() == session.plan().size());
  for (std::size_t i = 0; i < read.plan.size(); ++i) {
    CHECK(read.plan[i].item_set == session.plan()[i].item_set);
    CHECK(read.plan[i].sequence == session.plan()[i].sequence);
    CHECK(read.plan[i].period == session.plan()[i].period);
    CHECK(read.plan[i].trained_condition == session.plan()[i].trained_condition);
  }
  // A trial record's "trial" object is the same JSON.
  CHECK(study_detail::planned_trial_json(session.plan()[0]) == first);

  // A plan written before item sets: the keys are absent and read as none.
  nlohmann::json older = document;
  for (nlohmann::json& entry : older["plan"]) {
    for (const char* key : {"item_set", "sequence", "period", "trained_condition"}) entry.erase(key);
  }
  const SessionManifest old = study_detail::manifest_from_json(older.dump(2), "session.json");
  CHECK(old.plan[0].item_set.empty());
  CHECK(old.plan[0].sequence.empty());
  CHECK(old.plan[0].period == 0);
  CHECK(old.plan[0].trained_condition.empty());

  const auto refused = [&](const char* key, const nlohmann::json& value, const std::string& words) {
    nlohmann::json bad = document;
    bad["plan"][1][key] = value;
    CHECK_THROWS_WITH(
        study_detail::manifest_from_json(bad.dump(2), "session.json"),
        Catch::StartsWith(std::string("session.json: /plan/1/") + key + ": ") && Catch::Contains(words));
  };
  refused("period", 0, "");
  refused("period", 27, "");
  refused("trained_condition", "Z", "not a condition of the protocol");
  refused("trained_condition", "a b", "letters");
  refused("item_set", "", "letters");
  refused("sequence", "ab", "letters A-Z");
  refused("sequence", 3, "");

  // A protocol without sets writes none of the keys.
  const LoadedProtocol plain = protocol_from_text(
      crossover_text(R"([{"phase": "test", "conditions": ["A", "B"], "characters": ["大"]}])"), "plain.json");
  SessionFolder plain_session = SessionFolder::create(temp.path / "S1", setup, plain);
  // Parsed into a variable: a range-for over a member of a temporary would read it after its end.
  const nlohmann::json plain_manifest =
      nlohmann::json::parse(calligraphy::testing_files::contents(plain_session.path() / "session.json"));
  for (const nlohmann::json& entry : plain_manifest["plan"]) {
    for (const char* key : {"item_set", "sequence", "period", "trained_condition"})
      CHECK_FALSE(entry.contains(key));
  }
}

TEST_CASE("crossover protocol: the tidy tables give each trial's set, sequence, period and trained condition",
          "[study][tables][crossover]") {
  TempFolder temp;
  const LoadedProtocol protocol =
      protocol_from_text(crossover_text(R"([{"phase": "pre-test", "condition": "A", "sets": ["s2", "s3"]},
          {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["s2", "s3"]},
          {"phase": "post-test", "condition": "A", "sets": ["s2", "s3"]}])"),
                         "xo.json");
  for (const std::size_t number : {std::size_t{1}, std::size_t{2}}) {
    SessionSetup setup;
    setup.subject = {subject_id(number), number};
    setup.writer_seed = subject_seed(setup.subject.id);
    SessionFolder session = SessionFolder::create(temp.path / setup.subject.id, setup, protocol);
    (void)run_session(session, study_test::run_options());
  }
  const StudyTables tables = read_study_tables({temp.path});
  REQUIRE(tables.trials.size() == 2 * 6);
  const std::string csv = trials_csv(tables);
  CHECK_THAT(csv, Catch::Contains(",item,repetition,item_set,sequence,period,trained_condition,writer,"));
  for (const TrialRow& row : tables.trials) {
    INFO(row.subject << " " << row.phase << " " << row.characters);
    CHECK(row.sequence == (row.subject == "S1" ? "AB" : "BA"));
    CHECK(row.item_set == (row.characters == "人" ? "s2" : "s3"));
    // S1: A on s2 in period 1, B on s3 in period 2; S2: B on s3 in period 1, A on s2 in period 2.
    const bool s2 = row.item_set == "s2";
    CHECK(row.trained_condition == (s2 ? "A" : "B"));
    REQUIRE(row.period.has_value());
    CHECK(*row.period == (row.subject == "S1" ? (s2 ? 1 : 2) : (s2 ? 2 : 1)));
  }
  // S1's first row: pre-test on 人 (s2), trained first under A.
  CHECK_THAT(csv, Catch::Contains(",pre-test,1,A,vision,人,1,1,1,s2,AB,1,A,"));
}

TEST_CASE("a mixed design counts the crossover's subjects within their between-subjects group",
          "[study][crossover]") {
  const StudyProtocol protocol = parse_study_protocol(
      R"({"name": "mixed", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
           {"name": "F", "mode": "haptic"}, {"name": "G", "mode": "vision"}],
          "item_sets": [{"name": "one", "characters": ["十", "口"]}, {"name": "two", "characters": ["人", "又"]}],
          "phases": [
            {"phase": "training", "conditions": ["F", "G"], "assignment": "between-subjects", "characters": ["大"]},
            {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["one", "two"]}]})",
      "mixed.json");
  // Per group, every (sequence, rotation) equally often: counted over all subjects, group and sequence would
  // both alternate with the subject's parity and coincide.
  std::map<std::string, std::map<std::pair<std::string, std::size_t>, int>> seen;
  for (std::size_t number = 1; number <= 16; ++number) {
    const SubjectAssignment subject{subject_id(number), number};
    const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
    ++seen[subject_group(protocol, subject)][{crossover.sequence, crossover.rotation}];
  }
  REQUIRE(seen.size() == 2);
  for (const auto& [group, counts] : seen) {
    INFO("group " << group);
    CHECK(counts.size() == 4);
    for (const auto& [key, count] : counts) CHECK(count == 2);
  }
}

TEST_CASE("a between-subjects familiarisation beside a crossover gives each subject its group's condition",
          "[study][crossover]") {
  const StudyProtocol protocol = parse_study_protocol(crossover_text(R"([
      {"phase": "practice", "conditions": ["A", "B"], "assignment": "between-subjects", "characters": ["大"]},
      {"phase": "pre-test", "condition": "A", "sets": ["s1", "s2"]},
      {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["s1", "s2"]}])"),
                                                      "mixed.json");
  std::map<std::string, std::set<std::string>> cells;  // group -> sequence and rotation
  for (std::size_t number = 1; number <= 8; ++number) {
    const SubjectAssignment subject{subject_id(number), number};
    const std::string group = number % 2 == 1 ? "A" : "B";
    INFO("subject " << number);
    CHECK(subject_group(protocol, subject) == group);
    CHECK(block_conditions(protocol, protocol.phases[0], subject) == std::vector<std::string>{group});
    const std::vector<PlannedTrial> trials = plan_session(protocol, subject);
    REQUIRE(trials.size() == 1 + 3 + 3);
    CHECK(trials[0].phase == StudyPhase::practice);
    CHECK(trials[0].condition == group);
    const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
    for (const PlannedTrial& trial : trials) CHECK(trial.sequence == crossover.sequence);
    cells[group].insert(crossover.sequence + std::to_string(crossover.rotation));
  }
  // Each group gets every sequence and rotation over its 4 subjects.
  CHECK(cells["A"] == std::set<std::string>{"AB0", "BA0", "AB1", "BA1"});
  CHECK(cells["B"] == cells["A"]);
  CHECK(counterbalancing_square(protocol) == 8);
}

TEST_CASE("a second training of a crossover's set is refused naming its pointer", "[study][crossover]") {
  const std::string crossover =
      R"({"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["s1", "s2"]})";
  // Between subjects on a set, within subjects on a character of one, before or after the crossover.
  check_error(crossover_text("[" + crossover + R"(,
      {"phase": "training", "conditions": ["A", "B"], "assignment": "between-subjects", "sets": ["s3", "s2"]}])"),
              "/phases/1/sets/1", R"(the item set "s2" is trained in the crossover phase /phases/0)");
  check_error(crossover_text(R"([{"phase": "training", "condition": "C", "characters": ["山", "十口"]}, )" +
                             crossover + "]"),
              "/phases/0/characters/1", R"("十" is in the item set "s1", trained in the crossover phase)");
  check_error(
      crossover_text("[" + crossover + R"(, {"phase": "training", "condition": "C", "sets": ["t1"]}])"),
      "/phases/1/sets/0", R"(the item set "t1" is the transfer items of "s1")");
  // A set the crossover does not train may be trained elsewhere, and practised anywhere.
  const StudyProtocol other = parse_study_protocol(
      crossover_text(R"([{"phase": "practice", "condition": "B", "characters": ["十"]}, )" + crossover + R"(,
      {"phase": "training", "conditions": ["A", "B"], "assignment": "between-subjects", "sets": ["s3"]}])"),
      "p.json");
  CHECK(plan_session(other, {"S1", 1}).back().trained_condition.empty());
}

TEST_CASE("a crossover's tests that list characters are attributed to their sets, or refused by the item",
          "[study][crossover]") {
  const std::string head = R"([{"phase": "pre-test", "condition": "A", )";
  const std::string tail = R"(},
      {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["s1", "s2"]},
      {"phase": "transfer", "condition": "A", "characters": ["中"]}])";
  const StudyProtocol by_sets =
      parse_study_protocol(crossover_text(head + R"("sets": ["s1", "s2"])" + tail), "p.json");
  const StudyProtocol by_characters =
      parse_study_protocol(crossover_text(head + R"("characters": ["十", "人", "口十"])" + tail), "p.json");
  CHECK(by_characters.phases[0].item_sets == std::vector<std::string>{"s1", "s2", "s1"});
  CHECK(by_characters.phases[2].item_sets == std::vector<std::string>{"t1"});
  for (std::size_t number = 1; number <= 4; ++number) {
    const SubjectAssignment subject{subject_id(number), number};
    const CrossoverAssignment crossover = crossover_assignment(by_characters, subject);
    for (const PlannedTrial& trial : plan_session(by_characters, subject)) {
      if (trial.phase == StudyPhase::training) continue;
      INFO("subject " << number << " trial " << trial.index);
      REQUIRE_FALSE(trial.item_set.empty());
      CHECK(trial.trained_condition == crossover.trained.at(trial.item_set).condition);
      CHECK(trial.period == crossover.trained.at(trial.item_set).period);
    }
    // The same attribution as the phase given by its sets.
    const std::vector<PlannedTrial> listed = plan_session(by_sets, subject);
    const std::vector<PlannedTrial> named = plan_session(by_characters, subject);
    CHECK(listed[0].trained_condition == named[0].trained_condition);
    CHECK(listed[2].trained_condition == named[1].trained_condition);
  }
  check_error(crossover_text(head + R"("characters": ["十", "大"])" + tail), "/phases/0/characters/1",
              R"("大" is in no item set)");
  check_error(crossover_text(head + R"("characters": ["十人"])" + tail), "/phases/0/characters/0",
              R"("十人" holds characters of the item sets "s1" and "s2")");
  check_error(crossover_text(head + R"("sets": ["s1"]},
      {"phase": "training", "conditions": ["A", "B"], "assignment": "crossover", "sets": ["s1", "s2"]},
      {"phase": "transfer", "condition": "A", "characters": {"choose": 1, "from": ["大", "山"]}}])"),
              "/phases/2/characters", "chosen by coverage are in no set");
  // Without a crossover, characters of no set stay as they were.
  const StudyProtocol plain = parse_study_protocol(
      crossover_text(R"([{"phase": "training", "condition": "A", "characters": ["大"]}])"), "p.json");
  CHECK(plain.phases[0].item_sets.empty());
}
