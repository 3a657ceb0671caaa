// `calligraphy schema specification|record`: the JSON Schema (draft 2020-12) of a trial specification or of a
// trial record's specification object, made from the one schema the readers and writers use (schema.hpp), or
// with --markdown the fields as the documentation's table.
#include <string>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/study/recorded_trial.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "cli/app.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct SchemaCommand {
  std::string document;
  bool markdown = false;
};

int run_schema(const SchemaCommand& command) {
  // A specification a person writes may leave out what keeps its default; a record holds every part.
  const bool record = command.document == "record";
  const Schema& schema = record ? recorded_trial_schema() : SchemaOf<TrialSpec>::get();
  if (command.markdown) {
    write_output("-", schema_markdown(schema));
    return 0;
  }
  const std::string id = "https://calligraphy.invalid/schema/" + command.document + ".json";
  write_output("-", json_schema_text(schema, id,
                                     record ? "calligraphy trial record (its \"specification\" object)"
                                            : "calligraphy trial specification",
                                     record));
  return 0;
}

}  // namespace

void add_schema_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<SchemaCommand>();
  CLI::App* app = commands.add(root, "schema",
                               "Print the JSON Schema (2020-12) of a trial specification or a trial record",
                               [command] { return run_schema(*command); });
  required(
      add_choice(*app, "DOCUMENT", command->document, {"specification", "record"},
                 "specification: a trial as `trial --spec` and Python state it (keys left out keep their "
                 "defaults); record: the \"specification\" object of a trial record (every part required)"));
  add_flag(*app, "--markdown", command->markdown, "the fields as a Markdown table instead");
}

}  // namespace calligraphy::cli
