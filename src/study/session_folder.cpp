#include "calligraphy/study/session_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <utility>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "core/json_reader.hpp"
#include "core/whole_file.hpp"
#include "report/compressed_text.hpp"
#include "study/manifest_json.hpp"
#include "study/manifest_schema.hpp"
#include "study/names.hpp"
#include "study/saved_sessions.hpp"

namespace calligraphy {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void fail_errno(const fs::path& path, const std::string& what, int error) {
  throw DataError(path.string() + ": " + what + ": " + std::strerror(error));
}

void make_folder(const fs::path& folder) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw DataError(folder.string() + ": cannot create the folder: " + error.message());
}

void fsync_folder(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail_errno(folder, "cannot open the folder to sync it", errno);
  const int result = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (result != 0 && error != EINVAL) fail_errno(folder, "cannot sync the folder", error);
}

void write_all(int fd, std::string_view bytes, const fs::path& path) {
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd, bytes.data(), bytes.size());
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) fail_errno(path, "write failed", written < 0 ? errno : EIO);
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
}

// The most a session log is copied whole to be made a folder's own (below): far above any session's.
constexpr std::uintmax_t kMaxLogBytes = std::uintmax_t{1} << 30;

// Opens (creating it) the log for appending and takes its exclusive lock.
int open_locked_log(const fs::path& log_path) {
  // O_NOFOLLOW: a link planted under the log's name is refused, not followed (the log is the session's own
  // file; a run appends to it).
  const int fd = ::open(log_path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0 && errno == ELOOP) {
    throw DataError(log_path.string() +
                    ": the session log is a symbolic link: a session's log is a file of its own folder; put "
                    "the log back");
  }
  if (fd < 0) fail_errno(log_path, "cannot open the session log", errno);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EWOULDBLOCK) {
      throw StateError(log_path.parent_path().string() +
                       ": the session is open in another process (its log is locked)");
    }
    fail_errno(log_path, "cannot lock the session log", error);
  }
  // A log with other hard links (a study copied with `cp -l`) is another folder's file too: appending would
  // write this session's events into the other copy. It becomes this folder's own first (copied whole under
  // a temporary name and renamed over its name; the other names keep the earlier file), then is locked again.
  struct stat status {};
  if (::fstat(fd, &status) == 0 && S_ISREG(status.st_mode) && status.st_nlink > 1) {
    std::string text;
    try {
      text = read_regular_file(log_path, kMaxLogBytes);
      write_file_atomically(log_path.string(), text);
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
    return open_locked_log(log_path);
  }
  return fd;
}

// "YYYYMMDD-HHMMSS" of the session's created_utc ("YYYY-MM-DDTHH:MM:SS.mmmZ", utc_now_iso8601): the folder
// is named by the second its session.json says it was made, not by a later reading of the clock.
std::string folder_timestamp(const std::string& created_utc) {
  return created_utc.substr(0, 4) + created_utc.substr(5, 2) + created_utc.substr(8, 2) + "-" +
         created_utc.substr(11, 2) + created_utc.substr(14, 2) + created_utc.substr(17, 2);
}

// "PID.HOST" of this process: whose a temporary session folder is, so that only a dead run's is removed.
std::string partial_owner() {
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  std::string name;
  for (const char* c = host; *c != '\0' && name.size() < 64; ++c) {
    const bool plain = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9');
    name += plain ? *c : '-';  // no '.': it separates the fields
  }
  return std::to_string(::getpid()) + "." + (name.empty() ? "host" : name);
}

