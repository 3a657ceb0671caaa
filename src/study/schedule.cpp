#include "calligraphy/study/schedule.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <span>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "study/names.hpp"

namespace calligraphy {

bool is_subject_id(std::string_view id) { return study_detail::is_label(id, 64); }

namespace {

// A reproducible stream of 64-bit numbers (SplitMix64), the same on every platform (std::shuffle and
// the standard distributions are not).
class SeededStream {
 public:
  explicit SeededStream(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() { return study_detail::mix64(state_++ * 0x9e3779b97f4a7c15ULL); }
  // Uniform in [0, bound), bound > 0, without modulo bias (rejection).
  std::size_t below(std::size_t bound) {
    const std::uint64_t limit = UINT64_MAX - UINT64_MAX % bound;
    std::uint64_t value = next();
    while (value >= limit) value = next();
    return static_cast<std::size_t>(value % bound);
  }

 private:
  std::uint64_t state_;
};

template <typename T>
void shuffle(std::vector<T>& values, std::uint64_t seed) {
  SeededStream stream(seed);
  for (std::size_t i = values.size(); i > 1; --i) std::swap(values[i - 1], values[stream.below(i)]);
}

// Row `row` of the balanced Latin square of n conditions (Williams 1949): the first row is
// 0, 1, n-1, 2, n-2, ...; row r adds r mod n; for odd n rows n..2n-1 are rows 0..n-1 reversed.
std::vector<std::size_t> williams_row(std::size_t n, std::size_t row) {
  std::vector<std::size_t> first{0};
  for (std::size_t k = 1, low = 1, high = n - 1; k < n; ++k) first.push_back(k % 2 == 1 ? low++ : high--);
  std::vector<std::size_t> out(n);
  for (std::size_t j = 0; j < n; ++j) out[j] = (first[j] + row) % n;
  if (n % 2 == 1 && (row / n) % 2 == 1) std::reverse(out.begin(), out.end());
  return out;
}

std::uint64_t subject_seed(const StudyProtocol& protocol, const SubjectAssignment& subject) {
  return study_detail::mix64(protocol.seed ^ study_detail::fnv1a_64(subject.id));
}

// The indices in `phase.items` of the items of set `name`, in listed order.
std::vector<std::size_t> items_of_set(const ProtocolPhase& phase, const std::string& name) {
  std::vector<std::size_t> items;
  for (std::size_t i = 0; i < phase.item_sets.size(); ++i) {
    if (phase.item_sets[i] == name) items.push_back(i);
  }
  return items;
}

// The trial's item set and how the subject's crossover trains it, so that every phase's trial (a pre-test's
// too) names the condition its item is or was trained under.
void describe_crossover(PlannedTrial& trial, const ProtocolPhase& phase,
                        const CrossoverAssignment& crossover) {
  if (trial.item < phase.item_sets.size()) trial.item_set = phase.item_sets[trial.item];
  trial.sequence = crossover.sequence;
  const auto trained = crossover.trained.find(trial.item_set);
  if (trial.item_set.empty() || trained == crossover.trained.end()) return;
  trial.period = trained->second.period;
  trial.trained_condition = trained->second.condition;
}

// One block of a phase: a condition, the items it writes (indices in the phase's list, listed order), rounds.
struct BlockPlan {
  std::string condition;
  std::vector<std::size_t> items;
  int rounds = 1;
};

// The phase's blocks for the subject: a crossover phase one a period, its condition on its set's items; any
// other a block per condition of `block_conditions` on every item (ABBA: half the repetitions each).
std::vector<BlockPlan> phase_blocks(const StudyProtocol& protocol, const ProtocolPhase& phase,
                                    const SubjectAssignment& subject, const CrossoverAssignment& crossover) {
  std::vector<BlockPlan> blocks;
  if (phase.assignment == ConditionAssignment::crossover && phase.kind != StudyPhase::practice) {
    for (std::size_t p = 0; p < crossover.conditions.size(); ++p) {
      blocks.push_back({crossover.conditions[p], items_of_set(phase, crossover.sets[p]), phase.repetitions});
    }
    return blocks;
  }
  const bool split = phase.assignment == ConditionAssignment::within_subjects &&
                     protocol.condition_order == ConditionOrder::abba && phase.kind != StudyPhase::practice;
  std::vector<std::size_t> every(phase.items.size());
  for (std::size_t i = 0; i < every.size(); ++i) every[i] = i;
  for (const std::string& condition : block_conditions(protocol, phase, subject)) {
    blocks.push_back({condition, every, split ? phase.repetitions / 2 : phase.repetitions});
  }
  return blocks;
}

void check_subject(const SubjectAssignment& subject) {
  if (!is_subject_id(subject.id)) {
    throw InvalidArgument("subject id '" + subject.id + "': expected 1 to 64 letters, digits, '_' or '-'");
  }
}

}  // namespace

std::size_t trailing_number(std::string_view subject_id) noexcept {
  std::size_t begin = subject_id.size();
  while (begin > 0 && subject_id[begin - 1] >= '0' && subject_id[begin - 1] <= '9') --begin;
  if (begin == subject_id.size() || subject_id.size() - begin > 9) return 0;
  std::size_t number = 0;
  for (std::size_t i = begin; i < subject_id.size(); ++i) {
    number = number * 10 + static_cast<std::size_t>(subject_id[i] - '0');
  }
  return number;
}

namespace {

// Subjects after which the between-subjects groups repeat: groups go in turn by number in each between phase
// (`block_conditions`), so the pattern repeats every lcm of their sizes; under a random order they are drawn,
// not in turn, and there is no cycle to count within.
std::size_t between_subjects_cycle(const StudyProtocol& protocol) {
  if (protocol.condition_order == ConditionOrder::random) return 1;
  std::size_t cycle = 1;
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.assignment == ConditionAssignment::between_subjects)
      cycle = std::lcm(cycle, phase.conditions.size());
  }
  return cycle;
}

// The 0-based cell from which whatever else is assigned by number (a crossover's sequence and rotation, a
// within-subjects phase's Latin square row or ABBA direction) is taken: m = j + g, g = (n - 1) mod G the
// subject's group and j = (n - 1) / G its place in the group, G the between-subjects cycle (n - 1 when there
// are no groups). A cyclic Latin square of groups by subjects within the group: every group gets every row
// over its own first subjects, and consecutive subjects consecutive cells. Counted over all subjects alone
// (m = n - 1), two groups beside two orders would coincide: every subject of a group in one order.
std::size_t assignment_cell(const StudyProtocol& protocol, std::size_t number) {
  const std::size_t cycle = between_subjects_cycle(protocol);
  return (number - 1) / cycle + (number - 1) % cycle;
}

}  // namespace

