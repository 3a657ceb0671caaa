#include "calligraphy/study/session_series.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <thread>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "core/json_reader.hpp"
#include "core/utc_time.hpp"
#include "study/names.hpp"
#include "study/saved_sessions.hpp"

namespace calligraphy {
namespace fs = std::filesystem;
namespace {

std::string manifest_sha256(const fs::path& folder) {
  return sha256_hex(study_detail::read_session_file(SessionLayout::manifest(folder), kMaxSessionManifestBytes,
                                                    "session manifest"));
}

// Session `number` (> 1) must follow the folder found for the session before it: by name, and by content
// where the link recorded it.
void check_link(const fs::path& folder, const SessionManifest& manifest, const fs::path& before, int number) {
  const std::string source = (SessionLayout::manifest(folder)).string();
  const PreviousSession& previous = *manifest.previous;
  if (previous.session_id != before.filename().string()) {
    json_detail::fail(source, "/previous_session/session_id",
                      "session " + std::to_string(number) + " follows '" + previous.session_id +
                          "', but session " + std::to_string(number - 1) + " is " + before.string() +
                          " (moved, renamed or copied from elsewhere?): put the session it follows back in " +
                          folder.parent_path().string());
  }
  (void)study_detail::read_previous_session(folder, manifest);  // its content, where the link recorded it
}

// Whether any planned trial of the session has no record (not only its last: a record may be lost).
// A session planned before by another assignment (an earlier build of the library) than the protocol now
// gives its subject: the next session would put the subject in another group or crossover sequence than the
// sessions before it, and its trials would be attributed to other conditions.
void check_assignment(const fs::path& folder, const SessionManifest& manifest,
                      const StudyProtocol& protocol) {
  const SubjectAssignment& subject = manifest.setup.subject;
  std::string group;
  CrossoverAssignment crossover;
  try {
    group = subject_group(protocol, subject);
    crossover = crossover_assignment(protocol, subject);
  } catch (const InvalidArgument&) {
    return;  // no number to assign by: the next session's plan refuses it, naming the subject
  }
  std::string recorded_sequence;
  bool pairing_differs = false;
  for (const PlannedTrial& trial : manifest.plan) {
    if (!trial.sequence.empty()) recorded_sequence = trial.sequence;
    const auto trained = crossover.trained.find(trial.item_set);
    if (!trial.trained_condition.empty() &&
        (trained == crossover.trained.end() || trained->second.condition != trial.trained_condition))
      pairing_differs = true;
  }
  if (manifest.group == group && (recorded_sequence.empty() || recorded_sequence == crossover.sequence) &&
      !pairing_differs)
    return;
  throw DataError(SessionLayout::manifest(folder).string() + ": session " +
                  std::to_string(manifest.setup.session_number) + " of subject " + subject.id +
                  " was planned with group '" + manifest.group + "' and sequence '" + recorded_sequence +
                  "', but the protocol now assigns subject number " + std::to_string(subject.number) +
                  " group '" + group + "' and sequence '" + crossover.sequence + "'" +
                  (pairing_differs ? " with another pairing of conditions and sets" : "") +
                  " (this build assigns by another rule than the one that planned it): finish the "
                  "subject's series with the build that began it (session.json names it under library)");
}

bool has_unsaved_trial(const fs::path& folder, const SessionManifest& manifest) {
  for (const PlannedTrial& trial : manifest.plan) {
    std::error_code error;
    if (!fs::exists(SessionLayout::record(folder, trial), error)) return true;
  }
  return false;
}

}  // namespace

SessionSeries session_series(const fs::path& root, const std::string& subject_id,
                             const LoadedProtocol& protocol) {
  SessionSeries series;
  series.sessions = protocol.protocol.session_count();
  const fs::path subject_folder = root / subject_id;
  std::error_code error;
  std::map<int, std::pair<fs::path, SessionManifest>> by_number;  // the newest folder of each number
  if (fs::is_directory(subject_folder, error)) {
    // The study's identity: a session of another study (copied in) is not followed.
    const std::optional<std::string> study_id = StudyIdentity::read(root);
    for (const fs::path& folder : find_session_folders(subject_folder)) {
      SessionManifest manifest = study_detail::read_session_manifest(folder);
      if (manifest.protocol.sha256 != protocol.sha256) continue;
      StudyIdentity::check(study_id, root, folder, manifest);
      study_detail::check_session_in_subject_folder(root, folder, subject_id, manifest);
      const int number = manifest.setup.session_number;
      const auto known = by_number.find(number);
      if (known == by_number.end() || known->second.second.created_utc <= manifest.created_utc) {
        by_number[number] = {folder, std::move(manifest)};
      }
    }
  }
  // A later session without an earlier one: the earlier folder was moved or deleted.
  int expected = 1;
  for (const auto& [number, entry] : by_number) {
    if (number != expected) {
      throw DataError(
          subject_folder.string() + ": session " + std::to_string(expected) + " of " +
          protocol.protocol.name + " is missing, but session " + std::to_string(number) + " is " +
          entry.first.string() +
          (entry.second.previous ? " (it follows '" + entry.second.previous->session_id + "')" : "") +
          ": put the missing session folder back before running the next session");
    }
    ++expected;
  }
  for (int number = 1; number <= series.sessions; ++number) {
    const auto found = by_number.find(number);
    if (found == by_number.end()) break;
    const auto& [folder, manifest] = found->second;
    if (number > 1) check_link(folder, manifest, series.folders.back(), number);
    series.folders.push_back(folder);
    series.next = number + 1;
    if (has_unsaved_trial(folder, manifest)) {
      series.unfinished = folder;
      series.next = number;
      series.previous.reset();
      return series;
    }
    if (number == series.sessions) continue;
    // What links the next session to this one: its last trial's end, its content and the next session's
    // delay.
    const fs::path last_record = SessionLayout::record(folder, manifest.plan.back());
    PreviousSession previous;
    previous.session_id = manifest.session_id;
    previous.session_sha256 = manifest_sha256(folder);
    const nlohmann::json record = study_detail::read_trial_record(last_record);
    // Every saved record has its end; one without (null or missing: the run was killed as it wrote, or the
    // record was edited) gives no time to measure the delay from. The session's creation is not its end.
    const json_detail::JsonView view(record, "", last_record.string());
    if (!view.has("end_time_utc")) {
      json_detail::fail(last_record.string(), "/end_time_utc",
                        std::string(record.contains("end_time_utc") ? "null" : "missing") + ": session " +
                            std::to_string(number) + " of " + protocol.protocol.name + " (" +
                            folder.string() +
                            ") did not end: its last trial has no end time, so the delay before session " +
                            std::to_string(number + 1) +
                            " cannot be measured; restore this trial record (a saved trial is never written "
                            "again, so resume cannot)");
    }
    previous.ended_utc = view.string_or("end_time_utc", "");
    const double ended_s =
        study_detail::utc_seconds_of(previous.ended_utc, last_record.string(), "/end_time_utc");
    for (const ProtocolPhase& phase : protocol.protocol.phases) {
      if (phase.session == number + 1) {
        previous.delay_s = phase.delay_s;
        break;
      }
    }
    // Negative when the previous session's clock was ahead of this one's: recorded as measured. Rounded to
    // the microsecond: the two times are doubles near 1.8e9 s, whose difference carries their rounding (0.006
    // s would read 0.006000041961669922), far under the clock strings' millisecond.
    previous.elapsed_s = std::round((utc_seconds(utc_now_iso8601()) - ended_s) * 1e6) / 1e6;
    series.previous = std::move(previous);
    series.previous_record = last_record;
  }
  if (series.next > series.sessions) {
    series.previous.reset();
    series.previous_record.clear();
  } else if (!series.unfinished && !series.folders.empty()) {
    // The next session is planned now: by the assignment its sessions before it were planned with.
    for (const auto& [number, found] : by_number) {
      if (number < series.next) check_assignment(found.first, found.second, protocol.protocol);
    }
  }
  return series;
}

void check_protocol_unchanged(const fs::path& root, const LoadedProtocol& protocol) {
  std::error_code error;
  if (!fs::is_directory(root, error)) return;
  std::vector<fs::path> folders;
  try {
    folders = find_session_folders(root);
  } catch (const DataError&) {
    return;  // the series' reader lists the folder again and names what is wrong
  }
  for (const fs::path& folder : folders) {
    SessionManifest manifest;
    try {
      manifest = study_detail::read_session_manifest(folder);
    } catch (const DataError&) {
      continue;  // another session's damage is its readers' to report; the subject's own, the series'
    }
    if (!study_detail::protocols_conflict(manifest.protocol, protocol)) continue;
    throw DataError(
        protocol.path.string() + ": the protocol '" + protocol.protocol.name +
        "' differs from the one the session " + folder.string() + " was run with (SHA-256 " +
        protocol.sha256 + " here, " + manifest.protocol.sha256 +
        " there: edited since?); its sessions and this run's would be one design of two "
        "protocols: restore that protocol, or give the edited one another name or a new --out folder");
  }
}

// A session with unsaved trials that a later session already follows: the later one began from it as it was
// then, whole (a series goes on only after every trial is saved), so a trial missing now was removed since;
// resuming would extend the session under the one that follows it.
void check_not_followed(const SessionFolder& session) {
  const fs::path folder = session.path();
  fs::path base = fs::absolute(folder).lexically_normal();
  if (base.filename().empty()) base = base.parent_path();  // "S/x/" is x
  const std::string name = base.filename().string();
  std::vector<fs::path> siblings;
  try {
    siblings = find_session_folders(base.parent_path());
  } catch (const Error&) {
    return;  // the subject's folder cannot be listed: no later session to find
  }
  for (const fs::path& later : siblings) {
    if (later.filename().string() == name) continue;  // the session itself (its manifest is read already)
    SessionManifest manifest;
    try {
      manifest = study_detail::read_session_manifest(later);
    } catch (const Error&) {
      continue;
    }
    if (!manifest.previous || manifest.previous->session_id != name) continue;
    const PlannedTrial& missing = session.manifest().plan[*session.next_unsaved()];
    throw DataError(SessionLayout::record(folder, missing).string() + ": missing, but session " +
                    std::to_string(manifest.setup.session_number) + " (" + later.string() +
                    ") already follows this session and began from it with every trial "
                    "saved: the record was removed since; restore it (a session a later one follows is not "
                    "resumed)");
  }
}

SeriesLock::SeriesLock(const fs::path& root, const std::string& subject_id,
                       const std::function<void(const fs::path&)>& waiting,
                       const std::function<bool()>& should_stop)
    : path_(root / subject_id) {
  // The subject's folder itself is locked (flock(2) takes a directory): no lock file among the sessions.
  std::error_code error;
  fs::create_directories(path_, error);
  if (error) throw DataError(path_.string() + ": cannot create the folder: " + error.message());
  fd_ = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw DataError(path_.string() + ": cannot open the lock: " + std::strerror(errno));
  // A blocking flock restarts after a caught signal (SA_RESTART), so the wait polls instead: a stop request
  // ends it within one interval.
  bool told = false;
  while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    if (reason == EINTR) continue;
    if (reason != EWOULDBLOCK) {
      ::close(fd_);
      fd_ = -1;
      throw DataError(path_.string() + ": cannot lock: " + std::strerror(reason));
    }
    if (!told && waiting) waiting(path_);
    told = true;
    if (should_stop && should_stop()) {
      ::close(fd_);
      fd_ = -1;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

StudyRunLock::StudyRunLock(const fs::path& root, const std::string& command) {
  std::error_code error;
  fs::create_directories(root, error);
  if (error) throw DataError(root.string() + ": cannot create the folder: " + error.message());
  const fs::path path = root / kFileName;
  // O_NOFOLLOW: a link planted under the lock's name is refused, not followed and truncated.
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) throw DataError(path.string() + ": cannot open the study's run lock: " + std::strerror(errno));
  while (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    if (reason == EINTR) continue;
    std::string holder;
    if (reason == EWOULDBLOCK) {
      // The holder writes who it is just after it locks: a run refused in between reads again, briefly.
      for (int attempt = 0; attempt < 40 && holder.empty(); ++attempt) {
        if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        char text[512] = {};
        const ssize_t got = ::pread(fd_, text, sizeof text - 1, 0);
        if (got > 0) holder.assign(text, static_cast<std::size_t>(got));
      }
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == '\0')) holder.pop_back();
    }
    ::close(fd_);
    fd_ = -1;
    if (reason != EWOULDBLOCK) throw DataError(path.string() + ": cannot lock: " + std::strerror(reason));
    throw StateError(root.string() + ": another run is writing this study folder (" +
                     (holder.empty() ? std::string("pid unknown: it has not yet written its note") : holder) +
                     ", lock " + path.string() +
                     "): runs into one study folder take turns; run again when it has ended, or give "
                     "another --out");
  }
  // Who holds it, for the refusal of the next run.
  std::string who = "pid ";
  who.append(std::to_string(::getpid())).append(": ").append(command).append("\n");
  // Written, then cut to its length: a reader never sees it empty when a note was there before.
  if (::pwrite(fd_, who.data(), who.size(), 0) < 0 || ::ftruncate(fd_, static_cast<off_t>(who.size())) != 0) {
    // The lock holds without the note; the refusal then says the process is starting.
  }
}

StudyRunLock::~StudyRunLock() {
  if (fd_ < 0) return;
  // The note goes with the run (an ended run leaves an empty file, the same after every run); closing the
  // descriptor releases the lock. A killed run leaves its note, which the next run replaces.
  if (::ftruncate(fd_, 0) != 0) {
    // Left as it was: a note naming an ended run misleads no one while no lock is held.
  }
  ::close(fd_);
}

SeriesLock::~SeriesLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases the lock
}

}  // namespace calligraphy
