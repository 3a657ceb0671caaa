#include "study/manifest_json.hpp"

#include <algorithm>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "core/json_reader.hpp"
#include "study/names.hpp"
#include "study/protocol_reading.hpp"

namespace calligraphy::study_detail {
namespace {

using nlohmann::json;
constexpr const char* kFormat = "calligraphy-study-session";
// Version 2 counts a planned trial's block and item from 1, as its index and repetition; version 1 (older
// folders) counted them from 0.
constexpr std::int64_t kVersion = 2;

// A label (as item set and condition names) or nothing: plans made before item sets lack these keys.
std::string optional_label(json_detail::ObjectReader& reader, const std::string& key) {
  std::string text = reader.string_or(key, "");
  if (reader.has(key) && !is_label(text, 32)) {
    json_detail::fail(
        reader.source(), reader.pointer(key),
        "expected 1 to 32 letters, digits, '_' or '-', got " + json_detail::describe(json(text)));
  }
  return text;
}

// The item set and crossover of a planned trial, each written only when it has a value (plan_session).
void read_crossover_keys(json_detail::ObjectReader& reader, PlannedTrial& trial) {
  trial.item_set = optional_label(reader, "item_set");
  trial.sequence = reader.string_or("sequence", "");
  const bool letters =
      std::all_of(trial.sequence.begin(), trial.sequence.end(), [](char c) { return c >= 'A' && c <= 'Z'; });
  if (reader.has("sequence") && (trial.sequence.empty() || trial.sequence.size() > 26 || !letters)) {
    json_detail::fail(reader.source(), reader.pointer("sequence"),
                      "expected 1 to 26 letters A-Z (the crossover's conditions in period order), got " +
                          json_detail::describe(json(trial.sequence)));
  }
  trial.period = static_cast<int>(reader.integer_or("period", 0, 1, 26));
  trial.trained_condition = optional_label(reader, "trained_condition");
}

PlannedTrial planned_trial_from(const json& value, const std::string& pointer, const std::string& source,
                                std::size_t expected_index, std::int64_t version) {
  const std::int64_t first = version >= 2 ? 1 : 0;  // the first block and item
  json_detail::ObjectReader reader(value, pointer, source);
  PlannedTrial trial;
  trial.index = static_cast<std::size_t>(reader.integer("index", 1, 1000000)) - 1;
  if (trial.index != expected_index) {
    json_detail::fail(source, reader.pointer("index"),
                      "expected " + std::to_string(expected_index + 1) + " (trials in order)");
  }
  trial.phase = choice(reader, "phase", kStudyPhases);
  trial.block = static_cast<std::size_t>(reader.integer("block", first, 1000000) - first);
  trial.condition = reader.string("condition");
  try {
    trial.characters = decode_utf8(reader.string("characters"));
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, reader.pointer("characters"), std::string("not UTF-8: ") + e.what());
  }
  if (trial.characters.empty()) json_detail::fail(source, reader.pointer("characters"), "empty");
  trial.item = static_cast<std::size_t>(reader.integer("item", first, 1000000) - first);
  trial.repetition = static_cast<int>(reader.integer("repetition", 1, 1000000));
  trial.break_before_s = reader.number_or("break_before_s", 0.0, 0.0, 86400.0);
  read_crossover_keys(reader, trial);
  reader.optional("file");
  reader.finish();
  return trial;
}

}  // namespace

json library_build_json(const LibraryBuild& build) {
  return {{"version", build.version},
          {"build_type", build.build_type},
          {"compiler", build.compiler},
          {"cxx_standard", build.cxx_standard}};
}

json planned_trial_json(const PlannedTrial& trial) {
  std::string characters;
  for (const char32_t c : trial.characters) characters += encode_utf8(c);
  json out = {{"index", trial.index + 1},
              {"phase", to_string(trial.phase)},
              {"block", trial.block + 1},
              {"condition", trial.condition},
              {"characters", characters},
              {"item", trial.item + 1},
              {"repetition", trial.repetition},
              {"break_before_s", trial.break_before_s},
              {"file", SessionFolder::trial_stem(trial)}};
  // Only with a value: a protocol without item sets writes the plan it wrote before them, byte for byte.
  if (!trial.item_set.empty()) out["item_set"] = trial.item_set;
  if (!trial.sequence.empty()) out["sequence"] = trial.sequence;
  if (trial.period != 0) out["period"] = trial.period;
  if (!trial.trained_condition.empty()) out["trained_condition"] = trial.trained_condition;
  return out;
}

