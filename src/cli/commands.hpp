#pragma once
// Sub-commands of the `calligraphy` program. Each takes the arguments after its name, writes its
// report to stdout, and returns the process exit status. Errors are thrown (calligraphy::Error or
// cli::UsageError) and turned into a one-line message with a non-zero status by main().
#include <stdexcept>
#include <string>
#include <vector>

namespace calligraphy::cli {

using Args = std::vector<std::string>;

/// Wrong command-line usage; main() prints the message and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

int command_trial(const Args& args);          // calligraphy trial CHARS [...]
int command_model(const Args& args);          // calligraphy model CHAR [...]
int command_bench_nearest(const Args& args);  // calligraphy bench nearest [--json] [...]
int command_bench_jumps(const Args& args);    // calligraphy bench jumps [--json] [...]
int command_bench_tick(const Args& args);     // calligraphy bench tick [--json] [...]
int command_devices(const Args& args);        // calligraphy devices
int command_corpus(const Args& args);           // calligraphy corpus build|stats|fidelity [...]
int command_corpus_validate(const Args& args);  // calligraphy corpus validate --data DIR --cnchar FILE [...]
int command_strokes(const Args& args);          // calligraphy strokes [--markdown FILE] [--json]
int command_bench_loop(const Args& args);     // calligraphy bench loop [--rate HZ] [--seconds S] [...]

}  // namespace calligraphy::cli