CrossoverAssignment crossover_assignment(const StudyProtocol& protocol, const SubjectAssignment& subject) {
  check_subject(subject);
  CrossoverAssignment out;
  const ProtocolPhase* phase = protocol.crossover_phase();
  if (phase == nullptr) return out;
  if (subject.number == 0) {
    throw InvalidArgument("subject '" + subject.id + "': the crossover " + to_string(phase->kind) +
                          " phase counterbalances its sequence and sets by the subject's number (1, 2, ...)");
  }
  const std::vector<std::string>& listed = phase->conditions;
  const std::size_t k = listed.size();
  // The protocol's reader refuses this; a protocol made in code may not.
  if (k == 0 || phase->sets.size() != k) {
    throw InvalidArgument("protocol '" + protocol.name + "': the crossover phase " + phase->pointer +
                          " needs one item set per condition");
  }
  // Rows of the balanced Latin square (Williams 1949) balance the order: each condition in each period, and
  // after each other one, equally often. The rotation, advanced once per full set of rows, moves every
  // condition over every set, so that condition and set are balanced every rows x k subjects.
  const std::size_t rows = k % 2 == 0 ? k : 2 * k;
  // In a mixed design the cell m = j + g (`assignment_cell`) gives every group every sequence and rotation
  // over its first rows x k subjects, and consecutive subjects consecutive cells, so that the sequences stay
  // balanced over all subjects too; counted within the group alone (m = j), G subjects in a row would share
  // one sequence.
  const std::size_t cell = assignment_cell(protocol, subject.number);
  const std::size_t row = cell % rows;
  out.rotation = (cell / rows) % k;
  const std::vector<std::size_t> order = williams_row(k, row);
  for (std::size_t p = 0; p < k; ++p) {
    const std::size_t listed_index = order[p];
    const std::string& set = phase->sets[(listed_index + out.rotation) % k];
    out.sequence.push_back(static_cast<char>('A' + listed_index));
    out.conditions.push_back(listed[listed_index]);
    out.sets.push_back(set);
    out.trained[set] = {listed[listed_index], static_cast<int>(p + 1)};
  }
  // A transfer set is attributed to the condition its source set is trained under.
  for (const ItemSet& set : protocol.item_sets) {
    const auto source = out.trained.find(set.transfer_of);
    if (!set.transfer_of.empty() && source != out.trained.end()) out.trained[set.name] = source->second;
  }
  return out;
}