std::string manifest_to_json(const SessionManifest& manifest) {
  json plan = json::array();
  for (const PlannedTrial& trial : manifest.plan) plan.push_back(planned_trial_json(trial));
  const SessionSetup& setup = manifest.setup;
  json document = {{"format", kFormat},
                   {"version", kVersion},
                   {"created_utc", manifest.created_utc},
                   {"subject", {{"id", setup.subject.id}, {"number", setup.subject.number}}},
                   {"session_number", setup.session_number},
                   {"group", manifest.group},
                   {"device", setup.device},
                   {"writer", setup.writer},
                   {"writer_profile", setup.writer_profile},
                   {"writer_seed", setup.writer_seed},
                   {"writer_learning", setup.writer_learning},
                   {"individual_differences", setup.individual_differences},
                   {"pacing", setup.pacing},
                   {"library", library_build_json(manifest.library)},
                   {"protocol",
                    {{"name", manifest.protocol.protocol.name},
                     {"path", manifest.protocol.path.string()},
                     {"sha256", manifest.protocol.sha256},
                     {"text", manifest.protocol.text}}},
                   {"plan", plan}};
  if (manifest.previous) {
    const PreviousSession& p = *manifest.previous;
    document["previous_session"] = {{"session_id", p.session_id},
                                    {"ended_utc", p.ended_utc},
                                    {"delay_s", p.delay_s},
                                    {"elapsed_s", p.elapsed_s},
                                    {"delay", p.delay}};
    if (!p.session_sha256.empty()) document["previous_session"]["session_sha256"] = p.session_sha256;
  }
  if (!manifest.study_id.empty()) document["study_id"] = manifest.study_id;
  return document.dump(2) + "\n";
}

