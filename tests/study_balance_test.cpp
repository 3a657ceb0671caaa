// A protocol's counterbalancing square and how some subjects fill it (`counterbalancing_square`,
// `counterbalancing`), and each phase's place in a session's plan (`plan_session_phases`), for what
// `calligraphy session plan` prints.
#include <catch2/catch.hpp>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/schedule.hpp"
#include "protocol_checks.hpp"

using namespace calligraphy;
using protocol_checks::subject_id;

namespace {

std::vector<SubjectAssignment> subjects(std::size_t count) {
  std::vector<SubjectAssignment> out;
  for (std::size_t n = 1; n <= count; ++n) out.push_back({subject_id(n), n});
  return out;
}

// A crossover of `conditions` (2 or 3) on as many sets, with a pre-test.
StudyProtocol crossover(int conditions) {
  const std::string listed = conditions == 2 ? R"(["A", "B"])" : R"(["A", "B", "C"])";
  const std::string sets = conditions == 2 ? R"(["s1", "s2"])" : R"(["s1", "s2", "s3"])";
  return parse_study_protocol(
      R"({"name": "xo", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
           {"name": "C", "mode": "fading"}],
          "item_sets": [{"name": "s1", "characters": ["十"]}, {"name": "s2", "characters": ["人"]},
                        {"name": "s3", "characters": ["山"]}],
          "phases": [{"phase": "pre-test", "condition": "A", "sets": )" +
          sets + R"(}, {"phase": "training", "conditions": )" + listed +
          R"(, "assignment": "crossover", "sets": )" + sets + R"(, "repetitions": 2}]})",
      "xo.json");
}

const BalanceFactor& factor(const Counterbalancing& balance, const std::string& name) {
  for (const BalanceFactor& f : balance.factors) {
    if (f.name == name) return f;
  }
  FAIL("no factor " << name);
  return balance.factors.front();
}

// The assignment of a subject, by the schedule's own functions.
std::tuple<std::string, std::string, std::size_t> assignment(const StudyProtocol& protocol, std::size_t n) {
  const SubjectAssignment subject{subject_id(n), n};
  const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
  return {subject_group(protocol, subject), crossover.sequence, crossover.rotation};
}

}  // namespace

TEST_CASE("the square is where every assignment by number repeats, each cell once", "[study][balance]") {
  for (const int k : {2, 3}) {
    const StudyProtocol protocol = crossover(k);
    const std::size_t square = counterbalancing_square(protocol);
    CHECK(square == (k == 2 ? 4u : 18u));  // rows x k: 2 x 2, 6 x 3
    std::map<std::tuple<std::string, std::string, std::size_t>, int> cells;
    for (std::size_t n = 1; n <= square; ++n) {
      ++cells[assignment(protocol, n)];
      CHECK(assignment(protocol, n) == assignment(protocol, n + square));
    }
    CHECK(cells.size() == square);
  }
}

TEST_CASE("a 2x2 crossover of 5 subjects names the sequence and pairing left uneven", "[study][balance]") {
  const StudyProtocol protocol = crossover(2);
  const Counterbalancing four = counterbalancing(protocol, subjects(4));
  CHECK(four.filled());
  CHECK(four.warning().empty());
  const Counterbalancing five = counterbalancing(protocol, subjects(5));
  CHECK_FALSE(five.filled());
  const BalanceFactor& sequence = factor(five, "sequence");
  REQUIRE(sequence.levels == std::vector<std::string>{"AB", "BA"});
  CHECK(sequence.subjects == std::vector<std::size_t>{3, 2});
  CHECK(factor(five, "set pairing").levels == std::vector<std::string>{"A:s1 B:s2", "A:s2 B:s1"});
  const std::string warning = five.warning();
  CHECK(warning.find("N=5 does not fill the counterbalancing square of 4 subjects") != std::string::npos);
  CHECK(warning.find("sequence BA with 2 subjects and AB with 3") != std::string::npos);
  // Two subjects: each sequence once, but one pairing only.
  const Counterbalancing two = counterbalancing(protocol, subjects(2));
  CHECK(factor(two, "sequence").subjects == std::vector<std::size_t>{1, 1});
  CHECK(factor(two, "set pairing").subjects == std::vector<std::size_t>{2, 0});
  CHECK(two.warning().find("set pairing A:s2 B:s1 with 0 subjects and A:s1 B:s2 with 2") !=
        std::string::npos);
}

