#include "eval/corpus_report.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "report/appendf.hpp"

namespace calligraphy::cli {
namespace {

double bytes_per_character(const CorpusStoreInfo& info) {
  return info.character_count
             ? static_cast<double>(info.file_bytes) / static_cast<double>(info.character_count)
             : 0.0;
}

}  // namespace

std::string corpus_build_text(const std::string& store_name, const std::string& library_description,
                              const CorpusFit& fit, const CorpusStoreOptions& options, std::size_t bytes,
                              const CorpusBuildTimes& times) {
  std::string out;
  appendf(out, "corpus store %s from %s\n", store_name.c_str(), library_description.c_str());
  appendf(out, "  characters          %zu\n", fit.characters.size());
  appendf(out, "  not modelled        %zu\n", fit.failures.size());
  for (const auto& f : fit.failures) {
    appendf(out, "    %s: %s\n", describe_character(f.code_point).c_str(), f.reason.c_str());
  }
  appendf(out, "  tolerance           %.3g data units, quantisation 1/%d unit\n", options.fit_tolerance,
          options.steps_per_unit);
  appendf(
      out, "  store               %zu bytes, %.1f bytes per character\n", bytes,
      fit.characters.empty() ? 0.0 : static_cast<double>(bytes) / static_cast<double>(fit.characters.size()));
  appendf(out,
          "  time                %.2f s total: read+fit %.2f s wall on %u threads (summed over threads: "
          "read+parse %.2f s, fit %.2f s), encode+write %.3f s\n",
          times.total_s, fit.wall_s, fit.threads, fit.read_parse_cpu_s, fit.fit_cpu_s, times.encode_write_s);
  return out;
}

std::string corpus_stats_json(const CorpusStore& store, const CorpusStoreStats& stats) {
  const CorpusStoreInfo& info = store.info();
  nlohmann::json histogram = nlohmann::json::array();
  for (const auto& [id, count] : stats.strokes_by_typical_id) {
    histogram.push_back(
        {{"id", id}, {"acronym", std::string(typical_stroke(id).acronym)}, {"strokes", count}});
  }
  const nlohmann::json doc = {
      {"file", store.name()},
      {"format_version", std::to_string(info.version_major) + "." + std::to_string(info.version_minor)},
      {"medians", info.medians},
      {"outlines", info.outlines},
      {"characters", info.character_count},
      {"strokes", stats.strokes},
      {"elements", stats.elements},
      {"bytes", info.file_bytes},
      {"bytes_per_character", bytes_per_character(info)},
      {"fit_tolerance", info.fit_tolerance},
      {"steps_per_unit", info.steps_per_unit},
      {"checksums_ok", stats.errors.empty()},
      {"errors", stats.errors},
      {"typical_stroke_histogram", histogram}};
  return json_text(doc, 2) + "\n";
}

std::string corpus_stats_text(const CorpusStore& store, const CorpusStoreStats& stats) {
  const CorpusStoreInfo& info = store.info();
  const std::string checksums = stats.errors.empty() ? "ok (header, index and every record)"
                                                     : std::to_string(stats.errors.size()) + " bad records";
  std::string out;
  appendf(out, "corpus store %s\n", store.name().c_str());
  appendf(out, "  format version      %d.%d (%s)\n", info.version_major, info.version_minor,
          info.outlines  ? (info.medians ? "models, medians and outlines" : "models and outlines")
          : info.medians ? "models and medians"
                         : "models only, no medians");
  appendf(out, "  characters          %zu\n", info.character_count);
  appendf(out, "  strokes             %zu\n", stats.strokes);
  appendf(out, "  elements            %zu (%.2f per stroke)\n", stats.elements,
          stats.strokes ? static_cast<double>(stats.elements) / static_cast<double>(stats.strokes) : 0.0);
  appendf(out, "  bytes               %zu (header %zu, index %zu, records %zu); %.1f per character\n",
          info.file_bytes, info.header_bytes, info.index_bytes, info.record_bytes, bytes_per_character(info));
  appendf(out, "  fit tolerance       %.3g data units; quantisation 1/%d unit (max error %.3f units)\n",
          info.fit_tolerance, info.steps_per_unit, info.max_quantisation_error());
  appendf(out, "  checksums           %s\n", checksums.c_str());
  out += "  typical strokes:\n";
  for (const auto& [id, count] : stats.strokes_by_typical_id) {
    appendf(
        out, "    %2d %-6s %-8s %7zu  %5.2f %%\n", id, std::string(typical_stroke(id).acronym).c_str(),
        std::string(typical_stroke(id).name_zh).c_str(), count,
        100.0 * static_cast<double>(count) / static_cast<double>(std::max<std::size_t>(1, stats.strokes)));
  }
  return out;
}

}  // namespace calligraphy::cli