SessionManifest manifest_from_json(std::string_view text, const std::string& source) {
  const json document = json_detail::parse_json(text, source);
  json_detail::ObjectReader root(document, "", source);
  if (root.string("format") != kFormat)
    json_detail::fail(source, "/format", std::string("expected \"") + kFormat + "\"");
  const std::int64_t version = root.integer("version", 1, kVersion);
  SessionManifest manifest;
  manifest.created_utc = root.string("created_utc");
  json_detail::ObjectReader subject(root.required("subject"), "/subject", source);
  manifest.setup.subject.id = subject.string("id");
  if (!is_label(manifest.setup.subject.id, 64)) {  // as check_setup refuses it when a session is made
    json_detail::fail(source, "/subject/id",
                      "expected 1 to 64 letters, digits, '_' or '-', got " +
                          json_detail::describe(nlohmann::json(manifest.setup.subject.id)));
  }
  manifest.setup.subject.number = static_cast<std::size_t>(subject.integer("number", 0, 1000000000));
  subject.finish();
  manifest.setup.device = root.string("device");
  manifest.setup.writer = root.string("writer");
  manifest.setup.writer_profile = root.string("writer_profile");
  manifest.setup.writer_seed = root.unsigned_or("writer_seed", 0);
  manifest.setup.writer_learning =
      root.string_or("writer_learning", "none");  // "none" before writers learned
  if (manifest.setup.writer_learning != "none" && manifest.setup.writer_learning != "two-state") {
    json_detail::fail(source, "/writer_learning", "expected \"none\" or \"two-state\"");
  }
  // Sessions made before subjects differed: every subject was its profile.
  manifest.setup.individual_differences = root.boolean_or("individual_differences", false);
  manifest.setup.pacing = root.string("pacing");
  // Sessions made before protocols had phases are each the first of their series.
  manifest.setup.session_number = static_cast<int>(root.integer_or("session_number", 1, 1, 20));
  manifest.group = root.string_or("group", "");
  // Sessions made before study folders had an identity have none (StudyIdentity).
  manifest.study_id = root.string_or("study_id", "");
  if (!manifest.study_id.empty() && !is_study_id(manifest.study_id)) {
    json_detail::fail(
        source, "/study_id",
        "expected 32 lower-case hex digits, got " + json_detail::describe(json(manifest.study_id)));
  }
  if (const json* previous = root.optional("previous_session")) {
    json_detail::ObjectReader reader(*previous, "/previous_session", source);
    PreviousSession p;
    p.session_id = reader.string("session_id");
    p.ended_utc = reader.string("ended_utc");
    p.delay_s = reader.number("delay_s", 0.0, 1e9);
    // Any finite time: a clock that differs between the sessions is recorded as it was measured.
    p.elapsed_s = reader.number("elapsed_s", -1e15, 1e15);
    p.delay = reader.string("delay");
    p.session_sha256 = reader.string_or("session_sha256", "");
    reader.finish();
    manifest.previous = std::move(p);
  }
  if (manifest.previous.has_value() != (manifest.setup.session_number > 1)) {
    json_detail::fail(source, "/previous_session", "expected exactly for a session after the first");
  }
  json_detail::ObjectReader library(root.required("library"), "/library", source);
  manifest.library = {library.string("version"), library.string("build_type"), library.string("compiler"),
                      library.string("cxx_standard")};
  library.finish();
  json_detail::ObjectReader protocol(root.required("protocol"), "/protocol", source);
  const std::string name = protocol.string("name");
  const std::string path = protocol.string("path");
  const std::string sha256 = protocol.string("sha256");
  std::string protocol_text = protocol.string("text");
  protocol.finish();
  try {
    manifest.protocol = protocol_from_text(std::move(protocol_text), path);
  } catch (const DataError& e) {
    json_detail::fail(source, "/protocol/text", std::string("the protocol copy is not valid: ") + e.what());
  }
  if (manifest.protocol.sha256 != sha256) {
    json_detail::fail(source, "/protocol/text",
                      "the protocol copy does not match its recorded SHA-256 " + sha256);
  }
  if (manifest.protocol.protocol.name != name)
    json_detail::fail(source, "/protocol/name", "not the name in the protocol copy");
  const json& plan = root.required("plan");
  if (!plan.is_array() || plan.empty())
    json_detail::fail(source, "/plan", "expected a list of planned trials");
  for (std::size_t i = 0; i < plan.size(); ++i) {
    PlannedTrial trial =
        planned_trial_from(plan[i], json_detail::child_pointer("/plan", i), source, i, version);
    // Only conditions of the protocol can run, or have trained an item.
    const auto known = [&](const std::string& condition) {
      const std::vector<StudyCondition>& conditions = manifest.protocol.protocol.conditions;
      return std::any_of(conditions.begin(), conditions.end(),
                         [&](const StudyCondition& c) { return c.name == condition; });
    };
    if (!known(trial.condition))
      json_detail::fail(source,
                        json_detail::child_pointer(json_detail::child_pointer("/plan", i), "condition"),
                        "not a condition of the protocol");
    if (!trial.trained_condition.empty() && !known(trial.trained_condition)) {
      json_detail::fail(
          source, json_detail::child_pointer(json_detail::child_pointer("/plan", i), "trained_condition"),
          "not a condition of the protocol");
    }
    manifest.plan.push_back(std::move(trial));
  }
  root.finish();
  return manifest;
}

std::string session_created_details(const SessionManifest& manifest) {
  const SessionSetup& setup = manifest.setup;
  return json{{"subject", setup.subject.id},
              {"subject_number", setup.subject.number},
              {"device", setup.device},
              {"writer", setup.writer},
              {"writer_profile", setup.writer_profile},
              {"writer_learning", setup.writer_learning},
              {"individual_differences", setup.individual_differences},
              {"protocol", manifest.protocol.protocol.name},
              {"protocol_sha256", manifest.protocol.sha256},
              {"session_number", setup.session_number},
              {"group", manifest.group},
              {"trials_planned", manifest.plan.size()}}
      .dump();
}

std::string log_line(const std::string& time_utc, std::string_view event, std::string_view details_json) {
  json line = {{"time_utc", time_utc}, {"event", std::string(event)}};
  if (!details_json.empty()) {
    json details;
    try {
      details = json::parse(details_json.begin(), details_json.end());
    } catch (const json::parse_error& e) {
      throw InvalidArgument(std::string("session log details: not JSON: ") + e.what());
    }
    if (!details.is_object()) throw InvalidArgument("session log details: expected a JSON object");
    for (auto& item : details.items()) {
      if (item.key() != "time_utc" && item.key() != "event") line[item.key()] = item.value();
    }
  }
  return line.dump() + "\n";
}

}  // namespace calligraphy::study_detail
