#pragma once
// A metric a project might add, for the tests that show one row of the metric table reaching every form:
// the share of the reference strokes written, a number of the scene's totals, at `trials_column` among the
// trials table's metric columns (0: not one of them).
#include <cstdint>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/analysis/writing_metrics.hpp"

namespace calligraphy::testing {

inline MetricInfo written_share_metric(std::uint8_t trials_column) {
  return {
      .name = "written_share",
      .doc = "share of the reference strokes written",
      .definition = "strokes_written / strokes_total",
      .levels = metric_level_scene,
      .of_scene =
          [](const WritingMetrics& m) {
            return MetricValue(static_cast<double>(m.strokes_written) / static_cast<double>(m.strokes_total));
          },
      .trials_column = trials_column};
}

}  // namespace calligraphy::testing
