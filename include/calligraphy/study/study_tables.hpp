#pragma once
/// \file study_tables.hpp
/// A study as tidy tables (Wickham 2014, "Tidy data", J Stat Softw 59(10)): one row per saved trial and one
/// row per reference stroke of each saved trial, read from session folders (session_folder.hpp) by the one
/// reader of sessions (session_reader.hpp). The metrics are the one metrics record each trial record holds
/// (writing_metrics.hpp), in SI units with the unit in every column name; indices count from 1 (trial,
/// block, item, repetition, character, stroke), as the trial files' numbers (001-..., r1) and session
/// numbers do. `calligraphy report --csv DIR` writes them as CSV and
/// Python's `calligraphy.study.load` gives them as pandas DataFrames. The traces are not read: a row names
/// its trace file, read on demand. Columns and meaning: docs/experiments.md ("Tidy tables").
#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calligraphy/analysis/metric_table.hpp"

namespace calligraphy {

/// One saved trial.
struct TrialRow {
  std::string subject;
  std::string session;     ///< the session folder's name
  std::string protocol;    ///< the protocol's name
  int session_number = 1;  ///< which of the protocol's sessions (1-based; a retention test a day later: 2)
  std::string group;       ///< the subject's between-subjects group (`subject_group`); "" when none
  std::string phase;  ///< "practice", "test", "pre-test", "training", "post-test", "retention", "transfer"
  std::size_t block = 1;       ///< 1-based block of the session's plan
  std::string condition;       ///< the condition's name
  std::string mode;            ///< the condition's mode ("vision", "haptic", "fading", "replay", "quiz")
  std::string characters;      ///< UTF-8, written left to right
  std::size_t trial = 1;       ///< 1-based position in the session's plan (the NNN of its files)
  std::size_t item = 1;        ///< 1-based position of `characters` in the phase's list
  std::size_t repetition = 1;  ///< 1-based repetition of the item in the condition (the rN of its files)
  std::string item_set;        ///< the item's set (`item_sets`); "" when the phase lists characters
  /// The subject's crossover sequence ("AB", "BA", ...; A the crossover phase's first listed condition); ""
  /// when the protocol has no crossover phase.
  std::string sequence;
  /// The 1-based crossover period in which the item's set is trained (a transfer set: its source's); absent
  /// when the set is not trained in the crossover.
  std::optional<int> period;
  /// The condition the item is or was trained under in the crossover, on every phase's row; "" when none.
  std::string trained_condition;
  std::string writer;  ///< "simulated" or "person"
  /// A simulated writer's profile ("novice", "skilled", "foreign") and learning model ("none", "two-state");
  /// "" for a person.
  std::string writer_profile;
  std::string writer_learning;
  std::string end_reason;  ///< how the trial ended (TrialEnd as text)
  std::string start_utc;   ///< ISO 8601
  /// The record's metrics that are columns of the trials table (the metric table's `trials_column`: the
  /// matching's counts, completed_in_order, the deviations, times, fluency and strokes_assisted), read by
  /// name: `metrics.number("mean_deviation_m")`; a number is null when nothing was matched.
  MetricValues metrics{StudyTable::trials};
  /// A learning simulated writer's skills before the trial, in [0, 1] (docs/writer.md, "Memory"); absent
  /// otherwise.
  std::optional<double> shape_skill;
  std::optional<double> order_skill;
  std::optional<double> timing_skill;
  /// A simulated subject's traits (sim/subject_traits.hpp, docs/writer.md "Individual differences"): factors
  /// on its profile (dimensionless) and its two-state rates per trial; absent when subjects do not differ.
  std::optional<double> subject_writing_speed_factor;
  std::optional<double> subject_spatial_error_factor;
  std::optional<double> subject_error_rate_factor;
  std::optional<double> subject_motor_noise_factor;
  std::optional<double> subject_fast_learning_per_trial;
  std::optional<double> subject_slow_learning_per_trial;
  std::optional<double> subject_fast_retention_per_trial;
  std::optional<double> subject_slow_retention_per_trial;
  /// Strokes a simulated writer gave up on after its last attempt and left (docs/writer.md, "Give-up and
  /// retries"); absent for a person and for records from before it was kept.
  std::optional<double> strokes_given_up;
  /// Shares of the trial's characters that an independent recogniser (zinnia) ranked first, and among its
  /// first five, reading the final writing (legibility/legibility.hpp); absent without a recogniser.
  std::optional<double> legibility_top1;
  std::optional<double> legibility_top5;
  std::filesystem::path trace_file;  ///< the trial's trace (HDF5; a CSV in folders written before it)
  /// Lower-case hex SHA-256 of the trace file as saved (the record's files.trace_sha256): a reader of the
  /// trace checks it. Empty for records written before traces were bound to them.
  std::string trace_sha256;
};

/// One reference stroke of one saved trial.
struct StrokeRow {
  std::string subject;
  std::string session;
  std::size_t trial = 1;  ///< the trial's `TrialRow::trial`
  std::string phase;
  std::string condition;
  std::size_t character = 1;   ///< 1-based position of the character in the trial
  std::string character_text;  ///< UTF-8
  std::size_t stroke = 1;      ///< 1-based position of the stroke in its character (writing order)
  int typical_id = 0;          ///< the typical stroke's fixed ID (1..39)
  bool written = false;        ///< a pen-down segment was matched to it
  bool backwards = false;      ///< it was written from its end
  std::size_t segments =
      0;  ///< pen-down segments the matcher gave this stroke as their expected or matched one
  std::size_t refused_segments = 0;  ///< those refused
  std::string refusal;               ///< the last refused one's reason ("too_short", ...); "" when none
  /// The stroke's metrics that are columns of the strokes table (the metric table's `strokes_column`: its
  /// deviations, time_s, path_length_m), read by name; null for a stroke never written.
  MetricValues metrics{StudyTable::strokes};
};

struct StudyTables {
  std::vector<TrialRow> trials;    ///< sessions sorted by path, trials in planned order
  std::vector<StrokeRow> strokes;  ///< in the order of `trials`, then characters, then strokes
};

/// The tables of every saved trial in the session folders under `roots` (each a session folder or a folder
/// holding some). Reads session.json and each trial's JSON record, never the traces, sessions on `threads`
/// threads at once (0: one a core); the rows are in the same order whatever the threads. The rows' metrics
/// are the metric table's study-table columns. Throws DataError naming the file (and JSON pointer) for a
/// root without a session folder, a damaged manifest or record (one without a metric of the scene's totals
/// that is a trials column).
[[nodiscard]] StudyTables read_study_tables(const std::vector<std::filesystem::path>& roots,
                                            unsigned threads = 0);

/// The trials table as CSV (RFC 4180): a header of the column names, one line per row; absent values empty.
/// The metric columns are those of `metrics` (the metric table; another, as the rows were read with, only to
/// try a metric added to it), in their `trials_column` order, after start_utc.
[[nodiscard]] std::string trials_csv(const StudyTables& tables,
                                     std::span<const MetricInfo> metrics = metric_table());
/// The strokes table as CSV; the metric columns, in their `strokes_column` order, after refusal.
[[nodiscard]] std::string strokes_csv(const StudyTables& tables,
                                      std::span<const MetricInfo> metrics = metric_table());

}  // namespace calligraphy
