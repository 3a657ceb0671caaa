// A protocol's "phases" (docs/experiments.md): pre-test, training, post-test, retention after a delay and
// transfer on characters not trained, the design motor-learning studies report (Schmidt & Lee, Motor
// Control and Learning, ch. 9), over one or more sessions.
#include <algorithm>
#include <array>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "study/protocol_reading.hpp"

namespace calligraphy::study_detail {
namespace {

using nlohmann::json;

// "condition": "name" or "conditions": ["a", "b"].
std::vector<std::string> read_conditions(json_detail::ObjectReader& reader,
                                         const std::vector<StudyCondition>& defined) {
  const std::string& source = reader.source();
  if (reader.has("condition") == reader.has("conditions")) {
    json_detail::fail(source, reader.pointer("condition"), "give either \"condition\" or \"conditions\"");
  }
  if (reader.has("condition")) {
    return {condition_name(reader.required("condition"), reader.pointer("condition"), source, defined)};
  }
  const json& listed = reader.required("conditions");
  if (!listed.is_array() || listed.empty()) {
    json_detail::fail(source, reader.pointer("conditions"),
                      "expected a list of condition names, got " + json_detail::describe(listed));
  }
  std::vector<std::string> names;
  for (std::size_t i = 0; i < listed.size(); ++i) {
    const std::string at = json_detail::child_pointer(reader.pointer("conditions"), i);
    std::string name = condition_name(listed[i], at, source, defined);
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      json_detail::fail(source, at, "the condition \"" + name + "\" is listed twice");
    }
    names.push_back(std::move(name));
  }
  return names;
}

// "characters": a list of strings, or {"choose": N, "from": [...]} (transfer only).
void read_characters(json_detail::ObjectReader& reader, ProtocolPhase& phase) {
  const std::string& source = reader.source();
  const json& value = reader.required("characters");
  const std::string at = reader.pointer("characters");
  if (!value.is_object()) {
    phase.items = read_items(value, at, source);
    return;
  }
  if (phase.kind != StudyPhase::transfer) {
    json_detail::fail(source, at, "only a transfer phase chooses its characters; expected a list of strings");
  }
  json_detail::ObjectReader choice(value, at, source);
  TransferChoice chosen;
  chosen.count = static_cast<std::size_t>(choice.integer("choose", 1, static_cast<std::int64_t>(kMaxItems)));
  chosen.candidates = read_items(choice.required("from"), choice.pointer("from"), source);
  for (std::size_t i = 0; i < chosen.candidates.size(); ++i) {
    if (chosen.candidates[i].size() != 1) {
      json_detail::fail(source, json_detail::child_pointer(choice.pointer("from"), i),
                        "expected one character per candidate");
    }
  }
  if (chosen.count > chosen.candidates.size()) {
    json_detail::fail(source, choice.pointer("choose"),
                      "more characters to choose (" + std::to_string(chosen.count) + ") than candidates (" +
                          std::to_string(chosen.candidates.size()) + ")");
  }
  choice.finish();
  phase.choice = std::move(chosen);
}

// "characters" or "sets" (names of the protocol's item sets), exactly one of them.
void read_phase_items(json_detail::ObjectReader& reader, const StudyProtocol& protocol,
                      ProtocolPhase& phase) {
  if (reader.has("characters") == reader.has("sets")) {
    json_detail::fail(reader.source(), reader.pointer("characters"),
                      "give either \"characters\" or \"sets\" (names of the protocol's \"item_sets\")");
  }
  if (reader.has("characters")) {
    read_characters(reader, phase);
  } else {
    read_phase_sets(reader.required("sets"), reader.pointer("sets"), reader.source(), protocol, phase);
  }
}

// A crossover phase trains each of its conditions on another of its sets: one set per condition, each a set
// that is trained (not a transfer set), once in a protocol, so that an item has one training condition.
void check_crossover(const json_detail::ObjectReader& reader, const StudyProtocol& protocol,
                     const ProtocolPhase& phase) {
  const std::string& source = reader.source();
  const std::string at = reader.pointer("assignment");
  if (phase.kind == StudyPhase::practice) {
    json_detail::fail(source, at,
                      "a practice phase is written as listed: crossover is for the phases compared");
  }
  if (phase.conditions.size() < 2)
    json_detail::fail(source, at, "crossover needs two or more \"conditions\"");
  if (phase.sets.empty()) {
    json_detail::fail(source, at,
                      "crossover needs \"sets\": one item set per condition, each trained under one of them");
  }
  if (phase.sets.size() != phase.conditions.size()) {
    json_detail::fail(source, reader.pointer("sets"),
                      "crossover trains each of the " + std::to_string(phase.conditions.size()) +
                          " conditions on its own set: expected " + std::to_string(phase.conditions.size()) +
                          " sets, got " + std::to_string(phase.sets.size()));
  }
  for (std::size_t i = 0; i < phase.sets.size(); ++i) {
    const ItemSet* set = protocol.item_set(phase.sets[i]);
    if (set != nullptr && !set->transfer_of.empty()) {
      json_detail::fail(source, json_detail::child_pointer(reader.pointer("sets"), i),
                        "\"" + set->name + "\" is a transfer set (of \"" + set->transfer_of +
                            "\"): its items are tested, not trained");
    }
  }
  if (const ProtocolPhase* first = protocol.crossover_phase()) {
    json_detail::fail(
        source, at,
        "a second crossover phase (the first: " + first->pointer +
            "): a protocol has at most one, so that each item set is trained under one condition");
  }
}

ProtocolPhase read_phase(const json& value, const std::string& pointer, const std::string& source,
                         const StudyProtocol& protocol) {
  json_detail::ObjectReader reader(value, pointer, source);
  // A key of two that exclude each other, given null, is named as null rather than as the other one missing.
  for (const char* key : {"condition", "conditions", "characters", "sets"}) {
    if (value.is_object() && value.contains(key) && value.at(key).is_null())
      json_detail::fail(source, reader.pointer(key), "null is not a value (leave the key out)");
  }
  ProtocolPhase phase;
  phase.pointer = pointer;
  // The settings through their schema (SchemaOf<ProtocolPhase>: spellings and ranges written once).
  const Schema& settings = SchemaOf<ProtocolPhase>::get();
  read_member(reader, settings, "phase", &phase, true);
  phase.conditions = read_conditions(reader, protocol.conditions);
  read_member(reader, settings, "assignment", &phase);
  if (phase.assignment == ConditionAssignment::between_subjects && phase.conditions.size() < 2) {
    json_detail::fail(source, reader.pointer("assignment"),
                      "between-subjects needs two or more \"conditions\"");
  }
  read_phase_items(reader, protocol, phase);
  if (phase.assignment == ConditionAssignment::crossover) check_crossover(reader, protocol, phase);
  for (const char* key : {"repetitions", "session", "delay_s"}) read_member(reader, settings, key, &phase);
  reader.finish();
  // A crossover phase has its own order (crossover_assignment): `abba` does not split it.
  const bool ordered = phase.assignment == ConditionAssignment::within_subjects &&
                       protocol.condition_order == ConditionOrder::abba;
  if (ordered && phase.repetitions % 2 != 0) {
    json_detail::fail(
        source, reader.pointer("repetitions"),
        "order \"abba\" splits each condition's repetitions over two blocks: expected an even number, got " +
            std::to_string(phase.repetitions));
  }
  return phase;
}

bool shares_a_character(const std::u32string& item, const std::u32string& characters) {
  return std::any_of(item.begin(), item.end(),
                     [&](char32_t c) { return characters.find(c) != std::u32string::npos; });
}

// The design makes sense: sessions in order, tests around the training, retention on what was trained after
// a delay, transfer on what was not.
void check_design(const StudyProtocol& protocol, const std::string& pointer, const std::string& source) {
  const auto& phases = protocol.phases;
  const auto at = [&](std::size_t i, const std::string& key) {
    return json_detail::child_pointer(json_detail::child_pointer(pointer, i), key);
  };
  const auto first_training = std::find_if(
      phases.begin(), phases.end(), [](const ProtocolPhase& p) { return p.kind == StudyPhase::training; });
  const std::size_t training = static_cast<std::size_t>(first_training - phases.begin());
  const std::u32string trained = protocol.trained_characters();
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const ProtocolPhase& phase = phases[i];
    const int previous_session = i == 0 ? 1 : phases[i - 1].session;
    if (phase.session != previous_session && phase.session != previous_session + 1) {
      json_detail::fail(source, at(i, "session"),
                        "expected session " + std::to_string(previous_session) + " or " +
                            std::to_string(previous_session + 1) +
                            " (phases in order, sessions numbered from 1 without gaps), got " +
                            std::to_string(phase.session));
    }
    const char* name = to_string(phase.kind);
    if (phase.kind == StudyPhase::pre_test && i > training) {
      json_detail::fail(source, at(i, "phase"), "a pre-test comes before the training");
    }
    const bool after_training = phase.kind == StudyPhase::post_test || phase.kind == StudyPhase::retention ||
                                phase.kind == StudyPhase::transfer;
    const std::string test =
        phase.kind == StudyPhase::post_test ? std::string("a post-test") : std::string("a ") + name + " test";
    if (after_training && training == phases.size()) {
      json_detail::fail(source, at(i, "phase"), test + " needs a training phase before it");
    }
    if (after_training && i < training)
      json_detail::fail(source, at(i, "phase"), test + " comes after the training");
    if (phase.kind == StudyPhase::retention) {
      if (!(phase.delay_s > 0.0)) {
        json_detail::fail(source, at(i, "delay_s"),
                          "a retention test comes after a stated delay: expected delay_s > 0");
      }
      for (std::size_t k = 0; k < phase.items.size(); ++k) {
        for (const char32_t c : phase.items[k]) {
          if (trained.find(c) != std::u32string::npos) continue;
          // Appended, not concatenated: GCC 12 warns falsely on "x" + string (-Wrestrict).
          json_detail::fail(source, item_pointer(protocol, phase, k),
                            in_quotes(encode_utf8(c)) + " is not trained: a test on it is a transfer test");
        }
      }
    }
    if (phase.kind == StudyPhase::transfer) {
      const std::vector<std::u32string>& listed = phase.choice ? phase.choice->candidates : phase.items;
      for (std::size_t k = 0; k < listed.size(); ++k) {
        if (!shares_a_character(listed[k], trained)) continue;
        json_detail::fail(
            source,
            phase.choice
                ? json_detail::child_pointer(json_detail::child_pointer(at(i, "characters"), "from"), k)
                : item_pointer(protocol, phase, k),
            in_quotes(encode_utf8(listed[k])) + " is trained: a transfer test is on characters not trained");
      }
    }
  }
}

}  // namespace

void read_phases(const json& value, const std::string& pointer, const std::string& source,
                 StudyProtocol& protocol) {
  if (!value.is_array() || value.empty() || value.size() > kMaxPhases) {
    json_detail::fail(source, pointer,
                      "expected a list of 1 to " + std::to_string(kMaxPhases) + " phases, got " +
                          json_detail::describe(value));
  }
  for (std::size_t i = 0; i < value.size(); ++i) {
    protocol.phases.push_back(read_phase(value[i], json_detail::child_pointer(pointer, i), source, protocol));
  }
  if (protocol.phases.front().session != 1) {
    json_detail::fail(
        source, json_detail::child_pointer(json_detail::child_pointer(pointer, std::size_t{0}), "session"),
        "the first phase is in session 1");
  }
  check_design(protocol, pointer, source);
  check_crossover_items(protocol, source);
}

}  // namespace calligraphy::study_detail