// Removes the temporary session folders (".partial.PID.HOST.NAME") that runs on this host left when they
// were killed: their process is gone. Another host's, or a live process's, are left (readers skip them).
void remove_dead_partial_folders(const fs::path& subject_folder) {
  const std::string own = partial_owner();
  const std::string host = own.substr(own.find('.') + 1);
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(subject_folder, error)) {
    const std::string name = entry.path().filename().string();
    if (!is_partial_session_folder(entry.path())) continue;
    const std::string rest = name.substr(kPartialSessionPrefix.size());
    const std::size_t dot = rest.find('.');
    if (dot == std::string::npos || rest.compare(dot + 1, host.size() + 1, host + ".") != 0) continue;
    pid_t pid = 0;
    try {
      pid = static_cast<pid_t>(std::stol(rest.substr(0, dot)));
    } catch (const std::exception&) {
      continue;
    }
    if (pid <= 0 || (pid != ::getpid() && (::kill(pid, 0) == 0 || errno != ESRCH))) continue;
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
  }
}

// rename(2) that fails with EEXIST rather than replace an (empty) folder of that name.
int rename_no_replace(const fs::path& from, const fs::path& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return -1;
  // A file system without RENAME_NOREPLACE: a folder appearing in between is the only race left.
  std::error_code error;
  if (fs::exists(to, error)) {
    errno = EEXIST;
    return -1;
  }
  return ::rename(from.c_str(), to.c_str());
}

void check_setup(const SessionSetup& setup) {
  if (!study_detail::is_label(setup.subject.id, 64)) {
    throw InvalidArgument("subject id '" + setup.subject.id +
                          "': expected 1 to 64 letters, digits, '_' or '-'");
  }
  if (setup.writer == TrialWriter::automatic) {
    throw InvalidArgument("writer 'auto': a session's writer is 'simulated' or 'person'");
  }
  (void)writer_profile(setup.writer_profile);  // InvalidArgument naming it and the known profiles
  if (setup.device.empty()) throw InvalidArgument("session setup: the device name is empty");
  if (setup.writer_learning != WriterLearning::none && setup.writer != TrialWriter::simulated) {
    throw InvalidArgument("writer learning '" + std::string(enum_spelling(setup.writer_learning)) +
                          "' models a simulated writer, not a person");
  }
}

SessionManifest make_manifest(const SessionSetup& setup, const LoadedProtocol& protocol,
                              const std::optional<PreviousSession>& previous) {
  SessionManifest manifest;
  manifest.setup = setup;
  manifest.protocol = protocol;
  manifest.library = library_build();
  manifest.created_utc = utc_now_iso8601();
  manifest.plan = plan_session(protocol.protocol, setup.subject, setup.session_number);
  manifest.previous = previous;
  manifest.group = subject_group(protocol.protocol, setup.subject);
  return manifest;
}

// Refuses a session.json a reader would refuse (kMaxSessionManifestBytes), counted without building it and
// only up to the limit: a plan of a million trials is refused at the quarter of it that fills the limit.
void check_manifest_size(const SessionManifest& manifest) {
  const study_detail::ManifestSize size =
      study_detail::manifest_json_bytes(manifest, kMaxSessionManifestBytes);
  if (size.bytes > kMaxSessionManifestBytes) {
    throw DataError(
        manifest.protocol.path.string() + ": session " + std::to_string(manifest.setup.session_number) +
        " of subject " + manifest.setup.subject.id + " plans " + std::to_string(manifest.plan.size()) +
        " trials, more than the " + std::to_string(kMaxSessionManifestBytes >> 20) +
        " MiB of session.json a session's reader takes (" +
        (size.trials > 0 ? "its first " + std::to_string(size.trials - 1) + " trials fill it"
                         : "its protocol alone fills it") +
        "): fewer characters, conditions or repetitions a session, or the phases over more sessions");
  }
}

// session.json's text, refused when a reader would refuse it.
std::string manifest_text(const SessionManifest& manifest) {
  check_manifest_size(manifest);
  return study_detail::manifest_to_json(manifest);
}

}  // namespace

std::uintmax_t trial_files_bytes(const ProtocolTrialSettings& trial) {
  const double ticks = std::ceil(trial.max_duration_s * trial.rate_hz);
  return static_cast<std::uintmax_t>(ticks) * 64 + (std::uintmax_t{1} << 20);
}