std::vector<std::string> block_conditions(const StudyProtocol& protocol, const ProtocolPhase& phase,
                                          const SubjectAssignment& subject) {
  check_subject(subject);
  const std::vector<std::string>& listed = phase.conditions;
  // Familiarisation within subjects is written as listed: the order counterbalances what is compared. A
  // between-subjects familiarisation gives the subject its group's one condition, as any between phase.
  if (phase.kind == StudyPhase::practice && phase.assignment != ConditionAssignment::between_subjects)
    return listed;
  if (phase.assignment == ConditionAssignment::crossover) {
    // The protocol's one crossover phase: its own counterbalanced order.
    if (protocol.crossover_phase() == &phase) return crossover_assignment(protocol, subject).conditions;
    throw InvalidArgument("protocol '" + protocol.name + "': the crossover phase " + phase.pointer +
                          " is not the protocol's");
  }
  const std::size_t n = listed.size();
  const bool between = phase.assignment == ConditionAssignment::between_subjects;
  const bool needs_number = protocol.condition_order == ConditionOrder::latin_square ||
                            protocol.condition_order == ConditionOrder::abba ||
                            (between && protocol.condition_order == ConditionOrder::fixed);
  if (needs_number && subject.number == 0) {
    throw InvalidArgument("subject '" + subject.id + "': " +
                          (between ? std::string("the between-subjects ") + to_string(phase.kind) +
                                         " phase assigns groups by the subject's number (1, 2, ...)"
                                   : "the order '" + std::string(to_string(protocol.condition_order)) +
                                         "' needs the subject's number (1, 2, ...) to counterbalance"));
  }
  if (between) {
    // Groups in turn by number (balanced), or drawn per subject from the seed under a random order.
    if (protocol.condition_order == ConditionOrder::random) {
      std::vector<std::string> drawn = listed;
      shuffle(drawn, subject_seed(protocol, subject));
      return {drawn.front()};
    }
    return {listed[(subject.number - 1) % n]};
  }
  std::vector<std::string> blocks;
  switch (protocol.condition_order) {
    case ConditionOrder::fixed:
      blocks = listed;
      break;
    case ConditionOrder::latin_square: {
      const std::size_t rows = n % 2 == 0 ? n : 2 * n;
      // By the subject's cell, so that beside between-subjects groups every group gets every row.
      const std::size_t row = assignment_cell(protocol, subject.number) % rows;
      for (const std::size_t k : williams_row(n, row)) blocks.push_back(listed[k]);
      break;
    }
    case ConditionOrder::abba: {
      std::vector<std::string> first = listed;
      // Odd cells (even numbers without groups) reverse: every group gets both directions.
      if (assignment_cell(protocol, subject.number) % 2 == 1) std::reverse(first.begin(), first.end());
      blocks = first;
      blocks.insert(blocks.end(), first.rbegin(), first.rend());
      break;
    }
    case ConditionOrder::random:
      blocks = listed;
      shuffle(blocks, subject_seed(protocol, subject));
      break;
  }
  return blocks;
}

std::string subject_group(const StudyProtocol& protocol, const SubjectAssignment& subject) {
  std::string group;
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.assignment != ConditionAssignment::between_subjects) continue;
    group += (group.empty() ? "" : "/") + block_conditions(protocol, phase, subject).front();
  }
  return group;
}