TEST_CASE("a Williams crossover of three conditions has six sequences", "[study][balance]") {
  const Counterbalancing balance = counterbalancing(crossover(3), subjects(18));
  CHECK(balance.filled());
  const BalanceFactor& sequence = factor(balance, "sequence");
  CHECK(sequence.levels.size() == 6);
  for (const std::size_t count : sequence.subjects) CHECK(count == 3);
  CHECK(factor(balance, "set pairing").levels.size() == 3);
  CHECK_FALSE(counterbalancing(crossover(3), subjects(6)).filled());  // sequences even, pairings not
}

TEST_CASE("between-subjects groups and within-subjects orders make their square", "[study][balance]") {
  const StudyProtocol between = parse_study_protocol(
      R"({"name": "b", "conditions": [{"name": "F", "mode": "vision"}, {"name": "G", "mode": "haptic"},
           {"name": "H", "mode": "fading"}],
          "phases": [{"phase": "training", "conditions": ["F", "G", "H"], "assignment": "between-subjects",
                      "characters": ["十"]}]})",
      "b.json");
  CHECK(counterbalancing_square(between) == 3);
  const Counterbalancing four = counterbalancing(between, subjects(4));
  CHECK(factor(four, "group").subjects == std::vector<std::size_t>{2, 1, 1});
  CHECK(four.warning().find("group G with 1 subject, H with 1 and F with 2") != std::string::npos);
  const StudyProtocol latin = parse_study_protocol(
      R"({"name": "l", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"},
           {"name": "C", "mode": "fading"}],
          "test": {"characters": ["十"], "conditions": ["A", "B", "C"], "repetitions": 1}, "order": {"conditions": "latin_square"}})",
      "l.json");
  CHECK(counterbalancing_square(latin) == 6);
  CHECK(counterbalancing(latin, subjects(6)).factors.front().levels.size() == 6);
  const StudyProtocol fixed = parse_study_protocol(
      R"({"name": "f", "conditions": [{"name": "A", "mode": "vision"}],
          "test": {"characters": ["十"], "conditions": ["A"], "repetitions": 1}})",
      "f.json");
  CHECK(counterbalancing_square(fixed) == 1);
  CHECK(counterbalancing(fixed, subjects(5)).filled());
}

TEST_CASE("each phase's trials are where plan_session puts them", "[study][balance]") {
  const StudyProtocol protocol = crossover(2);
  for (std::size_t n = 1; n <= 4; ++n) {
    const SubjectAssignment subject{subject_id(n), n};
    const std::vector<PlannedTrial> trials = plan_session(protocol, subject);
    const std::vector<PlannedPhase> phases = plan_session_phases(protocol, subject);
    REQUIRE(phases.size() == 2);
    CHECK(phases[0].first_trial == 0);
    CHECK(phases[0].trials == 2);
    CHECK(phases[1].first_trial == 2);
    CHECK(phases[1].trials + phases[1].first_trial == trials.size());
    const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
    CHECK(phases[1].blocks == crossover.conditions);
    CHECK(phases[1].block_sets == crossover.sets);
    for (std::size_t i = phases[1].first_trial; i < trials.size(); ++i)
      CHECK(trials[i].phase == phases[1].phase->kind);
  }
}