void check_writable_folder(const fs::path& folder, std::uintmax_t free_bytes) {
  const auto refuse = [&folder](const std::string& why) {
    throw DataError(folder.string() + ": " + why + " (checked before the first trial; nothing was written)");
  };
  if (::access(folder.c_str(), W_OK) != 0)
    refuse(std::string("cannot write in the folder: ") + std::strerror(errno));
  // access(2) lets a privileged user pass a read-only or immutable folder: a file made there does not. An
  // unnamed file (O_TMPFILE) needs the same rights and leaves nothing behind when the run is killed; a file
  // system without it gets a named probe, made and removed.
  int fd = ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
  if (fd >= 0) {
    ::close(fd);
  } else if (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL) {
    const fs::path probe = folder / (".calligraphy-write-probe-" + std::to_string(::getpid()));
    fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) refuse(std::string("cannot create a file in the folder: ") + std::strerror(errno));
    ::close(fd);
    if (::unlink(probe.c_str()) != 0)
      refuse("cannot remove a file from the folder (" + probe.filename().string() +
             "): " + std::strerror(errno));
  } else {
    refuse(std::string("cannot create a file in the folder: ") + std::strerror(errno));
  }
  struct statvfs space {};
  if (::statvfs(folder.c_str(), &space) != 0)
    refuse(std::string("cannot read its free space: ") + std::strerror(errno));
  const std::uintmax_t available = static_cast<std::uintmax_t>(space.f_bavail) * space.f_frsize;
  if (available < free_bytes) {
    char text[96];
    std::snprintf(text, sizeof text, "%.1f MiB free, less than the %.1f MiB one trial's files may take",
                  static_cast<double>(available) / (1 << 20), static_cast<double>(free_bytes) / (1 << 20));
    refuse(text);
  }
  // A file system that counts inodes (f_files > 0) may run out of them before its bytes.
  if (space.f_files > 0 && space.f_favail < 16)
    refuse(std::to_string(space.f_favail) + " inodes free, fewer than the 16 a trial's files may take");
}

void check_session_manifest_size(const SessionSetup& setup, const LoadedProtocol& protocol) {
  std::optional<PreviousSession> previous;
  if (setup.session_number > 1) {  // a link as long as a real one (its size counts too)
    previous.emplace();
    previous->session_id = protocol.protocol.name + "-" + setup.subject.id + "-YYYYMMDD-HHMMSS-1000";
    previous->ended_utc = utc_now_iso8601();
    previous->session_sha256 = std::string(64, '0');
    previous->delay = SessionDelay::overridden;
  }
  check_manifest_size(make_manifest(setup, protocol, previous));
}

std::uint64_t subject_seed(std::string_view subject_id) {
  return study_detail::mix64(study_detail::fnv1a_64(subject_id));
}

LibraryBuild library_build() {
  LibraryBuild build;
  build.version = CALLIGRAPHY_VERSION;
  build.build_type = CALLIGRAPHY_BUILD_TYPE;
#if defined(__clang__)
  build.compiler = "Clang " __clang_version__;
#elif defined(__GNUC__)
  build.compiler = "GCC " __VERSION__;
#else
  build.compiler = "unknown";
#endif
  build.cxx_standard = std::to_string(__cplusplus) + "L";
  build.cxx_standard.pop_back();
  return build;
}

SessionFolder::SessionFolder(fs::path path, SessionManifest manifest, int log_fd)
    : path_(std::move(path)), manifest_(std::move(manifest)), log_fd_(log_fd) {}

SessionFolder::SessionFolder(SessionFolder&& other) noexcept
    : path_(std::move(other.path_)),
      manifest_(std::move(other.manifest_)),
      log_fd_(std::exchange(other.log_fd_, -1)) {}

SessionFolder& SessionFolder::operator=(SessionFolder&& other) noexcept {
  if (this != &other) {
    if (log_fd_ >= 0) ::close(log_fd_);
    path_ = std::move(other.path_);
    manifest_ = std::move(other.manifest_);
    log_fd_ = std::exchange(other.log_fd_, -1);
  }
  return *this;
}

