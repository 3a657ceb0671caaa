#include "study/saved_sessions.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <optional>
#include <set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/sha256.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "core/json_reader.hpp"
#include "core/whole_file.hpp"
#include "study/manifest_json.hpp"
#include "study/names.hpp"
#include "trial/recorded_trial_object.hpp"

namespace calligraphy::study_detail {
namespace fs = std::filesystem;

std::vector<fs::path> session_folders_under(const std::vector<fs::path>& roots) {
  std::vector<fs::path> folders;
  for (const fs::path& root : roots) {
    for (fs::path& folder : find_session_folders(root)) folders.push_back(std::move(folder));
  }
  std::sort(folders.begin(), folders.end(), session_path_less);  // as find_session_folders orders them
  if (folders.empty()) {
    // The first few folders given, and how many more: a shell glob may give thousands.
    constexpr std::size_t kNamed = 3;
    std::string names;
    for (std::size_t i = 0; i < roots.size() && i < kNamed; ++i) {
      names.append(i == 0 ? "" : ", ").append(roots[i].string());
    }
    if (roots.size() > kNamed)
      names.append(" and ").append(std::to_string(roots.size() - kNamed)).append(" more folders");
    throw DataError(names + ": no session folder (one holding a session.json) found");
  }
  return folders;
}

fs::path named_folder(const fs::path& folder) {
  std::error_code error;
  fs::path named = fs::weakly_canonical(folder, error);
  if (error) {
    const fs::path absolute = fs::absolute(folder, error);
    named = (error ? folder : absolute).lexically_normal();
  }
  if (named.filename().empty()) named = named.parent_path();  // "S/x/" made normal keeps its last separator
  return named;
}

void check_session_in_subject_folder(const fs::path& root, const fs::path& folder,
                                     const std::string& subject_folder, const SessionManifest& manifest) {
  if (subject_folder == manifest.setup.subject.id) return;
  json_detail::fail(SessionLayout::manifest(folder).string(), "/subject/id",
                    "a session of subject '" + manifest.setup.subject.id + "' in the folder of '" +
                        subject_folder + "': move it back to " + (root / manifest.setup.subject.id).string());
}

std::string session_folder_id(const fs::path& folder) { return named_folder(folder).filename().string(); }

fs::path beside_session(const fs::path& folder, const std::string& name) {
  return named_folder(folder).parent_path() / name;
}

SessionManifest read_session_manifest(const fs::path& folder) {
  const fs::path path = SessionLayout::manifest(folder);
  SessionManifest manifest = manifest_from_json(
      read_session_file(path, kMaxSessionManifestBytes, "session manifest"), path.string());
  manifest.session_id = session_folder_id(folder);
  check_records_planned(folder, manifest);
  return manifest;
}

void refuse_session_links(const fs::path& folder) {
  const auto refuse_link = [](const fs::path& path) {
    struct stat status {};
    if (::lstat(path.c_str(), &status) == 0 && S_ISLNK(status.st_mode))
      throw DataError(session_file_link_message(path));
  };
  for (const fs::path& own : {SessionLayout::manifest(folder), SessionLayout::log(folder),
                              SessionLayout::trials(folder), SessionLayout::teachers(folder)}) {
    refuse_link(own);
  }
  for (const fs::path& own : {SessionLayout::trials(folder), SessionLayout::teachers(folder)}) {
    std::error_code error;
    for (fs::directory_iterator entry(own, error), end; !error && entry != end; entry.increment(error)) {
      std::error_code kind;
      if (entry->is_symlink(kind)) throw DataError(session_file_link_message(entry->path()));
    }
  }
}

void check_records_planned(const fs::path& folder, const SessionManifest& manifest) {
  refuse_session_links(folder);
  if (manifest.protocol.path == "calligraphy-train") return;
  std::set<std::string> planned;
  for (const PlannedTrial& trial : manifest.plan) planned.insert(SessionFolder::trial_stem(trial) + ".json");
  std::error_code error;
  for (fs::directory_iterator entry(SessionLayout::trials(folder), error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    if (name.starts_with(".") || !name.ends_with(".json") || planned.contains(name)) continue;
    std::error_code kind;
    if (entry->is_directory(kind)) continue;
    json_detail::fail(SessionLayout::manifest(folder).string(), "/plan",
                      "the plan has no trial " + name.substr(0, name.size() - 5) + ", but " +
                          entry->path().string() +
                          " is a saved record of this session: session.json was edited (its plan cut) or the "
                          "record copied in; restore the original session.json, or move the record out");
  }
}

void check_records_name_the_folder(const fs::path& folder, const SessionManifest& manifest) {
  // A session's id is its folder's name, and each record names it: a folder renamed since its first trial
  // was saved is refused before a resume saves records under the new name beside those of the old one.
  for (const PlannedTrial& trial : manifest.plan) {
    const fs::path record = SessionLayout::record(folder, trial);
    std::error_code missing;
    if (!fs::exists(record, missing)) continue;
    const nlohmann::json document = read_trial_record(record);
    const auto session = document.find("session");
    if (session != document.end() && session->is_string() && *session != manifest.session_id) {
      json_detail::fail(
          record.string(), "/session",
          "names the session '" + session->get<std::string>() + "', but its session folder is " +
              folder.string() +
              " (a session's id is its folder's name): the folder was renamed; rename it back to " +
              session->get<std::string>());
    }
    break;  // the first saved record tells the session's id
  }
}

SessionManifest read_previous_session(const fs::path& folder, const SessionManifest& manifest) {
  const PreviousSession& link = manifest.previous.value();
  const fs::path before = beside_session(folder, link.session_id);
  const fs::path path = SessionLayout::manifest(before);
  const std::string text = read_session_file(path, kMaxSessionManifestBytes, "session manifest");
  if (!link.session_sha256.empty() && sha256_hex(text) != link.session_sha256) {
    json_detail::fail(
        (SessionLayout::manifest(folder)).string(), "/previous_session/session_sha256",
        path.string() +
            " is not the session this one follows (its SHA-256 differs: replaced or edited?): restore the "
            "original folder");
  }
  SessionManifest previous = manifest_from_json(text, path.string());
  previous.session_id = before.filename().string();
  return previous;
}

bool protocols_conflict(const LoadedProtocol& a, const LoadedProtocol& b) {
  const auto practice = [](const LoadedProtocol& p) { return p.path == "calligraphy-train"; };
  return a.protocol.name == b.protocol.name && a.sha256 != b.sha256 && !(practice(a) && practice(b));
}

bool DistinctSessions::add(const fs::path& folder, const SessionManifest& manifest) {
  const std::string key = manifest.setup.subject.id + '\n' + manifest.protocol.sha256 + '\n' +
                          std::to_string(manifest.setup.session_number) + '\n' + manifest.created_utc;
  const auto [at, inserted] = seen_.emplace(key, folder);
  if (inserted) return true;
  std::error_code error;
  if (fs::equivalent(at->second, folder, error)) return false;
  throw DataError((SessionLayout::manifest(folder)).string() + ": the same session as " +
                  at->second.string() + " (subject " + manifest.setup.subject.id + ", session " +
                  std::to_string(manifest.setup.session_number) + ", created " + manifest.created_utc +
                  "): a copy; remove one so that its trials are not counted twice");
}

namespace {

// The record's own format and version (a study's trial record, kTrialRecordFormat) and the specification
// that ran, read by its one reader (read_recorded_trial's, as `trial --spec` reads it): a record whose trial
// could not be run again is refused naming its pointer. Returns that specification (none in a record written
// before records held one).
std::optional<RecordedTrial> check_trial_record(const nlohmann::json& record, const std::string& source) {
  if (!record.is_object() || !record.contains("format") || record["format"] != kTrialRecordFormat) {
    json_detail::fail(source, "/format", std::string("expected \"") + kTrialRecordFormat + "\"");
  }
  const auto version = record.find("version");
  if (version == record.end() || !version->is_number_integer() || version->get<std::int64_t>() < 1 ||
      version->get<std::int64_t>() > kTrialRecordVersion) {
    json_detail::fail(source, "/version",
                      "expected a trial record version from 1 to " + std::to_string(kTrialRecordVersion) +
                          ", got " + (version == record.end() ? std::string("none") : version->dump()) +
                          (version != record.end() && version->is_number_integer() &&
                                   version->get<std::int64_t>() > kTrialRecordVersion
                               ? " (written by a newer calligraphy: read it with that version)"
                               : ""));
  }
  if (!record.contains("specification")) return std::nullopt;
  return trial_detail::read_recorded_document(record, source);
}

}  // namespace

nlohmann::json read_trial_record(const fs::path& json_file) {
  const std::string source = json_file.string();
  nlohmann::json record =
      json_detail::parse_json(read_session_file(json_file, kMaxRecordBytes, "trial record (JSON)"), source);
  (void)check_trial_record(record, source);
  const auto version = record.find("version");
  // Versions 1 and 2 called a person writing "human": every reader sees version 3's "person".
  if (version->get<std::int64_t>() < 3 && record.contains("writer") && record["writer"].is_object() &&
      record["writer"].value("kind", nlohmann::json()) == "human")
    record["writer"]["kind"] = "person";
  return record;
}

}  // namespace calligraphy::study_detail

namespace calligraphy {

RecordedTrial read_study_recorded_trial(const std::string& path) {
  // Read whole, as read_recorded_trial_file reads: what is refused now is the record's content, the input
  // the command was given. A study's record (a format of its own beside its specification; a `trial --json`
  // record states none) is checked as every reader of a session's records checks it.
  const std::string text = read_regular_file(path, study_detail::kMaxRecordBytes);
  nlohmann::json document;
  RecordedTrial recorded;
  try {
    document = trial_detail::parse_record_text(text, path);
    if (document.is_object() && document.contains("specification") && document.contains("format"))
      recorded = *study_detail::check_trial_record(document, path);
    else
      recorded = trial_detail::read_recorded_document(document, path);
  } catch (const InputError&) {
    throw;
  } catch (const DataError& e) {
    throw InputError(e.what());
  }
  if (recorded.spec.guidance && recorded.spec.guidance_mode == GuidanceMode::replay &&
      recorded.spec.teacher.empty()) {
    // A session's replay ran on the teacher kept in its folder (trials/ is beside teachers/): the record
    // names the file and its SHA-256 under /guidance/teacher (trial_guidance.hpp). That file is the teacher,
    // bound by that SHA-256 as a replay's teacher file is (`teacher_sha256`, read_recorded_teacher): one
    // edited or replaced since is refused naming it and both SHA-256, and a recording given instead
    // (--teacher, Python's teacher=) must be the one it ran on.
    nlohmann::json* teacher = document.contains("guidance") && document["guidance"].is_object() &&
                                      document["guidance"].contains("teacher") &&
                                      document["guidance"]["teacher"].is_object()
                                  ? &document["guidance"]["teacher"]
                                  : nullptr;
    if (teacher != nullptr && (*teacher)["file"].is_string() && (*teacher)["sha256"].is_string() &&
        is_sha256_hex((*teacher)["sha256"].get<std::string>())) {
      recorded.spec.teacher =
          (std::filesystem::path(path).parent_path().parent_path() / (*teacher)["file"].get<std::string>())
              .string();
      recorded.teacher_sha256 = (*teacher)["sha256"].get<std::string>();
      recorded.teacher_kept_by_session = true;
    }
  }
  return recorded;
}

}  // namespace calligraphy
