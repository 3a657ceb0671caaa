#include "calligraphy/trial/session.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "core/library_log.hpp"
#include "core/rate_text.hpp"

namespace calligraphy {
namespace {

// The renderer's options of checked trial options: its rate within the trial's range (inside the renderer's)
// and the passivity controller TrialOptions::validate checked; the safety chain is the renderer's to check,
// once the device's figures fill it.
Checked<RendererOptions> renderer_options(const Checked<TrialOptions>& options) {
  return options.derive([](const TrialOptions& trial) {
    RendererOptions render;
    render.rate_hz = trial.rate_hz;
    render.safety = trial.safety;
    render.passivity = trial.passivity;
    return render;
  });
}

// Most ticks of trace room reserved before the trial, untouched: 2^19, 42 MB of address space.
constexpr std::size_t kUntouchedTraceTicks = std::size_t{1} << 19;

}  // namespace

TrialSession::TrialSession(const Scene& scene, const DeviceInfo& device, const TrialOptions& options)
    : TrialSession(scene, device, Checked<TrialOptions>::check(options)) {}

TrialSession::TrialSession(const Scene& scene, const DeviceInfo& device, const Checked<TrialOptions>& checked)
    : options_(*checked),
      renderer_(scene, checked.part(&TrialOptions::force), device, renderer_options(checked)),
      recorder_(scene, options_.keep_trace),
      max_ticks_(static_cast<std::size_t>(std::ceil(options_.max_duration_s * options_.rate_hz))) {
  // Room for the whole trace, untouched (pages are touched as samples are written): the trace never moves
  // while it grows, which a lock-step trial would otherwise pay for in copies and page faults. Capped, so
  // that a long fast trial does not reserve gigabytes of address space up front.
  if (options_.keep_trace)
    recorder_.reserve_untouched(std::min<std::size_t>(max_ticks_, kUntouchedTraceTicks));
  attach_display(options_.display);
}

void TrialSession::attach_display(DisplayChannel* channel) {
  if (channel == nullptr) {
    display_.reset();
  } else {
    display_.emplace(renderer_.scene(), *channel);
  }
}

void TrialSession::reserve_trace() { recorder_.reserve(max_ticks_); }

ServoCommand TrialSession::step(const DeviceState& device_state) noexcept {
  // Past the time limit the trial is over (a loop that went on after `stop`): nothing is recorded, so the
  // trace stays within what reserve_trace() allocated and what kMaxTrialTicks bounds, and the force is zero.
  if (ticks_ >= max_ticks_) return ServoCommand{Vec3::Zero(), true};
  // One time base for every device: the trial's clock starts at its first tick with a finite time stamp,
  // whatever the device's clock counts from (the simulated device from open(), OpenHaptics from the
  // machine's boot).
  if (!origin_set_ && std::isfinite(device_state.time_s)) {
    device_origin_s_ = device_state.time_s;
    origin_set_ = true;
  }
  DeviceState state = device_state;
  state.time_s = origin_set_ ? device_state.time_s - device_origin_s_ : device_state.time_s;
  last_output_ = renderer_.tick(state);  // a non-finite time stamp is a rejected reading: zero force
  // The recorded clock never runs backwards nor leaves the numbers: a device clock that stepped back, or a
  // garbled (non-finite) stamp, is recorded at the previous tick's time, so that the trace stays one the
  // trace readers take (times that do not decrease, all finite) and the metrics' times are not negative.
  if (!(state.time_s >= last_time_s_) || !std::isfinite(state.time_s)) state.time_s = last_time_s_;
  recorder_.record(state, last_output_);
  ++ticks_;
  if (display_) display_->publish_tick(ticks_, state, last_output_, recorder_.metrics());
  last_time_s_ = state.time_s;
  return ServoCommand{last_output_.force_n, last_output_.finished || ticks_ >= max_ticks_};
}

TrialResult TrialSession::finish(TrialEnd end, std::string reason, double end_time_s) {
  if (spent_)
    throw StateError("TrialSession::finish: called again; a session is spent after its first finish");
  spent_ = true;
  const double trial_end_s = end_time_s < 0.0 ? last_time_s_ : end_time_s - device_origin_s_;
  recorder_.finish(trial_end_s);
  if (display_) display_->publish_end(end, trial_end_s);
  TrialResult result;
  result.metrics = recorder_.metrics();
  result.trace = recorder_.take_trace();  // the session is spent after finish
  result.end = end;
  result.aborted = end != TrialEnd::completed;
  result.abort_reason = std::move(reason);
  result.device_time_at_start_s = device_origin_s_;
  if (result.metrics.readings_rejected > 0) {
    // Such ticks look like a pen held still with no force in the trace: say so once, after the loop.
    calligraphy::detail::library_log().warn(
        "trial: {} of {} device readings were no pen (not finite, or beyond 10 m) and were rejected: zero "
        "force "
        "on those ticks, the last accepted position kept (readings_rejected)",
        result.metrics.readings_rejected, ticks_);
  }
  if (ticks_ >= 2 && last_time_s_ > 0.0) {
    result.device_tick_rate_hz = static_cast<double>(ticks_ - 1) / last_time_s_;
    const double ratio = result.device_tick_rate_hz / options_.rate_hz;
    if (ticks_ >= 100 && (ratio < 0.9 || ratio > 1.1)) {
      calligraphy::detail::library_log().warn("{}", tick_rate_warning(result.device_tick_rate_hz));
    }
  }
  return result;
}

std::string TrialSession::tick_rate_warning(double measured_hz) const {
  const std::string measured = detail::measured_rate_text(measured_hz);
  const std::string asked = detail::rate_text(options_.rate_hz);
  constexpr const char* kSlow = "time-based parts of the force law (fades, filters, a replay) ran slow";
  // Load makes a loop keep fewer ticks than it is asked for, never more. On a loop that checked the rates at
  // start, fewer is timing; on the application's own loop, its rate is its promise, which may be wrong.
  if (measured_hz < options_.rate_hz && rate_checked_) {
    return "trial: the servo loop kept " + measured + " of the " + asked +
           " asked, by the device's clock: its ticks were late (load on the machine, a loop thread without "
           "real-time priority), the rates were set equal; " +
           kSlow;
  }
  if (measured_hz < options_.rate_hz) {
    return "trial: the ticks came at " + measured + " by the device's clock, not the " + asked +
           " of TrialOptions::rate_hz: late ticks (load on the machine) if the loop that steps the session "
           "runs at that rate, else a loop at another rate (step the session once per period); " +
           kSlow;
  }
  return "trial: the ticks came at " + measured + " by the device's clock, faster than the " + asked +
         " of TrialOptions::rate_hz: step the session once per period of TrialOptions::rate_hz; time-based "
         "parts of the force law (fades, filters, a replay) ran fast";
}

ServoCommand TrialSession::ServoTick::operator()(const DeviceState& state, double /*dt_s*/) const noexcept {
  session->rate_checked_ = true;  // a ServoLoop calls this only after start() checked the rates
  return session->step(state);
}

}  // namespace calligraphy