SessionFolder::~SessionFolder() {
  if (log_fd_ >= 0) ::close(log_fd_);  // releases the flock
}

SessionFolder SessionFolder::create(const fs::path& root, const SessionSetup& setup,
                                    const LoadedProtocol& protocol,
                                    const std::optional<PreviousSession>& previous) {
  check_setup(setup);
  if (previous.has_value() != (setup.session_number > 1)) {
    throw InvalidArgument(
        "session " + std::to_string(setup.session_number) + " of protocol '" + protocol.protocol.name +
        "': " +
        (previous ? "the first session has no previous one" : "a later session needs the previous one"));
  }
  SessionManifest manifest = make_manifest(setup, protocol, previous);
  check_manifest_size(manifest);  // refused before any folder is made
  // The study folder's identity, made by its first session; a later session of the subject's series
  // follows only a session of the same study (session_series).
  manifest.study_id = StudyIdentity::obtain(root);
  const std::string text = manifest_text(manifest);

  const fs::path subject_folder = root / setup.subject.id;
  make_folder(subject_folder);
  remove_dead_partial_folders(subject_folder);
  // The session id names the protocol, the subject and the second it began, so ids are keys across
  // subjects (two subjects started in the same second differ) and sort by time within a subject.
  const std::string base =
      protocol.protocol.name + "-" + setup.subject.id + "-" + folder_timestamp(manifest.created_utc);
  // The folder is made whole under a temporary name beside its own, session.json first, then renamed: a run
  // killed at any moment leaves no session folder or one with its session.json, and at worst a temporary
  // that readers skip and the next run removes.
  const fs::path building =
      subject_folder / (std::string(kPartialSessionPrefix) + partial_owner() + "." + base);
  if (::mkdir(building.c_str(), 0755) != 0) fail_errno(building, "cannot create the session folder", errno);
  int fd = -1;
  const auto abandon = [&building, &fd] {
    if (fd >= 0) ::close(fd);
    // What was made is removed by name first: listing the folder needs a file descriptor for each level,
    // which a process at its limit (RLIMIT_NOFILE, the very failure being undone) may not have.
    ::unlink(SessionLayout::log(building).c_str());
    ::rmdir(SessionLayout::trials(building).c_str());
    ::unlink(SessionLayout::manifest(building).c_str());
    if (::rmdir(building.c_str()) != 0) {
      std::error_code ignored;
      fs::remove_all(building, ignored);
    }
  };
  try {
    write_file_atomically(SessionLayout::manifest(building), text);
    make_folder(SessionLayout::trials(building));
    fd = open_locked_log(SessionLayout::log(building));
    fsync_folder(building);
  } catch (...) {
    abandon();
    throw;
  }
  fs::path folder;
  for (int suffix = 1;; ++suffix) {
    const std::string name = suffix == 1 ? base : base + "-" + std::to_string(suffix);
    folder = subject_folder / name;
    // Never onto an existing folder: two runners never share one.
    if (rename_no_replace(building, folder) == 0) {
      manifest.session_id = name;
      break;
    }
    const int error = errno;
    if ((error != EEXIST && error != ENOTEMPTY) || suffix > 1000) {
      abandon();
      fail_errno(folder, "cannot create the session folder", error);
    }
  }
  SessionFolder session(folder, std::move(manifest), fd);
  fsync_folder(subject_folder);
  session.log("session_created", study_detail::session_created_details(session.manifest_));
  return session;
}

std::optional<std::string> StudyIdentity::read(const fs::path& root) {
  const fs::path path = root / kFileName;
  struct stat status {};
  if (::lstat(path.c_str(), &status) != 0) {
    if (errno == ENOENT) return std::nullopt;
    fail_errno(path, "cannot read the study folder's identity", errno);
  }
  // Opened without following a link below too: a link put in its place after this look is refused there.
  if (!S_ISREG(status.st_mode)) {
    throw DataError(path.string() +
                    ": the study folder's identity is not a regular file (a link or a folder " +
                    "in its place): restore the file this study's first session made");
  }
  const std::string source = path.string();
  const nlohmann::json document =
      json_detail::parse_json(study_detail::read_session_file(path, 4096, "study folder identity"), source);
  json_detail::ObjectReader reader(document, "", source);
  if (reader.string("format") != "calligraphy-study")
    json_detail::fail(source, "/format", "expected \"calligraphy-study\"");
  (void)reader.integer("version", 1, 1);
  std::string id = reader.string("study_id");
  if (!study_detail::is_study_id(id))
    json_detail::fail(source, "/study_id", "expected 32 lower-case hex digits");
  reader.finish();
  return id;
}

