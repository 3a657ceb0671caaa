#include "trainer/session_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <nlohmann/json.hpp>
#include <system_error>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/report/atomic_file.hpp"

namespace calligraphy::trainer {
namespace {

constexpr int kMaxTrialNumber = 100000;

nlohmann::json loop_json(const ServoLoopStats& loop) {
  return {{"ticks", loop.ticks},
          {"late_ticks", loop.late_ticks},
          {"forces_withheld", loop.forces_withheld},
          {"longest_stall_s", loop.longest_stall_s},
          {"period_jitter_us_p50", loop.period_jitter_us_p50},
          {"period_jitter_us_p99", loop.period_jitter_us_p99},
          {"period_jitter_us_max", loop.period_jitter_us_max},
          {"callback_us_p99", loop.callback_us_p99},
          {"fifo_scheduling", loop.realtime.fifo_scheduling}};
}

}  // namespace

std::string trial_record_json(const TrialRecordInfo& info, const TrialResult& result) {
  nlohmann::json doc = nlohmann::json::parse(trial_json(info.description, result));
  doc["subject"] = info.subject;
  doc["condition"] = info.condition;
  doc["start_time"] = info.start_time_utc;
  doc["library_version"] = info.library_version;
  doc["device_model"] = info.description.device_model;
  if (result.loop) doc["servo_loop"] = loop_json(*result.loop);
  return doc.dump(2) + "\n";
}

SavedTrial save_trial(const std::filesystem::path& folder, const TrialRecordInfo& info, const Scene& scene,
                      const TrialResult& result) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw DataError(folder.string() + ": cannot create the session folder (" + ec.message() + ")");
  const std::string stem = info.subject + "-" + info.description.characters + "-";
  for (int n = 1; n <= kMaxTrialNumber; ++n) {
    SavedTrial saved{folder / (stem + std::to_string(n) + ".json"),
                     folder / (stem + std::to_string(n) + ".csv"),
                     folder / (stem + std::to_string(n) + ".svg")};
    if (std::filesystem::exists(saved.csv, ec) || std::filesystem::exists(saved.svg, ec)) continue;
    const int fd = ::open(saved.json.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      throw DataError(saved.json.string() + ": cannot create (" + std::strerror(errno) + ")");
    }
    ::close(fd);  // the name is ours now; the atomic writes below replace the empty file
    write_file_atomically(saved.json, trial_record_json(info, result));
    write_file_atomically(saved.csv, trial_csv(result.trace));
    write_file_atomically(saved.svg, trial_svg(scene, result));
    return saved;
  }
  throw DataError(folder.string() + ": more than " + std::to_string(kMaxTrialNumber) + " trials named " +
                  stem + "N already");
}

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

void check_subject_id(const std::string& subject) {
  bool ok = !subject.empty() && subject.size() <= 64 && subject.front() != '.';
  for (const char c : subject) {
    ok = ok && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' ||
                c == '_' || c == '-');
  }
  if (!ok) {
    throw InvalidArgument("subject id '" + subject +
                          "' must be 1-64 characters of A-Z a-z 0-9 . _ - (it is part of file names)");
  }
}

}  // namespace calligraphy::trainer
