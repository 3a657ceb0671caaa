#include "cli/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <utility>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/printable_text.hpp"

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

// Whether the terminal takes "\033[K" (erase to the end of the line): every one but a dumb one (TERM=dumb, as
// Emacs' shell says), which would show the escape as text.
bool erases_with_escapes() {
  const char* term = std::getenv("TERM");
  return term == nullptr || std::string_view(term) != "dumb";
}

}  // namespace

TerminalProgress::TerminalProgress(std::string label)
    : enabled_(::isatty(STDERR_FILENO) == 1),
      escapes_(erases_with_escapes()),
      label_(printable_one_line(label)),
      first_shown_after_(first_shown_after()) {}

TerminalProgress::~TerminalProgress() { clear(); }

void TerminalProgress::clear() {
  if (!shown_) return;
  if (escapes_) {
    std::fprintf(stderr, "\r\033[K");
  } else {
    std::fprintf(stderr, "\r%*s\r", static_cast<int>(shown_bytes_), "");
  }
  std::fflush(stderr);
  shown_ = false;
  shown_bytes_ = 0;
}

void TerminalProgress::relabel(std::string label) {
  clear();
  label_ = printable_one_line(label);
}

void TerminalProgress::update(std::size_t done, std::size_t total, const char* unit) {
  if (!enabled_) return;
  using namespace std::chrono_literals;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < first_shown_after_ || (shown_ && now - last_ < 100ms)) return;
  last_ = now;
  shown_ = true;
  // "\r" then the line; a terminal that erases takes "\033[K" first, a dumb one gets spaces over what is left
  // of the longer line before.
  const char* erase = escapes_ ? "\033[K" : "";
  int written = 0;
  if (unit[0] != '\0') {
    written = std::fprintf(stderr, "\r%s%s %zu / %zu %s", erase, label_.c_str(), done, total, unit);
  } else {
    const double percent = total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0;
    written = std::fprintf(stderr, "\r%s%s %.0f%%", erase, label_.c_str(), percent);
  }
  const std::size_t prefix = 1 + std::string_view(erase).size();  // "\r" and the erase
  const std::size_t line = written > 0 && static_cast<std::size_t>(written) > prefix ? written - prefix : 0;
  if (!escapes_ && line < shown_bytes_)
    std::fprintf(stderr, "%*s", static_cast<int>(shown_bytes_ - line), "");
  shown_bytes_ = std::max(line, shown_bytes_);
  std::fflush(stderr);
}

}  // namespace calligraphy::cli
