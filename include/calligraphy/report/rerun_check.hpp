#pragma once
/// \file rerun_check.hpp
/// Does a re-run of a trial record give what the record says its run gave?
#include <string>
#include <vector>

#include "calligraphy/trial/recorded_trial.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

/// The figures in which `result`, a re-run of `recorded` (`rerun_trial`), differs from what the record says
/// its run gave (`RecordedTrial::recorded_outcome`: `end_reason` and the run-level figures of the metric
/// table), each as "NAME recorded X, now Y" with the record's and the re-run's JSON text; empty when they
/// agree, when the record states none (a specification alone), and when the re-run is not meant to repeat the
/// run: a person's trial, one paced by the wall clock (`result.loop`), one interrupted. A simulated writer's
/// lock-step re-run repeats its run bit for bit (docs/cli.md, "Re-running a trial"), so a difference says the
/// record was changed since it was written (a seed past 2^53 written back rounded by a tool that reads JSON
/// numbers as doubles) or another library version ran it.
[[nodiscard]] std::vector<std::string> rerun_differences(const RecordedTrial& recorded,
                                                         const TrialResult& result);

/// One line for the differences: the first three of them and what they say, for a warning.
[[nodiscard]] std::string rerun_differences_text(const RecordedTrial& recorded,
                                                 const std::vector<std::string>& differences);

}  // namespace calligraphy
