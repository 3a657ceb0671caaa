// `calligraphy trace TRACE [--csv FILE]`: a saved trial's trace (a session's STEM.trace.h5) as the CSV that
// `trial --csv` writes (t,x,y,z,fx,fy,fz,state,stroke,element,attempt,rewritten; s, m, N): the export for
// spreadsheets and scripts that read no HDF5.
#include <memory>
#include <string>

#include "calligraphy/report/trace_hdf5.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"

namespace calligraphy::cli {
namespace {

struct TraceCommand {
  std::string trace;
  std::string csv = "-";
};

int run_trace(const TraceCommand& command) {
  FilePlan files;
  files.input("TRACE", command.trace);
  files.output("--csv", command.csv);
  write_output(command.csv,
               trial_csv(trial_samples(read_trace_hdf5(command.trace))));  // "-": standard output
  return 0;
}

}  // namespace

void add_trace_command(CLI::App& root, Commands& commands) {
  auto command = std::make_shared<TraceCommand>();
  CLI::App* app = commands.add(root, "trace",
                               "Write a saved trial's trace (.trace.h5) as CSV, the columns of trial --csv",
                               [command] { return run_trace(*command); });
  add_positional(*app, "TRACE", command->trace,
                 "the trace file (HDF5: a session folder's trials/STEM.trace.h5)", "FILE");
  with_default(add_output_path(*app, "--csv", command->csv, "write the CSV here", StandardOutput::allowed),
               "standard output");
}

}  // namespace calligraphy::cli