std::string StudyIdentity::obtain(const fs::path& root) {
  if (std::optional<std::string> id = read(root)) {
    // What a run killed as it made the identity left, once another run had made it.
    remove_dead_temporaries_of(root / kFileName);
    return *std::move(id);
  }
  make_folder(root);
  unsigned char bytes[16] = {};
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail_errno(root, "cannot draw the study folder's id (getrandom)", n < 0 ? errno : EIO);
    got += static_cast<std::size_t>(n);
  }
  const std::string id = lower_hex(bytes);
  std::string text = R"({"format": "calligraphy-study", "version": 1, "study_id": ")";
  text.append(id).append("\"}\n");
  // Created whole or not at all, never replacing a file (core's exclusive writer): of two runs making it at
  // once, the second reads the id the first one linked.
  if (write_file_exclusively(root / kFileName, text)) return id;
  if (std::optional<std::string> first = read(root)) return *std::move(first);
  throw DataError((root / kFileName).string() +
                  ": the study folder's identity was there and is gone: another program removes it?");
}

void StudyIdentity::check(const std::optional<std::string>& root_id, const fs::path& root,
                          const fs::path& folder, const SessionManifest& manifest) {
  if (manifest.study_id.empty()) return;
  if (manifest.study_id == root_id) {
    // However the reader spelt the folder ("S/x/.", a link): its subject folder's own name.
    study_detail::check_session_in_subject_folder(
        root, folder, study_detail::named_folder(folder).parent_path().filename().string(), manifest);
    return;
  }
  if (!root_id) {
    // Its study folder made an identity with its first session and this folder has none: the session came
    // from elsewhere (into a folder made before identities, or one copied without its hidden file).
    json_detail::fail(SessionLayout::manifest(folder).string(), "/study_id",
                      "this session belongs to study " + manifest.study_id + ", but " + root.string() +
                          " has no study identity (" + (root / kFileName).string() +
                          "): copied in from another study folder? move it back to the study it was run in, "
                          "or restore that file");
  }
  json_detail::fail(SessionLayout::manifest(folder).string(), "/study_id",
                    "this session belongs to study " + manifest.study_id + ", not to the study of " +
                        root.string() + " (" + *root_id + ", " + (root / kFileName).string() +
                        "): copied in from another study folder? move it back to the study it was run in");
}

bool is_partial_session_folder(const fs::path& folder) {
  return folder.filename().string().starts_with(kPartialSessionPrefix);
}

namespace {

// Removes from `folder` what a killed run of this session left half saved: the temporaries of its atomic
// writes (".NAME.tmp-PID-N") and a record's ".part" (written whole, then linked to its name: a kill between
// the link and the unlink leaves it beside the saved record, a kill before the link leaves a trial that is
// run again). Called with the session's lock held, when no other run can be writing there.
void remove_unsaved_leftovers(const fs::path& folder) {
  std::error_code error;
  std::vector<fs::path> leftovers;
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end; entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    const bool temporary = name.starts_with(".") && name.find(".tmp-") != std::string::npos;
    const bool part = name.ends_with(".json.part");
    if ((temporary || part) && entry->is_regular_file(error)) leftovers.push_back(entry->path());
  }
  for (const fs::path& path : leftovers) ::unlink(path.c_str());
  if (!leftovers.empty()) fsync_folder(folder);
}

}  // namespace

