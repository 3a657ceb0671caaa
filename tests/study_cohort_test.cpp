// A simulated cohort in memory (cohort.hpp) is the same study as session folders: for the same protocol,
// subjects, profile and learning, its rows equal those read from the folders `session run` makes, trial by
// trial and stroke by stroke, over two sessions, every adaptive schedule and a between-subjects design; its
// threads change nothing; and what it cannot do (a replay, a bad setup) is refused by name.
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/sim/subject_traits.hpp"
#include "calligraphy/study/cohort.hpp"
#include "calligraphy/study/session_runner.hpp"
#include "calligraphy/study/session_series.hpp"
#include "calligraphy/study/study_tables.hpp"
#include "study_test_devices.hpp"
#include "temp_folder.hpp"
#include "test_sizing.hpp"

using namespace calligraphy;

namespace {

// Under the sanitizers the tests that compare rows run one training character and trials of at most 10 s
// (a trial there runs ten times slower); the Release build runs the whole protocol in every test.
constexpr bool kSmall = calligraphy::testing::kSanitizedBuild;

// Two days, a group per schedule that adapts or pushes, a learning memory to carry over.
LoadedProtocol two_day_protocol(bool small = false) {
  std::string text(
      R"({"name": "cohort", "conditions": [
            {"name": "free", "mode": "vision"},
            {"name": "fading", "mode": "fading"},
            {"name": "band", "mode": "assist-as-needed", "parameters": {"start_band_m": 0.0005}},
            {"name": "adapt", "mode": "skill-adaptive", "parameters": {"threshold_m": 0.0012}},
            {"name": "push", "mode": "error-amplification"}],
          "phases": [
            {"phase": "pre-test", "condition": "free", "characters": ["十"]},
            {"phase": "training", "conditions": ["fading", "band", "adapt", "push"],
             "assignment": "between-subjects", "characters": )");
  text.append(small ? R"(["十"])" : R"(["十", "人"])");
  text.append(R"(, "repetitions": 2},
            {"phase": "post-test", "condition": "free", "characters": ["十"]},
            {"phase": "retention", "condition": "free", "characters": ["十"], "session": 2, "delay_s": 86400},
            {"phase": "transfer", "condition": "free", "characters": ["口"], "session": 2}],
          "trial": {"max_duration_s": )");
  text.append(small ? "10" : "40");
  text.append("}}");
  return protocol_from_text(text, "cohort.json");
}

// Every session of each subject through session folders, as `calligraphy session run` does.
StudyTables through_folders(const std::filesystem::path& root, const LoadedProtocol& protocol,
                            const std::vector<SubjectAssignment>& subjects, const CohortSetup& cohort) {
  for (const SubjectAssignment& subject : subjects) {
    for (int number = 1; number <= protocol.protocol.session_count(); ++number) {
      SessionSetup setup;
      setup.subject = subject;
      setup.writer_profile = cohort.writer_profile;
      setup.writer_seed = subject_seed(subject.id);
      setup.writer_learning = cohort.writer_learning;
      setup.individual_differences = cohort.individual_differences;
      setup.session_number = number;
      std::optional<PreviousSession> previous = session_series(root, subject.id, protocol).previous;
      if (previous) previous->delay = SessionDelay::simulated;
      SessionFolder session = SessionFolder::create(root, setup, protocol, previous);
      REQUIRE(run_session(session, study_test::run_options()).complete());
    }
  }
  return read_study_tables({root});
}

// Rows equal but for what only a folder has: its name, the start time, the trace file.
void check_same_trials(const TrialRow& a, const TrialRow& b) {
  INFO(a.subject << " session " << a.session_number << " trial " << a.trial);
  CHECK(a.subject == b.subject);
  CHECK(a.session_number == b.session_number);
  CHECK(a.group == b.group);
  CHECK(a.phase == b.phase);
  CHECK(a.condition == b.condition);
  CHECK(a.mode == b.mode);
  CHECK(a.characters == b.characters);
  CHECK(a.trial == b.trial);
  CHECK(a.repetition == b.repetition);
  CHECK(a.end_reason == b.end_reason);
  // every metric column (the matching's counts, the deviations, times and fluency)
  REQUIRE(a.metrics.names().size() == b.metrics.names().size());
  for (const std::string_view name : a.metrics.names()) {
    INFO(name);
    CHECK(a.metrics.at(name) == b.metrics.at(name));
  }
  CHECK(a.shape_skill == b.shape_skill);
  CHECK(a.order_skill == b.order_skill);
  CHECK(a.timing_skill == b.timing_skill);
  CHECK(a.subject_writing_speed_factor == b.subject_writing_speed_factor);
  CHECK(a.subject_fast_learning_per_trial == b.subject_fast_learning_per_trial);
}

}  // namespace

TEST_CASE("a cohort in memory gives the rows of the same subjects' session folders", "[study][cohort]") {
  TempFolder temp;
  LoadedProtocol protocol = two_day_protocol(kSmall);
  const std::vector<SubjectAssignment> subjects = numbered_subjects(4, "C");
  CohortSetup setup;
  setup.writer_profile = "foreign";
  const StudyTables folders = through_folders(temp.path, protocol, subjects, setup);
  const StudyTables memory = simulate_cohort(protocol, subjects, setup, 2);
  REQUIRE(memory.trials.size() == folders.trials.size());
  REQUIRE(memory.trials.size() == 4 * (kSmall ? 6 : 8));
  for (std::size_t i = 0; i < memory.trials.size(); ++i) {
    check_same_trials(memory.trials[i], folders.trials[i]);
    CHECK(memory.trials[i].session ==
          "cohort-" + memory.trials[i].subject + "-s" + std::to_string(memory.trials[i].session_number));
    CHECK(memory.trials[i].trace_file.empty());
  }
  REQUIRE(memory.strokes.size() == folders.strokes.size());
  for (std::size_t i = 0; i < memory.strokes.size(); ++i) {
    CHECK(memory.strokes[i].typical_id == folders.strokes[i].typical_id);
    CHECK(memory.strokes[i].metrics.number("mean_deviation_m") ==
          folders.strokes[i].metrics.number("mean_deviation_m"));
  }
  // The memory learned: skills recorded on every trial, and the groups are the four schedules.
  std::vector<std::string> groups;
  for (const TrialRow& row : memory.trials) {
    CHECK(row.shape_skill.has_value());
    CHECK(row.timing_skill.has_value());
    if (groups.empty() || groups.back() != row.group) groups.push_back(row.group);
  }
  CHECK(groups == std::vector<std::string>{"fading", "band", "adapt", "push"});
}

TEST_CASE("a cohort's subjects differ, each by the traits its id draws, unless told otherwise",
          "[study][cohort][subjects]") {
  LoadedProtocol protocol = two_day_protocol();
  const std::vector<SubjectAssignment> subjects = numbered_subjects(4);
  CohortSetup setup;
  setup.writer_profile = "foreign";
  const StudyTables differ = simulate_cohort(protocol, subjects, setup, 2);
  setup.individual_differences = false;
  const StudyTables alike = simulate_cohort(protocol, subjects, setup, 2);
  REQUIRE(differ.trials.size() == alike.trials.size());
  std::vector<double> speeds;
  for (std::size_t i = 0; i < differ.trials.size(); ++i) {
    const TrialRow& row = differ.trials[i];
    const SubjectTraits traits = draw_subject_traits(subject_seed(row.subject));
    REQUIRE(row.subject_writing_speed_factor.has_value());
    CHECK(*row.subject_writing_speed_factor == traits.writing_speed_factor);
    CHECK(*row.subject_spatial_error_factor == traits.spatial_error_factor);
    CHECK(*row.subject_slow_learning_per_trial == traits.learning.slow_learning);
    if (speeds.empty() || speeds.back() != *row.subject_writing_speed_factor)
      speeds.push_back(*row.subject_writing_speed_factor);
    CHECK_FALSE(alike.trials[i].subject_writing_speed_factor.has_value());
  }
  CHECK(speeds.size() == 4);  // one person per subject, none the same
  // Subjects alike write their profile: every subject's pre-test of the same character at the same seed
  // differs only by the seed's draws, so the drawn subjects' spread of writing time is larger.
  const auto spread = [](const StudyTables& tables) {
    double low = 1e9, high = -1e9;
    for (const TrialRow& row : tables.trials) {
      if (row.phase != "pre-test") continue;
      low = std::min(low, *row.metrics.number("total_time_s"));
      high = std::max(high, *row.metrics.number("total_time_s"));
    }
    return high - low;
  };
  CHECK(spread(differ) > spread(alike));
}

TEST_CASE("a cohort's threads change none of its rows", "[study][cohort]") {
  LoadedProtocol protocol = two_day_protocol(kSmall);
  const std::vector<SubjectAssignment> subjects = numbered_subjects(3);
  CohortSetup setup;
  setup.writer_learning = WriterLearning::none;
  std::size_t reported = 0;
  const StudyTables one =
      simulate_cohort(protocol, subjects, setup, 1, [&](std::size_t done) { reported = done; });
  const StudyTables three = simulate_cohort(protocol, subjects, setup, 3);
  CHECK(reported == 3);
  REQUIRE(one.trials.size() == three.trials.size());
  for (std::size_t i = 0; i < one.trials.size(); ++i) {
    check_same_trials(one.trials[i], three.trials[i]);
    CHECK_FALSE(one.trials[i].shape_skill.has_value());  // no memory without learning
  }
  CHECK(trials_csv(one) == trials_csv(three));
}

TEST_CASE("a cohort asked to stop ends its running trials and starts no subject more", "[study][cohort]") {
  LoadedProtocol protocol = two_day_protocol(kSmall);
  const std::vector<SubjectAssignment> subjects = numbered_subjects(6);
  CohortSetup setup;
  setup.writer_learning = WriterLearning::none;
  std::atomic<int> polls{0};
  // Stops at the 200th tick of the first trial polled, from whichever of the two threads gets there.
  setup.should_stop = [&polls] { return polls.fetch_add(1) >= 200; };
  std::size_t done = 0;
  CHECK_THROWS_WITH(simulate_cohort(protocol, subjects, setup, 2, [&](std::size_t n) { done = n; }),
                    Catch::Contains("interrupted") && Catch::Contains("was not kept"));
  CHECK(done == 0);  // no subject of several trials each was finished
  CHECK_THROWS_AS(simulate_subject(protocol, subjects[0], setup), StateError);
  setup.should_stop = [] { return false; };  // a poll that never stops changes nothing
  CohortSetup plain;
  plain.writer_learning = WriterLearning::none;
  CHECK(trials_csv(simulate_cohort(protocol, {subjects[0]}, setup)) ==
        trials_csv(simulate_cohort(protocol, {subjects[0]}, plain)));
}

TEST_CASE("a cohort refuses what it cannot run, naming it", "[study][cohort]") {
  const LoadedProtocol replay = protocol_from_text(
      R"({"name": "r", "conditions": [{"name": "teacher", "mode": "replay"}],
          "test": {"characters": ["十"], "conditions": ["teacher"], "repetitions": 1}})",
      "r.json");
  CHECK_THROWS_WITH(simulate_cohort(replay, numbered_subjects(1), {}),
                    Catch::Contains("condition 'teacher'"));
  CohortSetup bad;
  bad.writer_profile = "expert";
  CHECK_THROWS_WITH(simulate_subject(two_day_protocol(), {"S01", 1}, bad),
                    Catch::Contains("CohortSetup.writer_profile"));
  bad = {};
  bad.writer_learning = static_cast<WriterLearning>(7);  // outside the table
  CHECK_THROWS_WITH(simulate_subject(two_day_protocol(), {"S01", 1}, bad),
                    Catch::Contains("CohortSetup.writer_learning"));
  CHECK_THROWS_AS(simulate_cohort(two_day_protocol(), numbered_subjects(1), {}, 0), InvalidArgument);
  CHECK_THROWS_AS(numbered_subjects(0), InvalidArgument);
  // The bound of every entry (CLI, Python, library), refused before anything is made or run.
  CHECK(numbered_subjects(kMaxCohortSubjects).size() == kMaxCohortSubjects);
  CHECK_THROWS_WITH(numbered_subjects(kMaxCohortSubjects + 1), Catch::Contains("1 to 100000 subjects"));
  const std::vector<SubjectAssignment> too_many(kMaxCohortSubjects + 1, SubjectAssignment{"S01", 1});
  CHECK_THROWS_WITH(simulate_cohort(two_day_protocol(), too_many, {}), Catch::Contains("at most 100000"));
  CHECK_THROWS_WITH(numbered_subjects(2, "a/b"), Catch::Contains("subject prefix 'a/b'"));
  CHECK(numbered_subjects(12).back().id == "S12");
  CHECK(numbered_subjects(12).back().number == 12);
  const LoadedProtocol missing = protocol_from_text(
      R"({"name": "m", "conditions": [{"name": "free", "mode": "vision"}],
          "test": {"characters": ["\u9fff"], "conditions": ["free"], "repetitions": 1}})",
      "m.json");
  CHECK_THROWS_AS(simulate_cohort(missing, numbered_subjects(1), {}), CharacterNotFound);
}
