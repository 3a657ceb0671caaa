#include "calligraphy/study/session_series.hpp"

#include <map>

#include "calligraphy/core/errors.hpp"
#include "study/json_reader.hpp"
#include "study/names.hpp"
#include "study/saved_sessions.hpp"

namespace calligraphy {
namespace fs = std::filesystem;

SessionSeries session_series(const fs::path& root, const std::string& subject_id,
                             const LoadedProtocol& protocol) {
  SessionSeries series;
  series.sessions = protocol.protocol.session_count();
  const fs::path subject_folder = root / subject_id;
  std::error_code error;
  std::map<int, std::pair<fs::path, SessionManifest>> by_number;  // the newest folder of each number
  if (fs::is_directory(subject_folder, error)) {
    for (const fs::path& folder : find_session_folders(subject_folder)) {
      SessionManifest manifest = study_detail::read_session_manifest(folder);
      if (manifest.protocol.sha256 != protocol.sha256) continue;
      const int number = manifest.setup.session_number;
      const auto known = by_number.find(number);
      if (known == by_number.end() || known->second.second.created_utc <= manifest.created_utc) {
        by_number[number] = {folder, std::move(manifest)};
      }
    }
  }
  for (int number = 1; number <= series.sessions; ++number) {
    const auto found = by_number.find(number);
    if (found == by_number.end()) break;
    const auto& [folder, manifest] = found->second;
    series.folders.push_back(folder);
    series.next = number + 1;
    const PlannedTrial& last = manifest.plan.back();
    const fs::path last_record = folder / "trials" / (SessionFolder::trial_stem(last) + ".json");
    if (!fs::exists(last_record, error)) {
      series.unfinished = folder;
      series.next = number;
      series.previous.reset();
      return series;
    }
    if (number == series.sessions) continue;
    // What links the next session to this one: its last trial's end and the next session's delay.
    PreviousSession previous;
    previous.session_id = manifest.session_id;
    const nlohmann::json record = study_detail::read_trial_record(last_record);
    const study_detail::JsonView view(record, "", last_record.string());
    previous.ended_utc = view.string_or("end_time_utc", manifest.created_utc);
    try {
      (void)study_detail::utc_seconds(previous.ended_utc);
    } catch (const InvalidArgument& e) {
      study_detail::fail(last_record.string(), "/end_time_utc", e.what());
    }
    for (const ProtocolPhase& phase : protocol.protocol.phases) {
      if (phase.session == number + 1) {
        previous.delay_s = phase.delay_s;
        break;
      }
    }
    previous.elapsed_s = study_detail::utc_seconds(study_detail::utc_now_iso8601()) -
                         study_detail::utc_seconds(previous.ended_utc);
    series.previous = std::move(previous);
  }
  if (series.next > series.sessions) series.previous.reset();
  return series;
}

}  // namespace calligraphy
