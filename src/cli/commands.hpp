#pragma once
// The commands of the `calligraphy` program. Each adds its subcommand (options, help) to the root and
// registers what runs it; the run writes its report to stdout or to files and returns the exit status.
// Errors are thrown (calligraphy::Error, UsageError) and turned into one line and a status by main().
#include "calligraphy/devices/device_registry.hpp"
#include "cli/app.hpp"

namespace calligraphy::cli {

void add_trial_command(CLI::App& root, Commands& commands, DeviceRegistry& devices);  // trial CHARS [...]
void add_train_command(CLI::App& root, Commands& commands,
                       DeviceRegistry& devices);                // train CHARS [...] (the trainer window)
void add_score_command(CLI::App& root, Commands& commands);     // score TRACE.csv --character C [...]
void add_trace_command(CLI::App& root, Commands& commands);     // trace TRACE.trace.h5 [--csv FILE]
void add_model_command(CLI::App& root, Commands& commands);     // model CHAR [...]
void add_strokes_command(CLI::App& root, Commands& commands);   // strokes [--markdown FILE] [--json]
// characters [--strokes N] [--typical STROKE] [--text TEXT] [--json]
void add_characters_command(CLI::App& root, Commands& commands);
void add_devices_command(CLI::App& root, Commands& commands, DeviceRegistry& devices);  // devices [--json]
void add_corpus_commands(CLI::App& root, Commands& commands);  // corpus build|stats|fidelity|validate
void add_bench_commands(CLI::App& root, Commands& commands);   // bench nearest|jumps|tick|loop|acceptance
void add_session_commands(CLI::App& root, Commands& commands, DeviceRegistry& devices);  // session run|resume
void add_report_command(CLI::App& root, Commands& commands);
void add_schema_command(CLI::App& root, Commands& commands);  // schema specification|record [--markdown]
void add_curriculum_command(
    CLI::App& root,
    Commands& commands);  // curriculum DIR... --subject ID --from CHARS    // report DIR... --out FILE

// The subcommands of the groups, one file each.
void add_corpus_build_command(CLI::App& corpus, Commands& commands);
void add_corpus_stats_command(CLI::App& corpus, Commands& commands);
void add_corpus_fidelity_command(CLI::App& corpus, Commands& commands);
void add_corpus_validate_command(CLI::App& corpus, Commands& commands);
void add_bench_nearest_command(CLI::App& bench, Commands& commands);
void add_bench_jumps_command(CLI::App& bench, Commands& commands);
void add_bench_tick_command(CLI::App& bench, Commands& commands);
void add_bench_loop_command(CLI::App& bench, Commands& commands);
void add_bench_acceptance_command(CLI::App& bench, Commands& commands);
void add_session_cohort_command(CLI::App& session, Commands& commands);
void add_session_plan_command(CLI::App& session, Commands& commands);

}  // namespace calligraphy::cli
