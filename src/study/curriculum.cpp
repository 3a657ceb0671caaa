#include "calligraphy/study/curriculum.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"

namespace calligraphy {

std::vector<TypicalStrokeRecord> typical_stroke_record(const StudyTables& tables,
                                                       const std::string& subject) {
  std::map<int, std::pair<std::size_t, double>> by_id;  // id -> (matched, sum of deviations)
  std::map<int, std::size_t> with_deviation;
  bool any = false;
  for (const StrokeRow& row : tables.strokes) {
    if (row.subject != subject) continue;
    any = true;
    auto& [written, sum] = by_id[row.typical_id];
    if (!row.written) continue;
    ++written;
    if (const std::optional<double> deviation_m = row.metrics.number("mean_deviation_m")) {
      sum += *deviation_m;
      ++with_deviation[row.typical_id];
    }
  }
  if (!any) throw InvalidArgument("subject '" + subject + "' has no saved trial in the record");
  std::vector<TypicalStrokeRecord> record;
  for (const auto& [id, counts] : by_id) {
    TypicalStrokeRecord r;
    r.typical_id = id;
    r.written = counts.first;
    if (with_deviation[id] > 0) r.mean_deviation_m = counts.second / static_cast<double>(with_deviation[id]);
    record.push_back(r);
  }
  return record;
}

std::u32string written_characters(const StudyTables& tables, const std::string& subject) {
  std::u32string written;
  for (const TrialRow& row : tables.trials) {
    if (row.subject != subject) continue;
    for (const char32_t c : decode_utf8(row.characters)) {
      if (written.find(c) == std::u32string::npos) written.push_back(c);
    }
  }
  return written;
}

std::vector<ProposedCharacter> propose_characters(
    const std::vector<TypicalStrokeRecord>& record, const std::u32string& written_characters,
    const std::u32string& candidates, std::size_t count,
    const std::function<std::vector<int>(char32_t)>& typical_ids) {
  // Weak: written, with a mean deviation above the median of the learner's written typical strokes.
  std::set<int> written;
  std::vector<double> deviations;
  for (const TypicalStrokeRecord& r : record) {
    if (r.written == 0) continue;
    written.insert(r.typical_id);
    if (r.mean_deviation_m) deviations.push_back(*r.mean_deviation_m);
  }
  std::set<int> weak;
  if (!deviations.empty()) {
    std::sort(deviations.begin(), deviations.end());
    const std::size_t n = deviations.size();
    const double median = n % 2 == 1 ? deviations[n / 2] : (deviations[n / 2 - 1] + deviations[n / 2]) / 2.0;
    for (const TypicalStrokeRecord& r : record) {
      if (r.written > 0 && r.mean_deviation_m && *r.mean_deviation_m > median) weak.insert(r.typical_id);
    }
  }
  struct Candidate {
    char32_t character;
    std::vector<int> ids;
  };
  std::vector<Candidate> pool;
  for (const char32_t c : candidates) {
    if (written_characters.find(c) != std::u32string::npos) continue;
    if (std::any_of(pool.begin(), pool.end(), [c](const Candidate& k) { return k.character == c; })) continue;
    pool.push_back({c, typical_ids(c)});
  }
  std::vector<ProposedCharacter> proposed;
  std::set<int> covered;
  std::vector<bool> taken(pool.size(), false);
  while (proposed.size() < count) {
    std::size_t best = pool.size();
    int best_gain = 0;
    for (std::size_t i = 0; i < pool.size(); ++i) {
      if (taken[i]) continue;
      const std::set<int> ids(pool[i].ids.begin(), pool[i].ids.end());
      int gain = 0;
      for (const int id : ids) {
        if (covered.count(id) > 0) continue;
        gain += written.count(id) == 0 ? 2 : weak.count(id) > 0 ? 1 : 0;
      }
      const bool better = gain > best_gain || (gain == best_gain && gain > 0 && best < pool.size() &&
                                               pool[i].ids.size() < pool[best].ids.size());
      if (better) {
        best = i;
        best_gain = gain;
      }
    }
    if (best == pool.size()) break;  // nothing left adds a stroke to learn
    taken[best] = true;
    ProposedCharacter p;
    p.character = pool[best].character;
    for (const int id : std::set<int>(pool[best].ids.begin(), pool[best].ids.end())) {
      if (covered.count(id) > 0) continue;
      if (written.count(id) == 0)
        p.new_strokes.push_back(id);
      else if (weak.count(id) > 0)
        p.weak_strokes.push_back(id);
    }
    covered.insert(pool[best].ids.begin(), pool[best].ids.end());
    proposed.push_back(std::move(p));
  }
  return proposed;
}

}  // namespace calligraphy
