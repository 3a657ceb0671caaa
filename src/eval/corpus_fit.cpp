#include "eval/corpus_fit.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <span>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/core/worker_threads.hpp"

namespace calligraphy::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A bar redrawn in place on a terminal; elsewhere (a log, CI) one line per 10 % when asked for
// (`log_lines`), else nothing.
class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total, bool log_lines)
      : label_(std::move(label)), total_(total), tty_(::isatty(STDERR_FILENO) != 0), log_lines_(log_lines) {}
  void show(std::size_t done) {
    if (tty_) {
      constexpr int kWidth = 40;
      const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
      std::fprintf(stderr, "\r%s [%.*s%*s] %zu/%zu", label_.c_str(), filled,
                   "########################################", kWidth - filled, "", done, total_);
      if (done == total_) std::fputc('\n', stderr);
    } else if (log_lines_) {
      const std::size_t tenth = total_ ? 10 * done / total_ : 10;
      if (tenth > last_tenth_ || (done == total_ && !finished_)) {
        std::fprintf(stderr, "%s: %zu/%zu\n", label_.c_str(), done, total_);
        last_tenth_ = tenth;
      }
      finished_ = done == total_;
    }
  }

 private:
  std::string label_;
  std::size_t total_;
  bool tty_;
  bool log_lines_;
  std::size_t last_tenth_ = 0;
  bool finished_ = false;
};

}  // namespace

std::filesystem::path fetched_corpus_folder() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  // The XDG base directory specification: $XDG_CACHE_HOME only when it is an absolute path (an empty or
  // relative one is ignored), else $HOME/.cache.
  std::filesystem::path cache;
  if (xdg != nullptr && std::filesystem::path(xdg).is_absolute()) {
    cache = xdg;
  } else if (home != nullptr) {
    cache = std::filesystem::path(home) / ".cache";
  }
  return cache / "calligraphy" / "hanzi-writer-data-2.0.1";
}

std::optional<std::filesystem::path> complete_fetched_corpus_folder() {
  const auto fetched = fetched_corpus_folder();
  std::error_code ec;
  // Without a cache folder the path is relative to the working directory: not the fetched data.
  if (fetched.parent_path() == "calligraphy") return std::nullopt;
  if (std::filesystem::exists(fetched / ".complete", ec)) return fetched;
  return std::nullopt;
}

unsigned default_corpus_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

CorpusFit fit_corpus(const CharacterLibrary& library, const FitOptions& options, unsigned threads,
                     const std::string& label, bool log_progress) {
  const auto start = Clock::now();
  const std::vector<char32_t> code_points = library.characters();
  std::vector<Character> fitted(code_points.size());
  std::vector<std::vector<double>> deviations(code_points.size());
  std::vector<std::string> errors(code_points.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::mutex timing_mutex;  // guards the timings and `fatal`
  std::exception_ptr fatal;
  std::atomic<bool> failed{false};
  double read_parse = 0.0;
  double fit = 0.0;

  const auto work = [&] {
    double my_read = 0.0;
    double my_fit = 0.0;
    for (std::size_t k = next++; k < code_points.size(); k = next++) {
      try {
        const auto t0 = Clock::now();
        const CharacterData data = library.load_data(code_points[k]);
        const auto t1 = Clock::now();
        // As fit_character, keeping each stroke's max deviation.
        Character& character = fitted[k];
        character.code_point = code_points[k];
        character.source = data.source;
        for (const auto& median : data.medians) {
          FittedStroke stroke = fit_stroke(median, options);
          deviations[k].push_back(stroke.max_deviation);
          character.strokes.push_back(std::move(stroke.stroke));
        }
        my_fit += seconds_since(t1);
        my_read += std::chrono::duration<double>(t1 - t0).count();
      } catch (const DataError& e) {  // the character's data: reported per character below, never fatal
        errors[k] = e.what();
      } catch (const InvalidArgument& e) {  // a median the fitter cannot take: as the data's
        errors[k] = e.what();
      } catch (...) {
        // The machine's refusal (no memory, no file descriptor: Error, bad_alloc), not the data's: the run
        // fails whole, since a store without the characters it could not read would replace a good one.
        const std::lock_guard lock(timing_mutex);
        if (!fatal) fatal = std::current_exception();
        next = code_points.size();
        failed = true;
      }
      ++done;
    }
    const std::lock_guard lock(timing_mutex);
    read_parse += my_read;
    fit += my_fit;
  };
  WorkerThreads pool(threads, work);
  if (pool.started() == 0) work();  // no thread could be started: the characters are fitted here
  ProgressBar bar(label, code_points.size(), log_progress);
  while (done < code_points.size() && !failed) {
    bar.show(done);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  pool.join();
  if (fatal) std::rethrow_exception(fatal);
  bar.show(code_points.size());

  CorpusFit result;
  result.threads = std::max<unsigned>(1, static_cast<unsigned>(pool.started()));  // those that ran
  for (std::size_t k = 0; k < code_points.size(); ++k) {
    if (errors[k].empty()) {
      result.characters.push_back(std::move(fitted[k]));
      result.fitter_deviation.push_back(std::move(deviations[k]));
    } else {
      result.failures.push_back({code_points[k], errors[k]});
    }
  }
  result.wall_s = seconds_since(start);
  result.read_parse_cpu_s = read_parse;
  result.fit_cpu_s = fit;
  return result;
}

void drop_unstorable(CorpusFit& fit, const CorpusStoreOptions& options) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < fit.characters.size(); ++k) {
    try {
      encode_corpus_store(std::span(&fit.characters[k], 1), options);
    } catch (const InvalidArgument& e) {
      fit.failures.push_back({fit.characters[k].code_point, e.what()});
      continue;
    }
    if (kept != k) {
      fit.characters[kept] = std::move(fit.characters[k]);
      fit.fitter_deviation[kept] = std::move(fit.fitter_deviation[k]);
    }
    ++kept;
  }
  fit.characters.resize(kept);
  fit.fitter_deviation.resize(kept);
  std::stable_sort(
      fit.failures.begin(), fit.failures.end(),
      [](const CorpusFitFailure& a, const CorpusFitFailure& b) { return a.code_point < b.code_point; });
}

}  // namespace calligraphy::cli
