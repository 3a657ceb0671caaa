#pragma once
/// \file options.hpp
/// The options of a guided writing trial, one struct for every device and pacing (validated once, in
/// `TrialOptions::validate`).
#include <array>
#include <functional>
#include <string_view>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/display.hpp"

namespace calligraphy {

/// The most servo ticks a trial may last (max_duration_s x rate_hz): its trace, one sample a tick, is held
/// in memory. TrialOptions::validate, a trial specification (TrialSpec::validate, which Python's checks use)
/// and a protocol's trial settings (at reading) refuse more, each naming its own fields.
inline constexpr double kMaxTrialTicks = 1e7;
/// Whether a trial of `max_duration_s` [s] at `rate_hz` [Hz] has more ticks than kMaxTrialTicks: the one test
/// every reader of the two fields applies. NaN gives false; the fields' own ranges refuse it.
[[nodiscard]] constexpr bool exceeds_trial_ticks(double max_duration_s, double rate_hz) noexcept {
  return max_duration_s * rate_hz > kMaxTrialTicks;
}
/// The longest a trial may be stated to last [s] (one day): `TrialSpec::max_duration_s` is in (0, this].
inline constexpr double kMaxTrialDurationS = 86400.0;

/// How a trial's ticks are paced.
enum class TrialPacing {
  automatic,  ///< lock-step when the trial is given a hand (hand.hpp), real time otherwise
  lock_step,  ///< no wall clock: only with a hand that moves the device (else InvalidArgument)
  real_time,  ///< the `ServoLoop` at `rate_hz` on its own thread, with `loop`'s realtime settings
};

/// The one spelling of a pacing in the CLI, protocols, session folders, records and Python.
template <>
struct EnumTable<TrialPacing> {
  static constexpr std::string_view name = "TrialPacing";
  static constexpr std::array<EnumEntry<TrialPacing>, 3> entries{{
      {TrialPacing::automatic, "auto",
       "lock-step for devices a simulated writer moves, real time for any other"},
      {TrialPacing::lock_step, "lock-step", "no wall clock: a tick as soon as the last is done"},
      {TrialPacing::real_time, "real-time", "the servo loop on its own thread at the rate"},
  }};
};

/// "auto", "lock-step" or "real-time" (EnumTable).
[[nodiscard]] const char* to_string(TrialPacing pacing) noexcept;
/// The pacing spelled `text` (as `to_string` spells it). Throws InvalidArgument naming `what` (the option or
/// field) and the three spellings otherwise.
[[nodiscard]] TrialPacing parse_trial_pacing(std::string_view text, std::string_view what = "pacing");

/// Options of a trial on any device.
struct TrialOptions {
  ForceLawParameters force{};       ///< the force law; `force.guidance` switches guidance on or off
  SafetyChainParameters safety{};   ///< the renderer's safety chain (renderer.hpp)
  PassivityParameters passivity{};  ///< the renderer's passivity controller (off by default)
  double rate_hz = 1000.0;          ///< servo rate [Hz]: [100, 100000] lock-step, [100, 10000] real time
  TrialPacing pacing = TrialPacing::automatic;
  /// Real-time pacing: realtime mode, priority, CPU, stale-force and stall bounds. Its `rate_hz` is
  /// ignored: the trial's `rate_hz` is used.
  ServoLoopOptions loop{};
  /// The trial ends after this much device time [s]: > 0, and at most kMaxTrialTicks ticks at `rate_hz`.
  double max_duration_s = 300.0;
  bool keep_trace = true;  ///< keep one `TrialSample` per tick in the result
  /// Polled by the thread that runs the trial (never the servo thread): once per tick in lock-step,
  /// every millisecond in real time. Returning true ends the trial at the next tick with
  /// `TrialEnd::interrupted` (zero force, forces disabled, every recorded tick kept). May be empty.
  std::function<bool()> should_stop;
  /// Where the session publishes what the display shows after every tick (display.hpp); not owned,
  /// must outlive the trial. nullptr: nothing is published.
  DisplayChannel* display = nullptr;

  /// Throws InvalidArgument naming the field when a value is out of range (the rate for the pacing
  /// `pacing`, or either range for `automatic`, which is checked again once the device is known).
  void validate() const;
};

}  // namespace calligraphy