namespace {

// The one planning of a session: its trials and, when asked, where each phase's trials are.
std::vector<PlannedTrial> plan_trials(const StudyProtocol& protocol, const SubjectAssignment& subject,
                                      int session, std::vector<PlannedPhase>* phases) {
  const std::uint64_t planned = planned_trial_count(protocol);  // before anything per trial is allocated
  if (planned > kMaxPlannedTrials) {
    throw InvalidArgument("protocol '" + protocol.name + "': " + thousands(planned) +
                          " trials planned, more than the limit of " + thousands(kMaxPlannedTrials) +
                          " trials per session");
  }
  if (session < 1 || session > protocol.session_count()) {
    throw InvalidArgument("protocol '" + protocol.name + "' has sessions 1 to " +
                          std::to_string(protocol.session_count()) + ", not " + std::to_string(session));
  }
  check_subject(subject);
  const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
  std::vector<PlannedTrial> trials;
  std::map<std::string, int> written;  // phase/condition/item -> times planned so far
  std::size_t block = 0;
  // `items`: the indices in the phase's list the block writes, in listed order.
  const auto add_block = [&](const ProtocolPhase& phase, const std::string& condition,
                             const std::vector<std::size_t>& items, int rounds, double rest_before_s) {
    const std::size_t first = trials.size();
    const bool shuffled = phase.kind != StudyPhase::practice && protocol.item_order == ItemOrder::random;
    for (int round = 0; round < rounds; ++round) {
      std::vector<std::size_t> order = items;
      if (shuffled) {
        shuffle(order, study_detail::mix64(
                           subject_seed(protocol, subject) ^
                           study_detail::mix64(block * 1000003ULL + static_cast<std::size_t>(round))));
      }
      for (const std::size_t item : order) {
        PlannedTrial trial;
        trial.index = trials.size();
        trial.phase = phase.kind;
        trial.block = block;
        trial.condition = condition;
        trial.characters = phase.items[item];
        trial.item = item;
        trial.repetition =
            ++written[std::string(to_string(phase.kind)) + "/" + condition + "/" + std::to_string(item)];
        describe_crossover(trial, phase, crossover);
        trials.push_back(std::move(trial));
      }
    }
    if (first < trials.size()) {
      const double between = block > 0 ? protocol.breaks.between_blocks_s : 0.0;
      trials[first].break_before_s = std::max(between, rest_before_s);
    }
    ++block;
  };
  bool first_phase = true;
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.session != session) continue;
    if (phase.choice && phase.items.empty()) {
      throw InvalidArgument(
          "protocol '" + protocol.name + "': the " + to_string(phase.kind) +
          " phase's characters are to be chosen (resolve_transfer_choices) before a session "
          "is planned");
    }
    // The first phase of a later session waits in the session's link (session_series.hpp), not as a rest.
    double rest_before_s = first_phase ? 0.0 : phase.delay_s;
    PlannedPhase shown{&phase, {}, {}, trials.size(), 0};
    for (const BlockPlan& planned_block : phase_blocks(protocol, phase, subject, crossover)) {
      add_block(phase, planned_block.condition, planned_block.items, planned_block.rounds, rest_before_s);
      rest_before_s = 0.0;
      shown.blocks.push_back(planned_block.condition);
      shown.block_sets.push_back(phase.assignment == ConditionAssignment::crossover &&
                                         phase.kind != StudyPhase::practice
                                     ? crossover.sets[shown.blocks.size() - 1]
                                     : std::string());
    }
    shown.trials = trials.size() - shown.first_trial;
    if (phases != nullptr) phases->push_back(std::move(shown));
    first_phase = false;
  }
  const auto every = static_cast<std::size_t>(protocol.breaks.every_trials);
  if (every > 0) {
    for (std::size_t i = every; i < trials.size(); i += every) {
      trials[i].break_before_s = std::max(trials[i].break_before_s, protocol.breaks.duration_s);
    }
  }
  return trials;
}

}  // namespace

std::vector<PlannedTrial> plan_session(const StudyProtocol& protocol, const SubjectAssignment& subject,
                                       int session) {
  return plan_trials(protocol, subject, session, nullptr);
}

