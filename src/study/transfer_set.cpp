#include "calligraphy/study/transfer_set.hpp"

#include <algorithm>
#include <set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy {

std::u32string choose_transfer_characters(const std::u32string& trained, const std::u32string& candidates,
                                          std::size_t count,
                                          const std::function<std::vector<int>(char32_t)>& typical_ids) {
  std::set<int> trained_ids;
  for (const char32_t c : trained) {
    for (const int id : typical_ids(c)) trained_ids.insert(id);
  }
  struct Candidate {
    char32_t character;
    std::set<int> ids;
    std::size_t strokes;
  };
  std::vector<Candidate> eligible;
  for (const char32_t c : candidates) {
    if (trained.find(c) != std::u32string::npos) continue;
    if (std::any_of(eligible.begin(), eligible.end(), [c](const Candidate& e) { return e.character == c; }))
      continue;
    const std::vector<int> ids = typical_ids(c);
    const bool covered =
        std::all_of(ids.begin(), ids.end(), [&](int id) { return trained_ids.count(id) > 0; });
    if (covered && !ids.empty()) eligible.push_back({c, std::set<int>(ids.begin(), ids.end()), ids.size()});
  }
  if (eligible.size() < count) {
    std::string qualified;
    for (const Candidate& e : eligible) qualified += encode_utf8(e.character);
    throw InvalidArgument(std::to_string(eligible.size()) + " of " + std::to_string(candidates.size()) +
                          " candidates are not trained and use only trained typical strokes (" +
                          (qualified.empty() ? std::string("none") : qualified) + "); " +
                          std::to_string(count) + " asked");
  }
  std::u32string chosen;
  std::set<int> covered;
  while (chosen.size() < count) {
    std::size_t best = eligible.size();
    std::size_t best_new = 0;
    for (std::size_t i = 0; i < eligible.size(); ++i) {
      if (chosen.find(eligible[i].character) != std::u32string::npos) continue;
      std::size_t fresh = 0;
      for (const int id : eligible[i].ids) fresh += covered.count(id) == 0 ? 1 : 0;
      const bool better = best == eligible.size() || fresh > best_new ||
                          (fresh == best_new && eligible[i].strokes > eligible[best].strokes);
      if (better) {
        best = i;
        best_new = fresh;
      }
    }
    chosen.push_back(eligible[best].character);
    covered.insert(eligible[best].ids.begin(), eligible[best].ids.end());
  }
  return chosen;
}

void resolve_transfer_choices(StudyProtocol& protocol, const std::function<Character(char32_t)>& load) {
  const std::u32string trained = protocol.trained_characters();
  const auto typical_ids = [&load](char32_t c) {
    const Character model = load(c);
    std::vector<int> ids;
    for (const Stroke& stroke : model.strokes) ids.push_back(stroke.typical_id);
    return ids;
  };
  for (ProtocolPhase& phase : protocol.phases) {
    if (!phase.choice || !phase.items.empty()) continue;
    std::u32string candidates;
    for (const std::u32string& item : phase.choice->candidates) candidates += item;
    std::u32string chosen;
    try {
      chosen = choose_transfer_characters(trained, candidates, phase.choice->count, typical_ids);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(phase.pointer + " (" + to_string(phase.kind) + "): " + e.what());
    }
    for (const char32_t c : chosen) phase.items.push_back(std::u32string(1, c));
  }
}

}  // namespace calligraphy
