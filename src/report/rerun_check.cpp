#include "calligraphy/report/rerun_check.hpp"

#include <cstddef>
#include <nlohmann/json.hpp>

#include "calligraphy/analysis/metric_table.hpp"
#include "report/metrics_object.hpp"
#include "report/trial_outcome.hpp"

namespace calligraphy {

std::vector<std::string> rerun_differences(const RecordedTrial& recorded, const TrialResult& result) {
  std::vector<std::string> differences;
  // Only a run that is meant to repeat: the simulated writer, paced by the device's clock, run to its end.
  if (recorded.spec.writer != TrialWriter::simulated || result.loop || result.end == TrialEnd::interrupted)
    return differences;
  for (const auto& [name, recorded_text] : recorded.recorded_outcome) {
    std::string now;
    if (name == "end_reason") {
      now = nlohmann::json(to_string(result.end)).dump();
    } else {
      for (const MetricInfo& info : metric_table()) {
        if (info.name == name && info.at(metric_level_run))
          now = report_detail::metric_json(report_detail::run_metric_value(info, result.metrics)).dump();
      }
    }
    // Compared as the JSON text each writes: the same double dumps to the same shortest decimal.
    if (!now.empty() && now != recorded_text)
      differences.push_back(name + " recorded " + recorded_text + ", now " + now);
  }
  return differences;
}

std::string rerun_differences_text(const RecordedTrial& recorded,
                                   const std::vector<std::string>& differences) {
  std::string text = "the re-run differs from the run the record states (";
  for (std::size_t i = 0; i < differences.size() && i < 3; ++i) text += (i == 0 ? "" : "; ") + differences[i];
  if (differences.size() > 3) text += "; " + std::to_string(differences.size() - 3) + " more";
  text +=
      "): the record was changed since it was written (a seed past 2^53 written back rounded by a tool "
      "that reads JSON numbers as doubles, such as jq 1.6 or Node), or another library ran it (" +
      (recorded.library_version.empty() ? std::string("unknown") : recorded.library_version) + ")";
  return text;
}

}  // namespace calligraphy