fs::path SessionLayout::manifest(const fs::path& folder) { return folder / "session.json"; }
fs::path SessionLayout::log(const fs::path& folder) { return folder / "log.jsonl"; }
fs::path SessionLayout::trials(const fs::path& folder) { return folder / "trials"; }
fs::path SessionLayout::attempts(const fs::path& folder) { return trials(folder) / "attempts"; }
fs::path SessionLayout::teachers(const fs::path& folder) { return folder / "teachers"; }
fs::path SessionLayout::record(const fs::path& folder, const PlannedTrial& trial) {
  return trials(folder) / (SessionFolder::trial_stem(trial) + ".json");
}

SessionFolder SessionFolder::open(const fs::path& folder) {
  if (is_partial_session_folder(study_detail::named_folder(folder)))
    throw DataError(folder.string() + ": " + kPartialNote);
  const fs::path manifest_path = SessionLayout::manifest(folder);
  // A file of the folder that is a symbolic link is refused as its content would be (InputError): a
  // session's files are its own, and nothing is read or written through a link.
  try {
    study_detail::refuse_session_links(folder);
  } catch (const DataError& e) {
    throw InputError(e.what());
  }
  const std::string text =
      study_detail::read_session_file(manifest_path, kMaxSessionManifestBytes, "session manifest");
  // The session folder is what `session resume` was given: what its session.json holds is refused as a
  // protocol's content is (InputError, "FILE: /pointer: what"); a file that cannot be read stays a DataError.
  SessionManifest manifest;
  try {
    manifest = study_detail::manifest_from_json(text, manifest_path.string());
  } catch (const InputError&) {
    throw;
  } catch (const DataError& e) {
    throw InputError(e.what());
  }
  // The id is the folder's own name, also when DIR was given through a symbolic link of another name.
  manifest.session_id = study_detail::session_folder_id(folder);
  // Trials are saved only into the session's own folders: one that is a symbolic link (or not a folder)
  // would take the records, traces and the removal of leftovers somewhere else.
  for (const fs::path& own :
       {SessionLayout::trials(folder), SessionLayout::attempts(folder), SessionLayout::teachers(folder)}) {
    struct stat status {};
    if (::lstat(own.c_str(), &status) != 0) {
      if (errno == ENOENT) continue;
      fail_errno(own, "cannot read the session's folder", errno);
    }
    if (!S_ISDIR(status.st_mode)) {
      throw InputError(own.string() + ": " + (S_ISLNK(status.st_mode) ? "a symbolic link" : "not a folder") +
                       " where the session keeps its own folder: nothing is written through it; put the "
                       "session's folder back in its place");
    }
  }
  study_detail::check_records_planned(folder, manifest);
  const fs::path log_path = SessionLayout::log(folder);
  const int fd = open_locked_log(log_path);
  SessionFolder session(folder, std::move(manifest), fd);
  // The lock says no other run writes here: what a killed run left half written is nobody's.
  remove_unsaved_leftovers(SessionLayout::trials(folder));
  remove_unsaved_leftovers(SessionLayout::attempts(folder));
  // A crash in the middle of a log line leaves it torn: end it, so that the next line stands alone.
  std::error_code error;
  const std::uintmax_t size = fs::file_size(log_path, error);
  if (!error && size > 0) {
    const int reader = ::open(log_path.c_str(), O_RDONLY | O_CLOEXEC);
    char last = '\n';
    if (reader >= 0) {
      if (::pread(reader, &last, 1, static_cast<off_t>(size - 1)) != 1) last = '\n';
      ::close(reader);
    }
    if (last != '\n') {
      write_all(fd, "\n", log_path);
      if (::fsync(fd) != 0) fail_errno(log_path, "cannot sync the session log", errno);
    }
  }
  return session;
}