std::vector<PlannedPhase> plan_session_phases(const StudyProtocol& protocol, const SubjectAssignment& subject,
                                              int session) {
  std::vector<PlannedPhase> phases;
  (void)plan_trials(protocol, subject, session, &phases);
  return phases;
}

std::size_t counterbalancing_square(const StudyProtocol& protocol) {
  const std::size_t groups = between_subjects_cycle(protocol);
  std::size_t square = groups;
  for (const ProtocolPhase& phase : protocol.phases) {
    if (phase.kind == StudyPhase::practice || phase.assignment == ConditionAssignment::between_subjects)
      continue;
    const std::size_t n = phase.conditions.size();
    const std::size_t rows = n % 2 == 0 ? n : 2 * n;
    if (phase.assignment == ConditionAssignment::crossover) {
      square = std::lcm(square, groups * rows * n);  // counted within the group (crossover_assignment)
    } else if (n > 1 && protocol.condition_order == ConditionOrder::latin_square) {
      square = std::lcm(square, groups * rows);  // every group every row (block_conditions)
    } else if (n > 1 && protocol.condition_order == ConditionOrder::abba) {
      square = std::lcm(square, groups * 2);
    }
  }
  return square;
}

std::string set_pairing(const StudyProtocol& protocol, const CrossoverAssignment& assignment) {
  const ProtocolPhase* crossover = protocol.crossover_phase();
  std::string pairing;
  if (crossover == nullptr) return pairing;
  for (std::size_t i = 0; i < crossover->conditions.size(); ++i) {
    for (std::size_t p = 0; p < assignment.conditions.size(); ++p) {
      if (assignment.conditions[p] != crossover->conditions[i]) continue;
      if (!pairing.empty()) pairing.push_back(' ');
      pairing.push_back(static_cast<char>('A' + i));
      pairing.push_back(':');
      pairing.append(assignment.sets[p]);
    }
  }
  return pairing;
}

namespace {

// The level of each factor the protocol counterbalances, for one subject, by the assignment functions above.
std::vector<std::pair<std::string, std::string>> balance_levels(const StudyProtocol& protocol,
                                                                const SubjectAssignment& subject) {
  std::vector<std::pair<std::string, std::string>> levels;
  bool between = false;
  for (const ProtocolPhase& phase : protocol.phases)
    between |= phase.assignment == ConditionAssignment::between_subjects;
  if (between) levels.emplace_back("group", subject_group(protocol, subject));
  if (const ProtocolPhase* crossover = protocol.crossover_phase(); crossover != nullptr) {
    const CrossoverAssignment assignment = crossover_assignment(protocol, subject);
    levels.emplace_back("sequence", assignment.sequence);
    levels.emplace_back("set pairing", set_pairing(protocol, assignment));
  }
  if (protocol.condition_order != ConditionOrder::fixed) {
    for (const ProtocolPhase& phase : protocol.phases) {
      if (phase.kind == StudyPhase::practice || phase.assignment != ConditionAssignment::within_subjects ||
          phase.conditions.size() < 2)
        continue;
      std::string order;
      for (const std::string& condition : block_conditions(protocol, phase, subject))
        order += (order.empty() ? "" : " ") + condition;
      levels.emplace_back(std::string("order of ") + to_string(phase.kind) + " (" + phase.pointer + ")",
                          order);
    }
  }
  return levels;
}

}  // namespace

Counterbalancing counterbalancing(const StudyProtocol& protocol,
                                  std::span<const SubjectAssignment> subjects) {
  Counterbalancing out;
  out.square = counterbalancing_square(protocol);
  out.groups = between_subjects_cycle(protocol);
  out.subjects = subjects.size();
  out.drawn = protocol.condition_order == ConditionOrder::random;
  const auto add = [&out](const std::vector<std::pair<std::string, std::string>>& levels, bool count) {
    for (std::size_t f = 0; f < levels.size(); ++f) {
      if (out.factors.size() <= f) out.factors.push_back({levels[f].first, {}, {}});
      BalanceFactor& factor = out.factors[f];
      auto at = std::find(factor.levels.begin(), factor.levels.end(), levels[f].second);
      if (at == factor.levels.end()) {
        factor.levels.push_back(levels[f].second);
        factor.subjects.push_back(0);
        at = factor.levels.end() - 1;
      }
      if (count) ++factor.subjects[static_cast<std::size_t>(at - factor.levels.begin())];
    }
  };
  // Every level a full square gives (numbers 1..square; ids matter only to a random order, whose levels are
  // the drawn ones), then the subjects counted on them.
  if (!out.drawn) {
    const std::size_t shown = std::min<std::size_t>(out.square, kMaxBalanceSquareShown);
    for (std::size_t n = 1; n <= shown; ++n)
      add(balance_levels(protocol, {"S" + std::to_string(n), n}), false);
  }
  for (const SubjectAssignment& subject : subjects) add(balance_levels(protocol, subject), true);
  return out;
}

