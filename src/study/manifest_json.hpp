#pragma once
// session.json and log lines as JSON (format: docs/experiments.md). Internal.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "calligraphy/study/session_folder.hpp"

namespace calligraphy::study_detail {

std::string manifest_to_json(const SessionManifest& manifest);
/// The size of manifest_to_json's text, counted without holding the text or its plan as one JSON tree.
struct ManifestSize {
  std::size_t bytes = 0;   // the whole text's, or once past the limit, the bytes counted so far
  std::size_t trials = 0;  // the planned trials counted: the first of them takes `bytes` past the limit
};
/// Counts the bytes of manifest_to_json's text, stopping at the planned trial that takes them past `limit`.
ManifestSize manifest_json_bytes(const SessionManifest& manifest, std::size_t limit);
/// Throws DataError naming `source` and the JSON pointer of a missing or bad value, or a protocol copy
/// whose SHA-256 is not the one recorded.
SessionManifest manifest_from_json(std::string_view text, const std::string& source);
/// The details of the "session_created" log line (subject, device, writer, protocol hash, trials planned).
std::string session_created_details(const SessionManifest& manifest);
/// One log line: {"time_utc", "event", ...details}, newline-terminated. Throws InvalidArgument when
/// `details_json` is neither empty nor a JSON object.
std::string log_line(const std::string& time_utc, std::string_view event, std::string_view details_json);

nlohmann::json planned_trial_json(const PlannedTrial& trial);
nlohmann::json library_build_json(const LibraryBuild& build);

}  // namespace calligraphy::study_detail
