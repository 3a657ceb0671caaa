// A protocol's "item_sets" and a phase's "sets" (docs/experiments.md, "Crossover designs"): named sets
// of items, so that a crossover phase can train each condition on its own set and every item, in every
// phase, is attributed to the one condition it was trained under.
#include <algorithm>
#include <map>

#include "calligraphy/core/unicode.hpp"
#include "study/names.hpp"
#include "study/protocol_reading.hpp"

namespace calligraphy {
namespace study_detail {
namespace {

using nlohmann::json;

std::string defined_sets(const std::vector<ItemSet>& sets) {
  std::string names;
  for (const ItemSet& set : sets) names += (names.empty() ? "" : ", ") + set.name;
  return names;
}

// A character in two sets could not be attributed to one condition: the second occurrence is the error.
void check_disjoint(const std::vector<ItemSet>& sets, const std::string& pointer, const std::string& source) {
  std::map<char32_t, std::size_t> owner;  // character -> the first set holding it
  for (std::size_t i = 0; i < sets.size(); ++i) {
    for (std::size_t k = 0; k < sets[i].items.size(); ++k) {
      for (const char32_t c : sets[i].items[k]) {
        const auto [first, added] = owner.emplace(c, i);
        if (added || first->second == i) continue;
        json_detail::fail(
            source,
            json_detail::child_pointer(
                json_detail::child_pointer(json_detail::child_pointer(pointer, i), "characters"), k),
            in_quotes(encode_utf8(c)) + " is also in the item set " + in_quotes(sets[first->second].name) +
                ": a character in two sets cannot be attributed to one condition");
      }
    }
  }
}

// `transfer_of` names another set, one that is not a transfer set itself (checked once every set is read:
// it may name a later one).
void check_transfer_sources(const std::vector<ItemSet>& sets, const std::string& pointer,
                            const std::string& source) {
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::string& wanted = sets[i].transfer_of;
    if (wanted.empty()) continue;
    const std::string at = json_detail::child_pointer(json_detail::child_pointer(pointer, i), "transfer_of");
    if (wanted == sets[i].name) json_detail::fail(source, at, "a set is not a transfer set of itself");
    const auto found =
        std::find_if(sets.begin(), sets.end(), [&](const ItemSet& set) { return set.name == wanted; });
    if (found == sets.end()) {
      json_detail::fail(source, at, "no item set " + in_quotes(wanted) + "; defined: " + defined_sets(sets));
    }
    if (!found->transfer_of.empty()) {
      json_detail::fail(source, at,
                        in_quotes(wanted) + " is itself a transfer set (of " + in_quotes(found->transfer_of) +
                            "): transfer_of names a set that is trained");
    }
  }
}

ItemSet read_item_set(const json& value, const std::string& pointer, const std::string& source) {
  json_detail::ObjectReader reader(value, pointer, source);
  ItemSet set;
  set.name = reader.string("name");
  if (!is_label(set.name, kMaxLabelLength)) {
    json_detail::fail(source, reader.pointer("name"),
                      "expected 1 to 32 letters, digits, '_' or '-', got " + in_quotes(set.name));
  }
  set.items = read_items(reader.required("characters"), reader.pointer("characters"), source);
  set.transfer_of = reader.string_or("transfer_of", "");
  if (reader.has("transfer_of") && !is_label(set.transfer_of, kMaxLabelLength)) {
    json_detail::fail(source, reader.pointer("transfer_of"),
                      "expected the name of an item set (1 to 32 letters, digits, '_' or '-'), got " +
                          in_quotes(set.transfer_of));
  }
  reader.finish();
  return set;
}

}  // namespace

void read_item_sets(const json& value, const std::string& pointer, const std::string& source,
                    StudyProtocol& protocol) {
  if (!value.is_array() || value.empty() || value.size() > kMaxItemSets) {
    json_detail::fail(source, pointer,
                      "expected a list of 1 to " + std::to_string(kMaxItemSets) + " item sets, got " +
                          json_detail::describe(value));
  }
  std::vector<ItemSet> sets;
  for (std::size_t i = 0; i < value.size(); ++i) {
    ItemSet set = read_item_set(value[i], json_detail::child_pointer(pointer, i), source);
    const bool named =
        std::any_of(sets.begin(), sets.end(), [&](const ItemSet& s) { return s.name == set.name; });
    if (named) {
      json_detail::fail(source, json_detail::child_pointer(json_detail::child_pointer(pointer, i), "name"),
                        "the item set " + in_quotes(set.name) + " is defined twice");
    }
    sets.push_back(std::move(set));
  }
  check_disjoint(sets, pointer, source);
  check_transfer_sources(sets, pointer, source);
  protocol.item_sets = std::move(sets);
}

void read_phase_sets(const json& value, const std::string& pointer, const std::string& source,
                     const StudyProtocol& protocol, ProtocolPhase& phase) {
  if (!value.is_array() || value.empty() || value.size() > kMaxItemSets) {
    json_detail::fail(source, pointer,
                      "expected a list of 1 to " + std::to_string(kMaxItemSets) + " item set names, got " +
                          json_detail::describe(value));
  }
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string at = json_detail::child_pointer(pointer, i);
    const std::string name = json_detail::as_string(value[i], at, source);
    const ItemSet* set = protocol.item_set(name);
    if (set == nullptr) {
      json_detail::fail(source, at,
                        "no item set " + in_quotes(name) + "; defined: " +
                            (protocol.item_sets.empty() ? std::string("none (\"item_sets\")")
                                                        : defined_sets(protocol.item_sets)));
    }
    if (std::find(phase.sets.begin(), phase.sets.end(), name) != phase.sets.end()) {
      json_detail::fail(source, at, "the item set " + in_quotes(name) + " is listed twice");
    }
    if (phase.items.size() + set->items.size() > kMaxItems) {
      json_detail::fail(
          source, at,
          "the sets hold more than the " + std::to_string(kMaxItems) + " items a phase may write");
    }
    phase.sets.push_back(name);
    for (const std::u32string& item : set->items) {
      phase.items.push_back(item);
      phase.item_sets.push_back(name);
    }
  }
}

