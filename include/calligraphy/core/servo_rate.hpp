#pragma once
/// \file servo_rate.hpp
/// The servo rates the library runs at [Hz]: the one definition that every check, option and message reads.
/// A lock-step trial (the simulated device, no wall clock) or a renderer ticked from its caller's own loop
/// runs at up to 100 kHz; a real-time loop (the ServoLoop's thread, a driver's scheduler) at up to 10 kHz,
/// ten times a Phantom's 1 kHz servo rate (Wang, Zhang & Yao 2006, section 7).
#include <string>

namespace calligraphy {

inline constexpr double kMinServoRateHz = 100.0;            ///< lowest rate of any loop [Hz]
inline constexpr double kMaxServoRateHz = 100000.0;         ///< highest lock-step or caller-ticked rate [Hz]
inline constexpr double kMaxRealTimeServoRateHz = 10000.0;  ///< highest real-time loop rate [Hz]

/// True when `rate_hz` is within the range of a real-time loop (`real_time`) or of any other.
[[nodiscard]] constexpr bool servo_rate_allowed(double rate_hz, bool real_time) noexcept {
  return rate_hz >= kMinServoRateHz && rate_hz <= (real_time ? kMaxRealTimeServoRateHz : kMaxServoRateHz);
}

/// The range as messages write it: "[100, 100000] Hz", or "[100, 10000] Hz" for a real-time loop.
[[nodiscard]] std::string servo_rate_range_text(bool real_time);

}  // namespace calligraphy
