// `calligraphy curriculum DIR... --subject ID --from CHARS [--count N] [--json]`: the characters a learner
// should practise next, from its saved trials (study/curriculum.hpp): new typical strokes first, then the
// ones it writes worst, spread over characters it has not written.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/study/curriculum.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct CurriculumCommand {
  std::vector<std::string> folders;
  std::string subject;
  std::string candidates;
  std::int64_t count = 3;
  bool json = false;
  LibraryOptions library;
};

std::string acronyms(const std::vector<int>& ids) {
  std::string out;
  for (const int id : ids) {
    if (!out.empty()) out += ' ';
    out += typical_stroke(id).acronym;
  }
  return out.empty() ? "-" : out;
}

int run_curriculum(const CurriculumCommand& command) {
  FilePlan files;
  for (const std::string& folder : command.folders) add_saved_sessions(files, "DIR", folder);
  add_library_inputs(files, command.library);
  std::u32string candidates;
  try {
    candidates = decode_utf8(command.candidates);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--from: not UTF-8: ") + e.what());
  }
  if (candidates.empty()) throw UsageError("--from: give the characters to choose from");
  const StudyTables tables =
      read_study_tables(std::vector<std::filesystem::path>(command.folders.begin(), command.folders.end()));
  std::vector<TypicalStrokeRecord> record;
  try {
    record = typical_stroke_record(tables, command.subject);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("--subject: ") + e.what());
  }
  const CharacterSource source(command.library);
  const auto typical_ids = [&source](char32_t c) {
    std::vector<int> ids;
    for (const Stroke& stroke : source.load_named(c, "--from").strokes) ids.push_back(stroke.typical_id);
    return ids;
  };
  const std::vector<ProposedCharacter> proposed =
      propose_characters(record, written_characters(tables, command.subject), candidates,
                         static_cast<std::size_t>(command.count), typical_ids);
  if (command.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const ProposedCharacter& p : proposed) {
      out.push_back({{"character", encode_utf8(p.character)},
                     {"new_strokes", p.new_strokes},
                     {"weak_strokes", p.weak_strokes}});
    }
    std::printf("%s\n", json_text(out, 2).c_str());
    return 0;
  }
  std::printf("%s: %zu of %zu typical strokes written; next:\n", command.subject.c_str(),
              static_cast<std::size_t>(std::count_if(
                  record.begin(), record.end(), [](const TypicalStrokeRecord& r) { return r.written > 0; })),
              typical_strokes().size());
  for (const ProposedCharacter& p : proposed) {
    std::printf("  %s  new: %s; again: %s\n", encode_utf8(p.character).c_str(),
                acronyms(p.new_strokes).c_str(), acronyms(p.weak_strokes).c_str());
  }
  if (proposed.empty()) std::printf("  (no candidate adds a new or a weak typical stroke)\n");
  return 0;
}

}  // namespace

void add_curriculum_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<CurriculumCommand>();
  CLI::App* app = commands.add(
      root, "curriculum",
      "Propose the characters a learner should practise next: new typical strokes, then its weakest",
      [command] { return run_curriculum(*command); });
  add_positional_list(*app, "DIR", command->folders,
                      "session folders of the learner, or folders holding them", "DIR");
  required(add_text(*app, "--subject", command->subject, "ID", "the learner's subject id"));
  required(add_text(*app, "--from", command->candidates, "CHARS", "the characters to choose from (UTF-8)"));
  add_integer(*app, "--count", command->count, "N", "characters to propose", 1,
              static_cast<std::int64_t>(kMaxProposedCharacters));
  add_flag(*app, "--json", command->json, "print the proposal as JSON");
  add_library_options(*app, command->library, true);
}

}  // namespace calligraphy::cli