TEST_CASE("a square no study reaches is said, and a mixed design's sequences alternate subject by subject",
          "[study][balance]") {
  // Between-subjects phases of 23, 25 and 26 conditions: the groups repeat every 14,950 subjects, the square
  // beside a 2x2 crossover is 59,800.
  // The first n conditions as a JSON list, and every condition defined (appended: GCC 12 at -O3 warns wrongly
  // about "x" + std::string).
  const auto first = [](int n) {
    std::string listed = "[";
    for (int i = 1; i <= n; ++i)
      listed.append(i == 1 ? "\"c" : ", \"c").append(std::to_string(i)).append("\"");
    return listed.append("]");
  };
  std::string conditions;
  for (int i = 1; i <= 26; ++i) {
    conditions.append(i == 1 ? "" : ", ").append(R"({"name": "c)").append(std::to_string(i));
    conditions.append(R"(", "mode": "vision"})");
  }
  const std::string names = first(26);
  const StudyProtocol protocol =
      parse_study_protocol(R"({"name": "huge", "conditions": [)" + conditions + R"(],
          "item_sets": [{"name": "s1", "characters": ["十"]}, {"name": "s2", "characters": ["人"]}],
          "phases": [
            {"phase": "practice", "conditions": )" +
                               names + R"(, "assignment": "between-subjects", "characters": ["口"]},
            {"phase": "training", "conditions": )" +
                               first(23) + R"(, "assignment": "between-subjects", "characters": ["大"]},
            {"phase": "training", "conditions": )" +
                               first(25) + R"(, "assignment": "between-subjects", "characters": ["山"]},
            {"phase": "training", "conditions": ["c1", "c2"], "assignment": "crossover", "sets": ["s1", "s2"]}]})",
                           "huge.json");
  CHECK(counterbalancing_square(protocol) == 59800);
  const Counterbalancing eight = counterbalancing(protocol, subjects(8));
  CHECK_FALSE(eight.reachable());
  CHECK(eight.groups == 14950);
  const std::string warning = eight.warning();
  CHECK_THAT(warning, Catch::StartsWith("a full counterbalancing square is 59,800 subjects (the "
                                        "between-subjects groups alone repeat every 14,950), more than any "
                                        "study can recruit (at most 1,000): no N balances this design; N=8"));
  CHECK_THAT(warning, Catch::Contains("group: 14,942 of its 14,950 levels with 0 subjects, 8 with 1"));
  CHECK(warning.size() < 400);
  // Every subject its own group, and the crossover's cells in turn: sequence and pairing balanced over 4.
  CHECK(factor(eight, "sequence").subjects == std::vector<std::size_t>{4, 4});
  CHECK(factor(eight, "set pairing").subjects == std::vector<std::size_t>{4, 4});
  for (std::size_t n = 1; n <= 8; ++n) {
    const auto [group, sequence, rotation] = assignment(protocol, n);
    CHECK(sequence == (n % 2 == 1 ? "AB" : "BA"));
    CHECK(rotation == ((n - 1) / 2) % 2);
  }
  // A square a study can reach is not said to be beyond one.
  CHECK(counterbalancing(crossover(2), subjects(5)).reachable());
  CHECK_THAT(counterbalancing(crossover(2), subjects(5)).warning(), Catch::StartsWith("N=5 does not fill"));
}

TEST_CASE("a within-subjects order beside between-subjects groups gives every group every order",
          "[study][balance]") {
  // Two groups beside tests in a Latin-square order of two conditions (and the same in ABBA): counted by
  // number alone, every subject of a group would write one order.
  for (const std::string order : {"latin_square", "abba"}) {
    const StudyProtocol protocol = parse_study_protocol(
        R"({"name": "gw", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"}],
            "phases": [{"phase": "pre-test", "conditions": ["A", "B"], "characters": ["十"], "repetitions": 2},
                       {"phase": "training", "conditions": ["A", "B"], "assignment": "between-subjects",
                        "characters": ["十"]}],
            "order": {"conditions": ")" +
            order + R"("}})",
        "gw.json");
    CAPTURE(order);
    const std::size_t square = counterbalancing_square(protocol);
    CHECK(square == 4);
    std::map<std::pair<std::string, std::string>, int> cells;
    for (std::size_t n = 1; n <= 2 * square; ++n) {
      const SubjectAssignment subject{subject_id(n), n};
      const std::vector<std::string> blocks = block_conditions(protocol, protocol.phases.front(), subject);
      ++cells[{subject_group(protocol, subject), blocks.front()}];
    }
    CHECK(cells.size() == 4);  // (group, first condition): A A, A B, B A, B B
    for (const auto& [cell, count] : cells) CHECK(count == 2);
    // Without groups the order is the number's, as before: subject 1 the listed order, subject 2 the other.
    const StudyProtocol alone = parse_study_protocol(
        R"({"name": "w", "conditions": [{"name": "A", "mode": "vision"}, {"name": "B", "mode": "haptic"}],
            "test": {"characters": ["十"], "conditions": ["A", "B"], "repetitions": 2},
            "order": {"conditions": ")" +
            order + R"("}})",
        "w.json");
    CHECK(block_conditions(alone, alone.phases.back(), {subject_id(1), 1}).front() == "A");
    CHECK(block_conditions(alone, alone.phases.back(), {subject_id(2), 2}).front() == "B");
    CHECK(counterbalancing_square(alone) == 2);
  }
}
