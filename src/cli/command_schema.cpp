// `calligraphy schema specification|record|protocol|session|metrics`: the JSON Schema (draft 2020-12) of a
// trial specification, of a trial record's specification object, of a study protocol, of a session folder's
// session.json or of a record's metrics,
// made from the one schema and the tables the readers and writers use (schema.hpp, metric_table.hpp), or with
// --markdown the fields as the documentation's table.
#include <string>

#include "calligraphy/analysis/metric_table.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/recorded_trial.hpp"
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
  if (command.document == "metrics") {
    // the metric keys of a record's scene level; the table as a whole with --markdown
    write_output("-", command.markdown ? metric_markdown() : metric_json_schema(metric_level_scene));
    return 0;
  }
  if (command.document == "protocol") {
    write_output("-", command.markdown ? protocol_schema_markdown() : protocol_json_schema_text());
    return 0;
  }
  if (command.document == "session") {
    write_output("-", command.markdown ? schema_markdown(session_manifest_schema())
                                       : session_manifest_json_schema_text());
    return 0;
  }
  if (command.document == "record") {
    write_output(
        "-", command.markdown ? schema_markdown(recorded_trial_schema()) : recorded_trial_json_schema_text());
    return 0;
  }
  // A specification a person writes may leave out what keeps its default.
  const Schema& schema = SchemaOf<TrialSpec>::get();
  write_output("-", command.markdown
                        ? schema_markdown(schema)
                        : json_schema_text(schema, "https://calligraphy.invalid/schema/specification.json",
                                           "calligraphy trial specification", false));
  return 0;
}

}  // namespace

void add_schema_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<SchemaCommand>();
  CLI::App* app = commands.add(
      root, "schema",
      "Print the JSON Schema (2020-12) of a trial specification, a trial record, a study protocol, a "
      "session's session.json or a record's metrics",
      [command] { return run_schema(*command); });
  required(add_choice(
      *app, "DOCUMENT", command->document, {"specification", "record", "protocol", "session", "metrics"},
      "specification: a trial as `trial --spec` and Python state it (keys left out keep their "
      "defaults); record: the \"specification\" object of a trial record (every part required); protocol: a "
      "study protocol file (docs/experiments.md); session: a session folder's session.json (every part "
      "required but the keys added since the first folders); metrics: the metric keys of a trial's metrics "
      "record "
      "(docs/metrics.md; with --markdown the whole metric table)"));
  add_flag(*app, "--markdown", command->markdown, "the fields as a Markdown table instead");
}

}  // namespace calligraphy::cli
