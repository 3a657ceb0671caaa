#pragma once
// Reading saved sessions back, shared by the report and the tidy tables: the session folders under given
// roots, each one's manifest, and each saved trial's record. Internal.
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/recorded_trial.hpp"

namespace calligraphy::study_detail {

/// Largest trial record read: a record's bound, 64 MiB (trial/recorded_trial.hpp; a session manifest:
/// kMaxSessionManifestBytes, session_folder.hpp).
inline constexpr std::uintmax_t kMaxRecordBytes = kMaxRecordedTrialBytes;

/// The session folders under `roots` (each a session folder or a folder holding some), sorted by path over
/// all the roots: the same folders in the same order whatever the order the roots are given in. Throws
/// DataError naming the roots when there is none.
std::vector<std::filesystem::path> session_folders_under(const std::vector<std::filesystem::path>& roots);

/// The folder as named by its own name: its links resolved ("S/x/", "S/x/.", "." inside x and a symbolic
/// link to x are x), or, when it cannot be resolved, its absolute path made lexically normal; never with a
/// trailing separator.
std::filesystem::path named_folder(const std::filesystem::path& folder);

/// The session folder `name` beside the session folder `folder` (in its subject's folder), however `folder`
/// is spelt: ".", "..", with a trailing '/', or through a symbolic link (named_folder).
std::filesystem::path beside_session(const std::filesystem::path& folder, const std::string& name);

/// A session's id: its folder's own name (named_folder), whatever spelling of the folder a reader was given.
std::string session_folder_id(const std::filesystem::path& folder);

/// Refuses the session in `folder` (of the study folder `root`) whose subject is not `subject_folder`, the
/// name of the subject's folder it lies in: a study's sessions lie in ROOT/SUBJECT/ (SessionFolder::create),
/// and one moved into another subject's folder would be read under its own subject from there while that
/// subject's series would not find it. Throws DataError naming the session.json's /subject/id and where it
/// belongs.
void check_session_in_subject_folder(const std::filesystem::path& root, const std::filesystem::path& folder,
                                     const std::string& subject_folder, const SessionManifest& manifest);

/// The manifest of the session folder `folder`, its `session_id` the folder's name (session_folder_id), its
/// saved records checked against its plan (check_records_planned), read without following a link
/// (read_session_file). Throws DataError naming the file (and JSON pointer) when it cannot be read.
SessionManifest read_session_manifest(const std::filesystem::path& folder);

/// Refuses a file of the session folder `folder` that is a symbolic link (session.json, log.jsonl, trials/,
/// teachers/ and every entry of those two): a session's files are its own, and a link would have a reader
/// take a file from elsewhere as the session's. Throws DataError naming the link (session_file_link_message).
void refuse_session_links(const std::filesystem::path& folder);

/// Refuses a file of the session that is a link (refuse_session_links), then a trial record in the session
/// folder `folder` (trials/NAME.json) that `manifest`'s plan does not
/// have: session.json was edited (its plan cut), or the record copied in. Every reader takes the trials the
/// plan names, so such a record would be left out without a word. The trainer's free practice (its trials
/// are made as they are practised) has no plan fixed in advance and is not checked. Throws DataError naming
/// the record and the session.json's /plan.
void check_records_planned(const std::filesystem::path& folder, const SessionManifest& manifest);

/// The saved records name the session by `manifest.session_id`, the folder's name: a DataError naming the
/// first saved record's /session when the folder was renamed since it was saved.
void check_records_name_the_folder(const std::filesystem::path& folder, const SessionManifest& manifest);

/// The manifest of the session that `manifest` (the session in `folder`) follows, from the folder beside it.
/// Throws DataError naming the file when it cannot be read or its session.json is not the one the link
/// recorded (another SHA-256: replaced or edited).
SessionManifest read_previous_session(const std::filesystem::path& folder, const SessionManifest& manifest);

/// True when `a` and `b` are two different protocols (another SHA-256) under one name, whose sessions a
/// reader would pool as one design. The trainer's free practice (`calligraphy train`, protocol "train" made
/// for each run from its characters) is one design whatever characters a run practised.
[[nodiscard]] bool protocols_conflict(const LoadedProtocol& a, const LoadedProtocol& b);

/// The session folders already read, by what makes a session itself (subject, protocol, session number and
/// creation time), so that a copy of one is refused rather than counted twice.
class DistinctSessions {
 public:
  /// False when this folder was read already (a root given twice); throws DataError naming both folders when
  /// `manifest` is a session already read from another folder.
  [[nodiscard]] bool add(const std::filesystem::path& folder, const SessionManifest& manifest);

 private:
  std::map<std::string, std::filesystem::path> seen_;
};

/// The format name and the newest version of a saved trial's record (trial_record.cpp writes it; version 1
/// counted a trial's block and item from 0; versions 1 and 2 called a person writing `human`, read as
/// `person`).
inline constexpr const char* kTrialRecordFormat = "calligraphy-study-trial";
inline constexpr std::int64_t kTrialRecordVersion = 3;

/// The record of a saved trial, its format and version checked, read without following a link
/// (read_session_file): every reader of a session's records reads them through this. Throws DataError naming
/// the file and the field: not a record, or a version this library does not know (a newer calligraphy wrote
/// it, or the file is damaged).
nlohmann::json read_trial_record(const std::filesystem::path& json_file);

}  // namespace calligraphy::study_detail
