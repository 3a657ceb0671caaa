#include "calligraphy/trial/result.hpp"

namespace calligraphy {

const char* to_string(TrialEnd end) noexcept {
  switch (end) {
    case TrialEnd::completed:
      return "completed";
    case TrialEnd::time_limit:
      return "time_limit";
    case TrialEnd::device_fault:
      return "device_fault";
    case TrialEnd::watchdog:
      return "watchdog";
    case TrialEnd::interrupted:
      return "interrupted";
    case TrialEnd::gave_up:
      return "gave_up";
    case TrialEnd::writer_finished:
      return "writer_finished";
  }
  return "unknown";
}

std::vector<PenSample> pen_samples(const Scene& scene, std::span<const TrialSample> trace) {
  std::vector<PenSample> samples;
  samples.reserve(trace.size());
  for (const TrialSample& s : trace) {
    samples.push_back(
        {s.time_s, s.position_m.head<2>(), s.position_m.z() - scene.layout.paper_z_m <= kPenContactThresholdM});
  }
  return samples;
}

WritingMetrics trial_writing_metrics(const Scene& scene, const TrialResult& result,
                                     const StrokeAcceptance& acceptance) {
  ScoreOptions options;
  options.acceptance = acceptance;
  return writing_metrics(scene, pen_samples(scene, result.trace), options);
}

}  // namespace calligraphy
