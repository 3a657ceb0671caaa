#pragma once
// Progress of a long step on the terminal: "\r<label> 42%" on stderr, only when stderr is a terminal (never
// into a redirected log or a pipe), first shown after half a second and at most ten times a second; the
// line is cleared when the step ends (by spaces on a dumb terminal, TERM=dumb, which shows escapes as text).
// The label is printed as printable text, so a file name cannot act on the terminal.
// CALLIGRAPHY_PROGRESS_AFTER_S (seconds) changes the half second.
#include <chrono>
#include <cstddef>
#include <string>

namespace calligraphy::cli {

class TerminalProgress {
 public:
  /// Shows nothing unless stderr is a terminal.
  explicit TerminalProgress(std::string label);
  ~TerminalProgress();
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;

  /// `done` of `total` (bytes, segments); `unit` names them ("segments"), or is empty to show a percentage.
  void update(std::size_t done, std::size_t total, const char* unit = "");
  /// Starts a new step: clears the line and shows `label` from now on.
  void relabel(std::string label);

 private:
  void clear();

  bool enabled_ = false;
  bool escapes_ = true;
  std::size_t shown_bytes_ = 0;
  bool shown_ = false;
  std::string label_;
  std::chrono::steady_clock::duration first_shown_after_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace calligraphy::cli
