#include "calligraphy/trial/options.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/servo_rate.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {

void TrialOptions::validate() const {
  // Lock-step has no wall clock, so it may run faster than any loop thread; real time is the ServoLoop's
  // range.
  const bool real_time = pacing == TrialPacing::real_time;
  if (!servo_rate_allowed(rate_hz, real_time)) {
    throw InvalidArgument("TrialOptions.rate_hz = " + detail::rate_text(rate_hz) + " must be in " +
                          servo_rate_range_text(real_time) + (real_time ? " in real time" : ""));
  }
  if (!(max_duration_s > 0.0) || !std::isfinite(max_duration_s)) {
    throw InvalidArgument("TrialOptions.max_duration_s = " + shortest_decimal(max_duration_s) +
                          " must be > 0");
  }
  // The trace is held in memory, one sample a tick (reserved up front in real time): a duration of 1e308 s
  // would be refused by the allocator, not by its field.
  if (exceeds_trial_ticks(max_duration_s, rate_hz)) {
    std::string message = "TrialOptions.max_duration_s = ";
    message.append(shortest_decimal(max_duration_s))
        .append(" s at ")
        .append(detail::rate_text(rate_hz))
        .append(" is more than a trial's limit of 10^7 ticks (kMaxTrialTicks)");
    throw InvalidArgument(message);
  }
  force.validate();
  passivity.validate();
  ServoLoopOptions paced = loop;
  paced.rate_hz =
      std::min(rate_hz, kMaxRealTimeServoRateHz);  // the loop's other fields; its rate is the trial's
  paced.validate();
}

const char* to_string(TrialPacing pacing) noexcept { return enum_spelling(pacing).data(); }

TrialPacing parse_trial_pacing(std::string_view text, std::string_view what) {
  if (const std::optional<TrialPacing> pacing = enum_from_spelling<TrialPacing>(text)) return *pacing;
  throw InvalidArgument(std::string(what) + ": '" + std::string(text) +
                        "' is not a pacing: expected 'auto', 'lock-step' or 'real-time'");
}

}  // namespace calligraphy