std::string SessionFolder::trial_stem(const PlannedTrial& trial) {
  char number[16];
  std::snprintf(number, sizeof number, "%03zu", trial.index + 1);
  std::string stem = std::string(number) + "-" + to_string(trial.phase) + "-" + trial.condition + "-r" +
                     std::to_string(trial.repetition) + "-";
  for (std::size_t i = 0; i < trial.characters.size(); ++i) {
    char code[16];
    std::snprintf(code, sizeof code, "%sU%04X", i == 0 ? "" : "_",
                  static_cast<unsigned>(trial.characters[i]));
    stem += code;
  }
  return stem;
}

fs::path SessionFolder::trial_file(const PlannedTrial& trial, std::string_view extension) const {
  return SessionLayout::trials(path_) / (trial_stem(trial) + "." + std::string(extension));
}

bool SessionFolder::is_saved(const PlannedTrial& trial) const {
  std::error_code error;
  return fs::exists(trial_file(trial, "json"), error);
}

std::size_t SessionFolder::saved_count() const {
  return static_cast<std::size_t>(
      std::count_if(plan().begin(), plan().end(), [this](const PlannedTrial& t) { return is_saved(t); }));
}

std::optional<std::size_t> SessionFolder::next_unsaved() const {
  for (const PlannedTrial& trial : plan()) {
    if (!is_saved(trial)) return trial.index;
  }
  return std::nullopt;
}