std::string item_pointer(const StudyProtocol& protocol, const ProtocolPhase& phase, std::size_t index) {
  // A phase that lists its characters is named there, its items mapped to sets (check_crossover_items) or
  // not.
  if (phase.sets.empty() || index >= phase.item_sets.size()) {
    return json_detail::child_pointer(json_detail::child_pointer(phase.pointer, "characters"), index);
  }
  const std::string& name = phase.item_sets[index];
  const auto first = std::find(phase.item_sets.begin(), phase.item_sets.end(), name);
  const auto set = std::find_if(protocol.item_sets.begin(), protocol.item_sets.end(),
                                [&](const ItemSet& s) { return s.name == name; });
  const auto position = index - static_cast<std::size_t>(first - phase.item_sets.begin());
  return json_detail::child_pointer(
      json_detail::child_pointer(
          json_detail::child_pointer("/item_sets",
                                     static_cast<std::size_t>(set - protocol.item_sets.begin())),
          "characters"),
      position);
}

void check_crossover_items(StudyProtocol& protocol, const std::string& source) {
  const ProtocolPhase* crossover = protocol.crossover_phase();
  if (crossover == nullptr) return;
  // Each character's set, and whether the crossover trains it (its own sets and their transfer sets).
  std::map<char32_t, const ItemSet*> set_of;
  for (const ItemSet& set : protocol.item_sets) {
    for (const std::u32string& item : set.items) {
      for (const char32_t c : item) set_of.emplace(c, &set);
    }
  }
  const auto trained_by_crossover = [&](const ItemSet& set) {
    const std::string& trained = set.transfer_of.empty() ? set.name : set.transfer_of;
    return std::find(crossover->sets.begin(), crossover->sets.end(), trained) != crossover->sets.end();
  };
  for (ProtocolPhase& phase : protocol.phases) {
    if (&phase == crossover || phase.kind == StudyPhase::practice) continue;
    const std::string characters = json_detail::child_pointer(phase.pointer, "characters");
    if (phase.kind == StudyPhase::training) {
      // A second training of a crossover set would train it under another condition than its one.
      for (std::size_t k = 0; k < phase.items.size(); ++k) {
        for (const char32_t c : phase.items[k]) {
          const auto found = set_of.find(c);
          if (found == set_of.end() || !trained_by_crossover(*found->second)) continue;
          const ItemSet& set = *found->second;
          // A phase's set by its place in "sets", a listed character by its place in "characters".
          std::string at = json_detail::child_pointer(characters, k);
          std::string what = in_quotes(encode_utf8(c)) + " is in the item set " + in_quotes(set.name) + ", ";
          if (!phase.sets.empty()) {
            const auto listed = std::find(phase.sets.begin(), phase.sets.end(), phase.item_sets[k]);
            at = json_detail::child_pointer(json_detail::child_pointer(phase.pointer, "sets"),
                                            static_cast<std::size_t>(listed - phase.sets.begin()));
            what = "the item set " + in_quotes(set.name) + " is ";
          }
          what += set.transfer_of.empty() ? std::string("trained in the crossover phase ")
                                          : "the transfer items of " + in_quotes(set.transfer_of) +
                                                ", trained in the crossover phase ";
          json_detail::fail(source, at,
                            what + crossover->pointer +
                                " under one condition a subject; a second training phase on it would "
                                "train it under another, and its trials could not be attributed to one "
                                "condition: train other characters here, or list this phase's conditions "
                                "in the crossover");
        }
      }
      continue;
    }
    if (!phase.sets.empty()) continue;
    // A test phase that lists its characters: each item is attributed by the one set holding it.
    if (phase.choice) {
      json_detail::fail(source, characters,
                        "a crossover attributes each tested item to the condition its set is trained under, "
                        "and characters chosen by coverage are in no set: give the transfer items as an "
                        "item set with \"transfer_of\" and this phase \"sets\"");
    }
    std::vector<std::string> mapped;
    for (std::size_t k = 0; k < phase.items.size(); ++k) {
      const ItemSet* set = nullptr;
      for (const char32_t c : phase.items[k]) {
        const auto found = set_of.find(c);
        if (found == set_of.end()) {
          json_detail::fail(source, json_detail::child_pointer(characters, k),
                            in_quotes(encode_utf8(c)) +
                                " is in no item set: in a protocol with a crossover phase each tested item "
                                "is attributed to the condition its set is trained under; list it in a set "
                                "of \"item_sets\" or give this phase \"sets\"");
        }
        if (set != nullptr && set != found->second) {
          json_detail::fail(source, json_detail::child_pointer(characters, k),
                            in_quotes(encode_utf8(phase.items[k])) + " holds characters of the item sets " +
                                in_quotes(set->name) + " and " + in_quotes(found->second->name) +
                                ": a tested item is attributed to one set's condition");
        }
        set = found->second;
      }
      mapped.push_back(set->name);
    }
    phase.item_sets = std::move(mapped);
  }
}

}  // namespace study_detail

const ItemSet* StudyProtocol::item_set(std::string_view wanted) const noexcept {
  const auto found = std::find_if(item_sets.begin(), item_sets.end(),
                                  [&](const ItemSet& set) { return set.name == wanted; });
  return found == item_sets.end() ? nullptr : &*found;
}

const ProtocolPhase* StudyProtocol::crossover_phase() const noexcept {
  const auto found = std::find_if(phases.begin(), phases.end(), [](const ProtocolPhase& phase) {
    return phase.assignment == ConditionAssignment::crossover;
  });
  return found == phases.end() ? nullptr : &*found;
}

}  // namespace calligraphy
