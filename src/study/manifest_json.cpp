#include "study/manifest_json.hpp"

#include <algorithm>
#include <iterator>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/study/schedule.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "core/json_reader.hpp"
#include "core/schema_json.hpp"
#include "study/manifest_schema.hpp"
#include "study/names.hpp"
#include "study/protocol_reading.hpp"

namespace calligraphy::study_detail {
namespace {

using nlohmann::json;

// The JSON pointers of the omissible keys a document lacks (SchemaReadResult::defaulted), looked up once per
// key of every planned trial: a set, as a plan may hold a million trials.
using Missing = std::unordered_set<std::string>;

// True when `pointer` was missing from the document and took its default.
bool defaulted(const Missing& missing, const std::string& pointer) { return missing.contains(pointer); }

// The item set and crossover of a planned trial at `at`, each written only when it has a value
// (plan_session): their type and range are the schema's, their spelling is checked here, naming the pointer.
void check_crossover_keys(const ManifestPlannedTrial& read, const Missing& missing, const std::string& at,
                          const std::string& source) {
  const auto label = [&](const std::string& text, const char* key) {
    const std::string pointer = json_detail::child_pointer(at, key);
    if (!defaulted(missing, pointer) && !is_label(text, 32)) {
      json_detail::fail(
          source, pointer,
          "expected 1 to 32 letters, digits, '_' or '-', got " + json_detail::describe(json(text)));
    }
  };
  label(read.item_set, "item_set");
  label(read.trained_condition, "trained_condition");
  const std::string sequence = json_detail::child_pointer(at, "sequence");
  const bool letters =
      std::all_of(read.sequence.begin(), read.sequence.end(), [](char c) { return c >= 'A' && c <= 'Z'; });
  if (!defaulted(missing, sequence) && (read.sequence.empty() || read.sequence.size() > 26 || !letters)) {
    json_detail::fail(source, sequence,
                      "expected 1 to 26 letters A-Z (the crossover's conditions in period order), got " +
                          json_detail::describe(json(read.sequence)));
  }
}

PlannedTrial planned_trial_from(const ManifestPlannedTrial& read, const Missing& missing,
                                const std::string& at, const std::string& source,
                                std::size_t expected_index) {
  PlannedTrial trial;
  if (read.index != static_cast<std::int64_t>(expected_index) + 1) {
    json_detail::fail(source, json_detail::child_pointer(at, "index"),
                      "expected " + std::to_string(expected_index + 1) + " (trials in order)");
  }
  trial.index = expected_index;
  trial.phase = read.phase;
  trial.block = static_cast<std::size_t>(read.block - 1);
  trial.condition = read.condition;
  try {
    trial.characters = decode_utf8(read.characters);
  } catch (const InvalidArgument& e) {
    json_detail::fail(source, json_detail::child_pointer(at, "characters"),
                      std::string("not UTF-8: ") + e.what());
  }
  if (trial.characters.empty())
    json_detail::fail(source, json_detail::child_pointer(at, "characters"), "empty");
  trial.item = static_cast<std::size_t>(read.item - 1);
  trial.repetition = static_cast<int>(read.repetition);
  trial.break_before_s = read.break_before_s;
  check_crossover_keys(read, missing, at, source);
  trial.item_set = read.item_set;
  trial.sequence = read.sequence;
  trial.period = static_cast<int>(read.period);
  trial.trained_condition = read.trained_condition;
  return trial;
}

// Version 1 counted a planned trial's block and item from 0: they are read as version 2 counts them, from 1,
// a whole number out of version 1's range refused here in its terms (another type is the schema's to refuse).
void count_from_one(json& document, const std::string& source) {
  const auto plan = document.find("plan");
  if (plan == document.end() || !plan->is_array()) return;
  for (std::size_t i = 0; i < plan->size(); ++i) {
    json& trial = (*plan)[i];
    if (!trial.is_object()) continue;
    for (const char* key : {"block", "item"}) {
      const auto value = trial.find(key);
      if (value == trial.end() || !value->is_number_integer()) continue;
      if (value->is_number_unsigned() && value->get<std::uint64_t>() < kMaxPlannedTrials) {
        *value = value->get<std::uint64_t>() + 1;
      } else {
        json_detail::fail(source, json_detail::child_pointer(json_detail::child_pointer("/plan", i), key),
                          "expected an integer in 0.." + std::to_string(kMaxPlannedTrials - 1) +
                              " (version 1 counts from 0), got " + json_detail::describe(*value));
      }
    }
  }
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

namespace {

// Gives `sink` session.json's text in pieces, in order, while it returns true: the document without its plan,
// dumped as nlohmann dumps it (keys sorted, two spaces), with each planned trial's object dumped on its own
// and indented as it would be in place; returns the planned trials given. A plan of a million trials is never
// one JSON tree: its tree took gigabytes, and freeing it under an address-space limit could fail inside
// nlohmann's destructor, which ends the process.
template <class Sink>
std::size_t write_manifest(const SessionManifest& manifest, Sink&& sink) {
  const SessionSetup& setup = manifest.setup;
  json document = {{"format", kSessionFormat},
                   {"version", kSessionVersion},
                   {"created_utc", manifest.created_utc},
                   {"subject", {{"id", setup.subject.id}, {"number", setup.subject.number}}},
                   {"session_number", setup.session_number},
                   {"group", manifest.group},
                   {"device", setup.device},
                   {"writer", std::string(enum_spelling(setup.writer))},
                   {"writer_profile", setup.writer_profile},
                   {"writer_seed", setup.writer_seed},
                   {"writer_learning", std::string(enum_spelling(setup.writer_learning))},
                   {"individual_differences", setup.individual_differences},
                   {"pacing", std::string(enum_spelling(setup.pacing))},
                   {"library", library_build_json(manifest.library)},
                   {"protocol",
                    {{"name", manifest.protocol.protocol.name},
                     {"path", manifest.protocol.path.string()},
                     {"sha256", manifest.protocol.sha256},
                     {"text", manifest.protocol.text}}},
                   {"plan", json::array()}};
  if (manifest.previous) {
    const PreviousSession& p = *manifest.previous;
    document["previous_session"] = {{"session_id", p.session_id},
                                    {"ended_utc", p.ended_utc},
                                    {"delay_s", p.delay_s},
                                    {"elapsed_s", p.elapsed_s},
                                    {"delay", std::string(enum_spelling(p.delay))}};
    if (!p.session_sha256.empty()) document["previous_session"]["session_sha256"] = p.session_sha256;
  }
  if (!manifest.study_id.empty()) document["study_id"] = manifest.study_id;
  const std::string text = json_text(document, 2) + "\n";
  // The empty plan as dumped: a top-level key starts a line after two spaces; a string value holds no line
  // break (dumped as \n), so this is the plan's key and nothing inside a value.
  constexpr std::string_view empty_plan = "\n  \"plan\": []";
  const std::size_t at = text.find(empty_plan);
  if (at == std::string::npos || manifest.plan.empty()) {
    sink(std::string_view(text));
    return 0;
  }
  const std::size_t open = at + empty_plan.size() - 1;  // the ']' of "[]"
  if (!sink(std::string_view(text).substr(0, open))) return 0;
  std::string item;
  for (std::size_t i = 0; i < manifest.plan.size(); ++i) {
    const std::string dumped = json_text(planned_trial_json(manifest.plan[i]), 2);
    item.assign(i == 0 ? "\n    " : ",\n    ");
    for (const char c : dumped) {
      item += c;
      if (c == '\n') item += "    ";
    }
    if (!sink(std::string_view(item))) return i + 1;
  }
  if (sink(std::string_view("\n  "))) sink(std::string_view(text).substr(open));
  return manifest.plan.size();
}

}  // namespace

std::string manifest_to_json(const SessionManifest& manifest) {
  std::string text;
  write_manifest(manifest, [&](std::string_view piece) {
    text += piece;
    return true;
  });
  return text;
}

ManifestSize manifest_json_bytes(const SessionManifest& manifest, std::size_t limit) {
  ManifestSize size;
  size.trials = write_manifest(manifest, [&](std::string_view piece) {
    size.bytes += piece.size();
    return size.bytes <= limit;
  });
  return size;
}

SessionManifest manifest_from_json(std::string_view text, const std::string& source) {
  json document = json_detail::parse_json(text, source);
  // The version picks what a document may lack (SchemaReadOptions::version) and how it counts; a version
  // that is not one is refused by the schema, naming /version.
  std::int64_t version = kSessionVersion;
  if (document.is_object()) {
    const auto given = document.find("version");
    for (std::int64_t known = 1; known <= kSessionVersion; ++known) {
      if (given != document.end() && given->is_number() && given->get<double>() == static_cast<double>(known))
        version = known;
    }
  }
  if (version < 2) count_from_one(document, source);
  ManifestDocument read;
  SchemaReadResult result;
  schema_detail::from_json(session_manifest_schema(), &read, document, "", source,
                           {.require_all = true, .version = static_cast<int>(version)}, result);
  const Missing missing(std::make_move_iterator(result.defaulted.begin()),
                        std::make_move_iterator(result.defaulted.end()));
  SessionManifest manifest;
  manifest.created_utc = read.created_utc;
  manifest.setup.subject.id = read.subject.id;
  if (!is_label(manifest.setup.subject.id, 64)) {  // as check_setup refuses it when a session is made
    json_detail::fail(source, "/subject/id",
                      "expected 1 to 64 letters, digits, '_' or '-', got " +
                          json_detail::describe(json(manifest.setup.subject.id)));
  }
  manifest.setup.subject.number = static_cast<std::size_t>(read.subject.number);
  manifest.setup.device = read.device;
  // Versions 1 and 2 called a person writing `human`; version 3 says `person`, as the trial's specification
  // does (and the schema's `allOf` on `version`).
  if (read.writer == WriterKind::human && version >= kSessionPersonVersion) {
    json_detail::fail(source, "/writer",
                      "\"human\" is how versions 1 and 2 said a person; version " + std::to_string(version) +
                          " says \"person\"");
  }
  manifest.setup.writer = read.writer == WriterKind::simulated ? TrialWriter::simulated : TrialWriter::person;
  manifest.setup.writer_profile = read.writer_profile;
  try {  // as check_setup refuses it when a session is made
    (void)writer_profile(manifest.setup.writer_profile);
  } catch (const InvalidArgument& error) {
    json_detail::fail(source, "/writer_profile", error.what());
  }
  manifest.setup.writer_seed = read.writer_seed;
  // The subject's seed (subject_seed) lies past 2^53; a tool that holds JSON numbers as doubles (Node's
  // JSON.parse, jq 1.6) writes it back rounded, and the session's later trials would be another writer's.
  // Such a rounding of the subject's own seed is named here rather than run.
  const std::uint64_t own_seed = subject_seed(manifest.setup.subject.id);
  if (read.writer_seed != own_seed &&
      static_cast<double>(read.writer_seed) == static_cast<double>(own_seed)) {
    json_detail::fail(source, "/writer_seed",
                      "is " + std::to_string(read.writer_seed) + ": the seed of subject '" +
                          manifest.setup.subject.id + "' (" + std::to_string(own_seed) +
                          ") rounded to a double by a tool that re-saved the file; put back " +
                          std::to_string(own_seed));
  }
  manifest.setup.writer_learning = read.writer_learning;
  manifest.setup.individual_differences = read.individual_differences;
  manifest.setup.pacing = read.pacing;
  manifest.setup.session_number = static_cast<int>(read.session_number);
  manifest.group = read.group;
  manifest.study_id = read.study_id;
  if (!defaulted(missing, "/study_id") && !is_study_id(manifest.study_id)) {
    json_detail::fail(
        source, "/study_id",
        "expected 32 lower-case hex digits, got " + json_detail::describe(json(manifest.study_id)));
  }
  if (!defaulted(missing, "/previous_session")) {
    manifest.previous = read.previous_session;
  }
  if (manifest.previous.has_value() != (manifest.setup.session_number > 1)) {
    json_detail::fail(source, "/previous_session", "expected exactly for a session after the first");
  }
  manifest.library = read.library;
  try {
    manifest.protocol = protocol_from_text(std::move(read.protocol.text), read.protocol.path);
  } catch (const DataError& e) {
    json_detail::fail(source, "/protocol/text", std::string("the protocol copy is not valid: ") + e.what());
  }
  if (manifest.protocol.sha256 != read.protocol.sha256) {
    json_detail::fail(source, "/protocol/text",
                      "the protocol copy does not match its recorded SHA-256 " + read.protocol.sha256);
  }
  if (manifest.protocol.protocol.name != read.protocol.name)
    json_detail::fail(source, "/protocol/name", "not the name in the protocol copy");
  // The group is the one the protocol copy assigns the subject (its number): a group edited in (or markup
  // put there) would be reported as the subject's. A folder from before groups were kept may lack it.
  if (!defaulted(missing, "/group")) {
    std::optional<std::string> assigned;
    try {
      assigned = subject_group(manifest.protocol.protocol, manifest.setup.subject);
    } catch (const InvalidArgument&) {  // a subject number the order cannot place: refused where it is read
    }
    if (assigned && *assigned != manifest.group) {
      json_detail::fail(source, "/group",
                        "is " + json_detail::describe(json(manifest.group)) +
                            ", but the protocol copy puts subject " +
                            std::to_string(manifest.setup.subject.number) + " in " +
                            (assigned->empty() ? std::string("no group (every phase is within subjects)")
                                               : "the group '" + *assigned + "'"));
    }
  }
  if (read.plan.empty()) json_detail::fail(source, "/plan", "expected a list of planned trials, got none");
  // Only conditions of the protocol can run, or have trained an item.
  const auto known = [&](const std::string& condition) {
    const std::vector<StudyCondition>& conditions = manifest.protocol.protocol.conditions;
    return std::any_of(conditions.begin(), conditions.end(),
                       [&](const StudyCondition& c) { return c.name == condition; });
  };
  // Only the protocol's items can be written: its phases' strings, its sets' and a transfer choice's
  // candidates (chosen when the session was made).
  std::set<std::u32string> items;
  for (const ProtocolPhase& phase : manifest.protocol.protocol.phases) {
    items.insert(phase.items.begin(), phase.items.end());
    if (phase.choice) items.insert(phase.choice->candidates.begin(), phase.choice->candidates.end());
  }
  for (const ItemSet& set : manifest.protocol.protocol.item_sets)
    items.insert(set.items.begin(), set.items.end());
  for (std::size_t i = 0; i < read.plan.size(); ++i) {
    const std::string at = json_detail::child_pointer("/plan", i);
    PlannedTrial trial = planned_trial_from(read.plan[i], missing, at, source, i);
    if (!known(trial.condition))
      json_detail::fail(source, json_detail::child_pointer(at, "condition"),
                        "not a condition of the protocol");
    if (!items.contains(trial.characters)) {
      json_detail::fail(
          source, json_detail::child_pointer(at, "characters"),
          "not an item of the protocol copy, got " + json_detail::describe(json(read.plan[i].characters)));
    }
    // Every reader finds a planned trial's files by the stem its values make; a `file` naming another one
    // (edited) would send a program reading session.json elsewhere.
    const std::string stem = SessionFolder::trial_stem(trial);
    if (!defaulted(missing, json_detail::child_pointer(at, "file")) && read.plan[i].file != stem) {
      json_detail::fail(source, json_detail::child_pointer(at, "file"),
                        "expected \"" + stem +
                            "\" (the stem of its index, phase, condition, repetition and "
                            "characters), got " +
                            json_detail::describe(json(read.plan[i].file)));
    }
    if (!trial.trained_condition.empty() && !known(trial.trained_condition)) {
      json_detail::fail(source, json_detail::child_pointer(at, "trained_condition"),
                        "not a condition of the protocol");
    }
    manifest.plan.push_back(std::move(trial));
  }
  return manifest;
}

std::string session_created_details(const SessionManifest& manifest) {
  const SessionSetup& setup = manifest.setup;
  return json_text(json{{"subject", setup.subject.id},
                        {"subject_number", setup.subject.number},
                        {"device", setup.device},
                        {"writer", std::string(enum_spelling(setup.writer))},
                        {"writer_profile", setup.writer_profile},
                        {"writer_learning", std::string(enum_spelling(setup.writer_learning))},
                        {"individual_differences", setup.individual_differences},
                        {"protocol", manifest.protocol.protocol.name},
                        {"protocol_sha256", manifest.protocol.sha256},
                        {"session_number", setup.session_number},
                        {"group", manifest.group},
                        {"trials_planned", manifest.plan.size()}});
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
  return json_text(line) + "\n";
}

}  // namespace calligraphy::study_detail