void SessionFolder::save_trial(const PlannedTrial& trial, std::string_view json, std::string_view trace,
                               std::string_view svg) {
  const fs::path target = trial_file(trial, "json");
  if (is_saved(trial))
    throw StateError(target.string() + ": the trial is saved already; it is never overwritten");
  write_file_atomically(trial_file(trial, kTraceExtension), trace);
  write_file_atomically(trial_file(trial, "svg"), svg);
  // The JSON marks the trial saved: written whole to a temporary, then linked to its name, which fails
  // (EEXIST) instead of replacing a file that appeared meanwhile.
  const fs::path temporary = target.string() + ".part";
  write_file_atomically(temporary, json);
  if (::link(temporary.c_str(), target.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    if (error == EEXIST)
      throw StateError(target.string() + ": the trial is saved already; it is never overwritten");
    fail_errno(target, "cannot save the trial", error);
  }
  ::unlink(temporary.c_str());
  fsync_folder(target.parent_path());
}

fs::path SessionFolder::save_attempt(const PlannedTrial& trial,
                                     const std::function<std::string(const std::string&)>& record,
                                     std::string_view trace) {
  const fs::path folder = SessionLayout::attempts(path_);
  make_folder(folder);
  for (int k = 1; k < 100000; ++k) {
    const std::string stem = trial_stem(trial) + ".attempt-" + std::to_string(k);
    const fs::path json_path = folder / (stem + ".json");
    const fs::path temporary = json_path.string() + ".part";
    std::error_code error;
    if (fs::exists(json_path, error)) continue;
    const std::string trace_name = stem + "." + std::string(kTraceExtension);
    write_file_atomically(folder / trace_name, trace);
    write_file_atomically(temporary, record(trace_name));
    const int linked = ::link(temporary.c_str(), json_path.c_str());
    const int link_error = errno;
    ::unlink(temporary.c_str());
    if (linked == 0) {
      fsync_folder(folder);
      return json_path;
    }
    if (link_error != EEXIST) fail_errno(json_path, "cannot keep the attempt", link_error);
  }
  throw DataError(folder.string() + ": too many attempts of trial " + trial_stem(trial));
}

void SessionFolder::check_records_name_this_session() const {
  study_detail::check_records_name_the_folder(path_, manifest_);
}

void SessionFolder::check_writable() const {
  const std::uintmax_t bytes = trial_files_bytes(manifest_.protocol.protocol.trial);
  check_writable_folder(path_, bytes);  // teachers/ and trials/attempts/ are made here when first needed
  for (const fs::path& folder :
       {SessionLayout::trials(path_), SessionLayout::attempts(path_), SessionLayout::teachers(path_)}) {
    std::error_code error;
    if (folder == SessionLayout::trials(path_) || fs::is_directory(folder, error))
      check_writable_folder(folder, bytes);
  }
  const fs::path log_path = SessionLayout::log(path_);
  if (::access(log_path.c_str(), W_OK) != 0) {
    throw DataError(log_path.string() + ": cannot write the session log: " + std::strerror(errno) +
                    " (checked before the first trial; nothing was written)");
  }
}

void SessionFolder::log(std::string_view event, std::string_view details_json) {
  const std::string line = study_detail::log_line(utc_now_iso8601(), event, details_json);
  const fs::path log_path = SessionLayout::log(path_);
  write_all(log_fd_, line, log_path);
  if (::fsync(log_fd_) != 0) fail_errno(log_path, "cannot sync the session log", errno);
}

namespace {

// A folder holding a session.json, whatever that is: a session.json that is a link, a FIFO or a folder makes
// a session folder that its reader refuses by name, rather than one left out of the tables without a word.
bool names_a_session(const fs::path& folder) {
  struct stat status {};
  return ::lstat(SessionLayout::manifest(folder).c_str(), &status) == 0;
}

// Walks the folders under `root` (not `root` itself), links not followed, to three levels: a session folder
// found goes to `on_session` and is not entered, a symbolic link goes to `on_link`, and a run's partial
// folder is skipped. A callback that returns true ends the walk. A folder that cannot be listed throws
// DataError when `strict`, and ends the walk otherwise. The one walk of a study's tree: finding its sessions
// and telling whether a link leads to some.
template <class OnSession, class OnLink>
void walk_session_tree(const fs::path& root, bool strict, OnSession on_session, OnLink on_link) {
  std::error_code error;
  const auto listing_failed = [&] {
    if (strict) throw DataError(root.string() + ": cannot list the folder: " + error.message());
    return true;
  };
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, error);
  if (error && listing_failed()) return;
  for (; it != fs::recursive_directory_iterator(); it.increment(error)) {
    if (error && listing_failed()) return;
    if (it->is_symlink(error)) {
      it.disable_recursion_pending();
      if (on_link(it->path())) return;
      continue;
    }
    if (!it->is_directory(error)) continue;
    if (is_partial_session_folder(it->path())) {  // a run's folder not made yet, or a killed run's
      it.disable_recursion_pending();
      continue;
    }
    if (names_a_session(it->path())) {
      it.disable_recursion_pending();
      if (on_session(it->path())) return;
    } else if (it.depth() >= 3) {
      it.disable_recursion_pending();
    }
  }
  // An increment that fails (a subfolder that cannot be opened: no file descriptor left, EMFILE) ends the
  // iteration with `error` set: the folders not listed are not "no session there".
  if (error) listing_failed();
}

// Whether `folder` (followed if it is a link) is a session folder or holds one, links inside it not followed.
bool holds_sessions(const fs::path& folder) {
  if (names_a_session(folder)) return true;
  bool found = false;
  walk_session_tree(
      folder, false, [&](const fs::path&) { return found = true; }, [](const fs::path&) { return false; });
  return found;
}

}  // namespace

std::vector<fs::path> find_session_folders(const fs::path& root) {
  std::error_code error;
  if (!fs::is_directory(root, error))
    throw DataError(root.string() + ": not a folder (expected session folders)");
  if (names_a_session(root)) {
    if (is_partial_session_folder(study_detail::named_folder(root)))
      throw DataError(root.string() + ": " + kPartialNote);
    return {root};
  }
  std::vector<fs::path> found;
  walk_session_tree(
      root, true,
      [&](const fs::path& folder) {
        found.push_back(folder);
        return false;
      },
      [](const fs::path& link) {
        // A study's sessions are its own, as a session's files are: a link to a session or subject folder
        // would be reported as part of this study, or skipped and the subject silently lost, so it is named.
        std::error_code ignored;
        if (fs::is_directory(link, ignored) && holds_sessions(link)) {
          throw DataError(
              link.string() +
              ": is a symbolic link to session folders; a study's folders are its own (copy them in)");
        }
        return false;
      });
  std::sort(found.begin(), found.end(), study_detail::session_path_less);
  return found;
}

}  // namespace calligraphy
