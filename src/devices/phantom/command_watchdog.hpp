#pragma once
/// \file command_watchdog.hpp
/// Trips when no force command arrived within a timeout, so that a stalled application cannot leave a
/// force on. Pure bookkeeping on caller-supplied time stamps: no clock, no allocation.

namespace calligraphy::devices {

class CommandWatchdog {
 public:
  /// `timeout_s` [s] > 0.
  explicit CommandWatchdog(double timeout_s) noexcept : timeout_s_(timeout_s) {}

  /// A command arrived at `now_s` [s]; arms the watchdog.
  void kick(double now_s) noexcept {
    last_command_s_ = now_s;
    armed_ = true;
  }
  /// Stops watching (forces are off, nothing to guard).
  void disarm() noexcept { armed_ = false; }
  [[nodiscard]] bool armed() const noexcept { return armed_; }
  /// True when armed and more than the timeout has passed since the last command.
  [[nodiscard]] bool expired(double now_s) const noexcept {
    return armed_ && now_s - last_command_s_ > timeout_s_;
  }
  [[nodiscard]] double timeout_s() const noexcept { return timeout_s_; }

 private:
  double timeout_s_;
  double last_command_s_ = 0.0;
  bool armed_ = false;
};

}  // namespace calligraphy::devices