bool Counterbalancing::filled() const noexcept {
  if (subjects % square != 0) return false;
  for (const BalanceFactor& factor : factors) {
    for (const std::size_t count : factor.subjects) {
      if (count != factor.subjects.front()) return false;
    }
  }
  return true;
}

bool Counterbalancing::reachable() const noexcept { return drawn || square <= kMaxReachableSquare; }

namespace {

// "group: 14,942 of its 14,950 levels with 0 subjects, 8 with 1": a factor of many levels, counted. Beyond
// kMaxBalanceSquareShown only the levels the subjects have are known: "8 levels with 1 subject".
std::string counted_levels(const BalanceFactor& factor, bool every_level) {
  std::map<std::size_t, std::size_t> levels_with;  // subjects -> levels with that many
  for (const std::size_t count : factor.subjects) ++levels_with[count];
  std::string text = factor.name + ": ";
  bool first = true;
  for (const auto& [count, levels] : levels_with) {
    text += first ? thousands(levels) +
                        (every_level ? " of its " + thousands(factor.levels.size()) + " levels" : " levels") +
                        " with " + std::to_string(count) + (count == 1 ? " subject" : " subjects")
                  : ", " + thousands(levels) + " with " + std::to_string(count);
    first = false;
  }
  return text;
}

}  // namespace

std::string Counterbalancing::warning() const {
  if (filled() || subjects == 0) return {};
  std::string text;
  if (!reachable()) {
    text = "a full counterbalancing square is " + thousands(square) + " subjects";
    if (groups > 1) text += " (the between-subjects groups alone repeat every " + thousands(groups) + ")";
    text += ", more than any study can recruit (at most " + thousands(kMaxReachableSquare) +
            "): no N balances this design; ";
  }
  text += "N=" + std::to_string(subjects);
  std::string parts;
  constexpr std::size_t kListedLevels = 6;
  for (const BalanceFactor& factor : factors) {
    bool even = true;
    for (const std::size_t count : factor.subjects) even &= count == factor.subjects.front();
    if (even) continue;
    if (factor.levels.size() > kListedLevels) {
      parts +=
          (parts.empty() ? "" : "; ") + counted_levels(factor, !drawn && square <= kMaxBalanceSquareShown);
      continue;
    }
    std::vector<std::size_t> order(factor.levels.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&factor](std::size_t a, std::size_t b) {
      return factor.subjects[a] < factor.subjects[b];
    });
    std::string part = factor.name + " ";
    for (std::size_t i = 0; i < order.size(); ++i) {
      const std::size_t count = factor.subjects[order[i]];
      part += (i == 0                  ? ""
               : i + 1 == order.size() ? " and "
                                       : ", ") +
              factor.levels[order[i]] + " with " + std::to_string(count) +
              (i == 0 ? (count == 1 ? " subject" : " subjects") : "");
    }
    parts += (parts.empty() ? "" : "; ") + part;
  }
  if (drawn) {
    text += parts.empty() ? " (orders or groups drawn per subject id, not balanced by number)"
                          : " leaves " + parts + " (drawn per subject id, not balanced by number)";
    return text;
  }
  text += " does not fill the counterbalancing square of " + thousands(square) + " subjects";
  if (reachable()) text += " (recruit a multiple of " + thousands(square) + ")";
  text += parts.empty() ? ": its cells are filled unevenly" : ": it leaves " + parts;
  return text;
}

}  // namespace calligraphy
