// The `calligraphy` program: guided writing trials on any device, scoring of pen traces, models, the
// corpus store, benchmarks. docs/cli.md describes every command.
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <set>
#include <string>
#include <string_view>
#include <system_error>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/logging.hpp"
#include "calligraphy/study/protocol.hpp"
#include "cli/cli_devices.hpp"
#include "cli/commands.hpp"
#include "cli/output.hpp"
#include "cli/suggest.hpp"

namespace calligraphy::cli {
namespace {

// The subcommands given so far, e.g. "calligraphy corpus build", and the deepest of them.
std::pair<std::string, const CLI::App*> given_command(const CLI::App& root) {
  std::string name = "calligraphy";
  const CLI::App* current = &root;
  while (true) {
    const auto selected = current->get_subcommands();
    if (selected.empty()) return {name, current};
    current = selected.front();
    name += " " + current->get_name();
  }
}

void print_error(const std::string& command, const std::string& message) {
  print_error_line(command, "error", message);
}

// The library's log as the command's own lines on standard error, one line each in the error lines' form:
// "calligraphy trial: warning: Phantom: ...". Its errors (a servo loop's watchdog) are warnings of the
// command, which says itself how it ended; info lines only with --verbose. Standard output carries reports.
// A warning said word for word before is not said again: each trial of a session builds its renderer, and a
// stiffness above the device's passivity bound was said once per trial.
void show_library_log(const std::string& command, bool verbose) {
  struct Said {
    std::mutex mutex;  // the handler may be called from the corpus fitter's threads
    std::set<std::string, std::less<>> warnings;
  };
  auto said = std::make_shared<Said>();
  calligraphy::set_log_handler([command, said](calligraphy::LogLevel level, std::string_view message) {
    using calligraphy::LogLevel;
    if (level >= LogLevel::warning) {
      const std::lock_guard<std::mutex> lock(said->mutex);
      if (!said->warnings.emplace(message).second) return;
    }
    const char* kind = level >= LogLevel::warning ? "warning" : level == LogLevel::info ? "info" : "debug";
    print_error_line(command, kind, message);
  });
  calligraphy::set_log_level(verbose ? calligraphy::LogLevel::info : calligraphy::LogLevel::warning);
}

}  // namespace

void add_corpus_commands(CLI::App& root, Commands& commands) {
  CLI::App* corpus =
      commands.add_group(root, "corpus", "The corpus store of all hanzi-writer-data characters");
  add_corpus_build_command(*corpus, commands);
  add_corpus_stats_command(*corpus, commands);
  add_corpus_fidelity_command(*corpus, commands);
  add_corpus_validate_command(*corpus, commands);
}

void add_bench_commands(CLI::App& root, Commands& commands) {
  CLI::App* bench =
      commands.add_group(root, "bench", "Measurements of the nearest-point methods and the servo loop");
  add_bench_nearest_command(*bench, commands);
  add_bench_jumps_command(*bench, commands);
  add_bench_tick_command(*bench, commands);
  add_bench_loop_command(*bench, commands);
  add_bench_acceptance_command(*bench, commands);
}

}  // namespace calligraphy::cli

int main(int argc, char** argv) {
  using namespace calligraphy::cli;
  // Before any thread and any file: a file size limit, a closed pipe and a stop signal while a file is
  // written each end as an error line or a signal with the temporary removed, never a silent death.
  calligraphy::guard_output_files();
  CLI::App root("Haptic training of Chinese handwriting: guided trials, scoring, character models",
                "calligraphy");
  configure_root(root);
  Commands commands;
  // The program's devices: one registry, owned here and passed to the commands that open a device.
  calligraphy::DeviceRegistry devices = make_cli_device_registry();
  add_trial_command(root, commands, devices);
  add_train_command(root, commands, devices);
  add_score_command(root, commands);
  add_model_command(root, commands);
  add_strokes_command(root, commands);
  add_schema_command(root, commands);
  add_characters_command(root, commands);
  add_trace_command(root, commands);
  add_devices_command(root, commands, devices);
  add_corpus_commands(root, commands);
  add_bench_commands(root, commands);
  add_session_commands(root, commands, devices);
  add_report_command(root, commands);
  add_curriculum_command(root, commands);

  int status = 0;
  try {
    try {
      parse_command_line(root, argc, argv);
    } catch (const CLI::Success& e) {  // --help, --version: printed on stdout, status 0
      return finish_standard_output(root.exit(e), given_command(root).first);
    } catch (const CLI::ParseError& e) {
      const auto [name, deepest] = given_command(root);
      std::string message = e.what();
      // A group given without its subcommand: its help shows what it offers. A group given a word that is
      // none of its commands (`calligraphy trail`) is the one error line below, naming the near ones.
      if (deepest->get_require_subcommand_min() > 0 && deepest->get_subcommands().empty() &&
          deepest->remaining().empty()) {
        const auto parent_end = name.rfind(' ');
        std::fputs(deepest->help(parent_end == std::string::npos ? "" : name.substr(0, parent_end)).c_str(),
                   stderr);
      }
      // An argument left unplaced is the cause of these errors (a mistyped option also leaves the option
      // it meant missing, `score T --charcter C`): it is named, with what it was likely meant to be.
      if (dynamic_cast<const CLI::ExtrasError*>(&e) || dynamic_cast<const CLI::RequiredError*>(&e)) {
        if (std::string unknown = unknown_argument_message(*deepest); !unknown.empty()) message = unknown;
      }
      // CLI11 words a value given to a flag (`--json=yes`) as an "override": say what the user did.
      if (dynamic_cast<const CLI::ArgumentMismatch*>(&e)) {
        static constexpr std::string_view kOverride = " was given a disallowed flag override";
        if (message.size() > kOverride.size() && message.ends_with(kOverride)) {
          std::string flag = message.substr(0, message.size() - kOverride.size());
          message = flag.size() == 1 ? "-" : "--";
          message.append(flag).append(": a flag takes no value");
        }
        // An option left without its value (`--svg` last, `--svg=`): CLI11 says "--svg: 1 required  missing".
        if (const auto required = message.find(": 1 required ");
            required != std::string::npos && message.ends_with(" missing")) {
          message = message.substr(0, required) + ": expects a value, none was given";
        }
      }
      print_error(name, message);
      return 2;
    }
    show_library_log(given_command(root).first, commands.verbose());
    status = commands.run_selected();
  } catch (const UsageError& e) {
    print_error(given_command(root).first, e.what());
    status = 2;
  } catch (const calligraphy::InputError& e) {  // a protocol's or a record's content: as a bad option
    print_error(given_command(root).first, e.what());
    status = 2;
  } catch (const calligraphy::Error& e) {
    print_error(given_command(root).first, e.what());
    status = 1;
  } catch (const std::bad_alloc&) {  // a limit on the address space (ulimit -v) or no memory left
    print_error(given_command(root).first, "out of memory (the memory this process may use is used up)");
    status = 1;
  } catch (const std::system_error& e) {
    if (e.code() != std::errc::resource_unavailable_try_again) {
      print_error_line(given_command(root).first, "internal error", e.what());
      status = 3;
    } else {  // std::thread's refusal: RLIMIT_NPROC, or no memory for a thread's stack
      print_error(given_command(root).first,
                  std::string("cannot start a thread: ") + e.code().message() +
                      " (the threads this user may run, RLIMIT_NPROC, or the memory of a thread's stack are "
                      "used up)");
      status = 1;
    }
  } catch (const std::exception& e) {
    print_error_line(given_command(root).first, "internal error", e.what());
    status = 3;
  }
  return finish_standard_output(status, given_command(root).first);
}
