// `calligraphy session plan PROTOCOL --subjects N [--json]`: what `session run` would run, subject by
// subject, and how N subjects fill the protocol's counterbalancing, without running or writing anything.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/study/cohort.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"
#include "cli/session_plan.hpp"
#include "cli/study_inputs.hpp"

namespace calligraphy::cli {
namespace {

// One session of one subject, as planned.
struct SessionShown {
  int number = 1;
  double delay_s = 0.0;  // after the subject's previous session (its first phase's delay_s)
  std::size_t trials = 0;
  double rest_s = 0.0;  // the rests planned between its trials
  std::vector<PlannedPhase> phases;
};

struct SubjectShown {
  const SubjectAssignment* subject = nullptr;
  std::string group, sequence, pairing;
  std::vector<SessionShown> sessions;
};

SubjectShown show_subject(const StudyProtocol& protocol, const SubjectAssignment& subject) {
  SubjectShown shown;
  shown.subject = &subject;
  shown.group = subject_group(protocol, subject);
  const CrossoverAssignment crossover = crossover_assignment(protocol, subject);
  shown.sequence = crossover.sequence;
  // From the assignment itself: counting a one-subject balance would walk the whole square per subject.
  shown.pairing = set_pairing(protocol, crossover);
  for (int number = 1; number <= protocol.session_count(); ++number) {
    SessionShown session;
    session.number = number;
    for (const ProtocolPhase& phase : protocol.phases) {
      if (phase.session == number) {
        session.delay_s = number > 1 ? phase.delay_s : 0.0;
        break;
      }
    }
    const std::vector<PlannedTrial> trials = plan_session(protocol, subject, number);
    session.trials = trials.size();
    for (const PlannedTrial& trial : trials) session.rest_s += trial.break_before_s;
    session.phases = plan_session_phases(protocol, subject, number);
    shown.sessions.push_back(std::move(session));
  }
  return shown;
}

// "1 h 02 min 05 s", "3 min 20 s", "45 s".
std::string duration_text(double seconds) {
  // Under ten seconds to the microsecond (a trial of 0.3 s is not one of "0 s", and three of them are 0.9 s,
  // not their sum's 0.8999999999999999 s); above, in whole seconds.
  if (seconds < 10.0) return shortest_decimal(std::round(seconds * 1e6) / 1e6) + " s";
  const auto total = static_cast<long long>(seconds + 0.5);
  char text[64];
  if (total >= 3600) {
    std::snprintf(text, sizeof text, "%lld h %02lld min %02lld s", total / 3600, total % 3600 / 60,
                  total % 60);
  } else if (total >= 60) {
    std::snprintf(text, sizeof text, "%lld min %02lld s", total / 60, total % 60);
  } else {
    std::snprintf(text, sizeof text, "%lld s", total);
  }
  return text;
}

// What a phase writes: its sets by name, or its characters (the first few, and how many more).
std::string phase_items(const ProtocolPhase& phase) {
  if (!phase.sets.empty()) {
    std::string text = phase.sets.size() == 1 ? "set " : "sets ";
    for (std::size_t i = 0; i < phase.sets.size(); ++i) text += (i == 0 ? "" : ", ") + phase.sets[i];
    return text;
  }
  constexpr std::size_t kShown = 6;
  std::string text = "items ";
  for (std::size_t i = 0; i < phase.items.size() && i < kShown; ++i)
    text += (i == 0 ? "" : " ") + encode_utf8(phase.items[i]);
  if (phase.items.size() > kShown) text += " and " + std::to_string(phase.items.size() - kShown) + " more";
  // Characters a crossover protocol attributes to the sets holding them.
  std::vector<std::string> sets;
  for (const std::string& set : phase.item_sets) {
    if (std::find(sets.begin(), sets.end(), set) == sets.end()) sets.push_back(set);
  }
  for (std::size_t i = 0; i < sets.size(); ++i)
    text += (i == 0 ? (sets.size() == 1 ? " (of set " : " (of sets ") : ", ") + sets[i];
  if (!sets.empty()) text += ")";
  return text;
}

std::string phase_line(const PlannedPhase& planned) {
  const ProtocolPhase& phase = *planned.phase;
  // A practice phase is the familiarisation: written first and not among the phases compared.
  std::string line = std::string(to_string(phase.kind)) + " (" + phase.pointer + ", " +
                     to_string(phase.assignment) +
                     (phase.kind == StudyPhase::practice ? ", familiarisation" : "") + "): ";
  for (std::size_t b = 0; b < planned.blocks.size(); ++b) {
    line += (b == 0 ? "" : ", then ") + planned.blocks[b];
    if (!planned.block_sets[b].empty()) line += " on " + planned.block_sets[b];
  }
  line += "; " + phase_items(phase) + "; " + std::to_string(planned.trials) +
          (planned.trials == 1 ? " trial" : " trials");
  if (phase.delay_s > 0.0 && planned.first_trial > 0)
    line += ", after a rest of " + duration_text(phase.delay_s);
  return line;
}

}  // namespace

std::string session_plan_text(const LoadedProtocol& loaded, std::span<const SubjectAssignment> subjects,
                              std::span<const SubjectAssignment> balanced) {
  const StudyProtocol& protocol = loaded.protocol;
  const double per_trial_s = protocol.trial.max_duration_s;
  std::string text =
      "plan of " + protocol.name + " (" + loaded.path.string() + ", sha256 " + loaded.sha256.substr(0, 12) +
      "): " + std::to_string(subjects.size()) + (subjects.size() == 1 ? " subject, " : " subjects, ") +
      std::to_string(protocol.session_count()) + (protocol.session_count() == 1 ? " session" : " sessions") +
      " each, trials of at most " + duration_text(per_trial_s) + "\n";
  for (const SubjectAssignment& subject : subjects) {
    const SubjectShown shown = show_subject(protocol, subject);
    text += subject.id + " (number " + std::to_string(subject.number) + ")";
    if (!shown.group.empty()) text += ": group " + shown.group;
    if (!shown.sequence.empty())
      text += std::string(shown.group.empty() ? ": " : ", ") + "sequence " + shown.sequence +
              ", set pairing " + shown.pairing;
    text += "\n";
    for (const SessionShown& session : shown.sessions) {
      text += "  session " + std::to_string(session.number);
      if (session.number > 1) text += " (" + duration_text(session.delay_s) + " after the previous one)";
      text += ": " + std::to_string(session.trials) + (session.trials == 1 ? " trial" : " trials") +
              ", at most " +
              duration_text(static_cast<double>(session.trials) * per_trial_s + session.rest_s) + " (" +
              duration_text(session.rest_s) + " of rests)\n";
      for (const PlannedPhase& phase : session.phases) text += "    " + phase_line(phase) + "\n";
    }
  }
  const Counterbalancing balance = counterbalancing(protocol, balanced.empty() ? subjects : balanced);
  text += "balance: ";
  if (!balanced.empty())
    text += "with the " + std::to_string(balanced.size() - subjects.size()) + " subjects before them, ";
  if (balance.drawn) {
    text +=
        "a random order draws each subject's orders and groups from its id; nothing is balanced by number";
  } else if (balance.square == 1) {
    text += "nothing is counterbalanced by subject number (every subject has the same plan)";
  } else {
    text += "a full counterbalancing square is " + thousands(balance.square) + " subjects";
    std::string factors;
    for (const BalanceFactor& factor : balance.factors)
      factors += (factors.empty() ? "" : " x ") + factor.name + " (" + thousands(factor.levels.size()) + ")";
    if (!factors.empty()) text += " over " + factors;
    if (!balance.reachable()) text += ", more than any study can recruit";
  }
  text += "\n";
  if (const std::string warning = balance.warning(); !warning.empty()) text += "warning: " + warning + "\n";
  return text;
}

std::string session_plan_json(const LoadedProtocol& loaded, std::span<const SubjectAssignment> subjects) {
  using Json = nlohmann::ordered_json;
  const StudyProtocol& protocol = loaded.protocol;
  Json document;
  document["format"] = "calligraphy-session-plan";
  document["version"] = 1;
  document["protocol"] = protocol.name;
  document["protocol_file"] = loaded.path.string();
  document["protocol_sha256"] = loaded.sha256;
  document["sessions"] = protocol.session_count();
  document["trial_max_duration_s"] = protocol.trial.max_duration_s;
  Json list = Json::array();
  for (const SubjectAssignment& subject : subjects) {
    const SubjectShown shown = show_subject(protocol, subject);
    Json entry;
    entry["id"] = subject.id;
    entry["number"] = subject.number;
    entry["group"] = shown.group;
    entry["sequence"] = shown.sequence;
    entry["set_pairing"] = shown.pairing;
    Json sessions = Json::array();
    for (const SessionShown& session : shown.sessions) {
      Json one;
      one["session"] = session.number;
      one["delay_s"] = session.delay_s;
      one["trials"] = session.trials;
      one["rest_s"] = session.rest_s;
      one["max_duration_s"] =
          static_cast<double>(session.trials) * protocol.trial.max_duration_s + session.rest_s;
      Json phases = Json::array();
      for (const PlannedPhase& planned : session.phases) {
        Json phase;
        phase["phase"] = to_string(planned.phase->kind);
        phase["pointer"] = planned.phase->pointer;
        phase["assignment"] = to_string(planned.phase->assignment);
        Json blocks = Json::array();
        for (std::size_t b = 0; b < planned.blocks.size(); ++b)
          blocks.push_back({{"condition", planned.blocks[b]}, {"set", planned.block_sets[b]}});
        phase["blocks"] = blocks;
        phase["sets"] = planned.phase->sets;
        Json items = Json::array();
        for (const std::u32string& item : planned.phase->items) items.push_back(encode_utf8(item));
        phase["items"] = items;
        phase["item_sets"] = planned.phase->item_sets;
        phase["repetitions"] = planned.phase->repetitions;
        // 1-based, the `index` of the phase's first trial in session.json's plan: a study's indices count
        // from 1 wherever it shows them.
        phase["first_trial"] = planned.first_trial + 1;
        phase["trials"] = planned.trials;
        phases.push_back(phase);
      }
      one["phases"] = phases;
      sessions.push_back(one);
    }
    entry["sessions"] = sessions;
    list.push_back(entry);
  }
  document["subjects"] = list;
  const Counterbalancing balance = counterbalancing(protocol, subjects);
  Json factors = Json::array();
  for (const BalanceFactor& factor : balance.factors) {
    Json levels = Json::array();
    for (std::size_t i = 0; i < factor.levels.size(); ++i)
      levels.push_back({{"level", factor.levels[i]}, {"subjects", factor.subjects[i]}});
    factors.push_back({{"name", factor.name}, {"levels", levels}});
  }
  document["balance"] = {{"square", balance.square},    {"subjects", balance.subjects},
                         {"filled", balance.filled()},  {"reachable", balance.reachable()},
                         {"drawn", balance.drawn},      {"factors", factors},
                         {"warning", balance.warning()}};
  return json_text(document, 2) + "\n";
}

namespace {

struct SessionPlanCommand {
  std::string protocol;
  std::int64_t subjects = 0;
  std::string prefix = "S";
  bool json = false;
  LibraryOptions library;
};

int print_session_plan(const SessionPlanCommand& command) {
  FilePlan files;
  files.input("PROTOCOL", command.protocol);
  add_library_inputs(files, command.library);
  const LoadedProtocol protocol = load_study_protocol(command.protocol);
  const CharacterSource characters(command.library);
  require_characters(protocol, characters);
  const LoadedProtocol resolved = resolved_protocol(protocol, characters);
  std::vector<SubjectAssignment> subjects;
  try {
    subjects = numbered_subjects(static_cast<std::size_t>(command.subjects), command.prefix);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--subject: ") + e.what());
  }
  write_standard_output(command.json ? session_plan_json(resolved, subjects)
                                     : session_plan_text(resolved, subjects));
  return 0;
}

}  // namespace

void add_session_plan_command(CLI::App& session, Commands& commands) {
  auto command = std::make_shared<SessionPlanCommand>();
  CLI::App* app = commands.add(
      session, "plan",
      "Print what session run would run for N subjects, without running anything: each subject's sequence, "
      "group, phases, item sets, trials and longest duration, and how N fills the counterbalancing square",
      [command] { return print_session_plan(*command); });
  add_positional(*app, "PROTOCOL", command->protocol, "the study protocol (JSON; docs/experiments.md)",
                 "FILE");
  required(add_integer(*app, "--subjects", command->subjects, "N",
                       "subjects PREFIX01..PREFIXN, numbered 1..N", 1, 1000));
  add_text(*app, "--subject", command->prefix, "PREFIX", "the prefix of the subjects' ids");
  add_flag(*app, "--json", command->json, "print the plan as JSON (docs/cli.md, \"session plan\")");
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
