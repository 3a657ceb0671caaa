#include "cli/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <utility>

#include "calligraphy/core/decimal_number.hpp"

namespace calligraphy::cli {

namespace {

// Half a second, so that a quick step shows nothing; CALLIGRAPHY_PROGRESS_AFTER_S (seconds >= 0) sets it, so
// that a test sees the progress of a step however fast the machine runs it.
std::chrono::steady_clock::duration first_shown_after() {
  const char* text = std::getenv("CALLIGRAPHY_PROGRESS_AFTER_S");
  if (text != nullptr) {
    if (const auto seconds = parse_finite_double(text); seconds && *seconds >= 0.0 && *seconds <= 3600.0) {
      return std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(*seconds));
    }
  }
  return std::chrono::milliseconds(500);
}

}  // namespace

TerminalProgress::TerminalProgress(std::string label)
    : enabled_(::isatty(STDERR_FILENO) == 1), label_(std::move(label)), first_shown_after_(first_shown_after()) {}

TerminalProgress::~TerminalProgress() { clear(); }

void TerminalProgress::clear() {
  if (!shown_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  shown_ = false;
}

void TerminalProgress::relabel(std::string label) {
  clear();
  label_ = std::move(label);
}

void TerminalProgress::update(std::size_t done, std::size_t total, const char* unit) {
  if (!enabled_) return;
  using namespace std::chrono_literals;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < first_shown_after_ || (shown_ && now - last_ < 100ms)) return;
  last_ = now;
  shown_ = true;
  if (unit[0] != '\0') {
    std::fprintf(stderr, "\r\033[K%s %zu / %zu %s", label_.c_str(), done, total, unit);
  } else {
    const double percent = total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0;
    std::fprintf(stderr, "\r\033[K%s %.0f%%", label_.c_str(), percent);
  }
  std::fflush(stderr);
}

}  // namespace calligraphy::cli
