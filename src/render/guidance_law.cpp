#include "calligraphy/render/guidance_law.hpp"

#include <cmath>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// The one range check of a guidance parameter: closed below, closed or open above.
void check_range(double value, const char* name, const char* unit, double low, double high, bool open_low) {
  const bool above_low = open_low ? value > low : value >= low;
  if (!std::isfinite(value) || !above_low || !(value <= high)) {
    throw InvalidArgument(std::string(name) + " = " + std::to_string(value) + (*unit ? " " : "") + unit +
                          " must be in " + (open_low ? "(" : "[") + std::to_string(low) + ", " +
                          (std::isinf(high) ? "inf)" : std::to_string(high) + "]"));
  }
}

constexpr double kUnbounded = INFINITY;

struct Validator {
  double constraint_radius_m;
  void operator()(const FixedGuidance&) const {}
  void operator()(const FadingGuidance& law) const {
    check_range(law.gain, "FadingGuidance.gain", "", 0.0, 1.0, false);
  }
  void operator()(const ReplayGuidance& law) const {
    validate_teacher_trajectory(law.teacher_trajectory);
    check_range(law.max_lead_m, "ReplayGuidance.max_lead_m (at most constraint_radius_m)", "m", 0.0,
                constraint_radius_m, true);
  }
  void operator()(const AssistAsNeededGuidance& law) const {
    check_range(law.band_m, "AssistAsNeededGuidance.band_m", "m", 0.0, kUnbounded, false);
  }
  void operator()(const ErrorAmplificationGuidance& law) const {
    check_range(law.gain, "ErrorAmplificationGuidance.gain", "", 0.0, 1.0, false);
    check_range(law.max_force_n, "ErrorAmplificationGuidance.max_force_n", "N", 0.0, kUnbounded, false);
  }
  void operator()(const TimingGuidance& law) const {
    check_range(law.speed_m_s, "TimingGuidance.speed_m_s", "m/s", 0.0, kUnbounded, true);
    check_range(law.max_lead_m, "TimingGuidance.max_lead_m (at most constraint_radius_m)", "m", 0.0,
                constraint_radius_m, true);
  }
};

}  // namespace

GuidanceMode mode_of(const GuidanceLaw& law) noexcept {
  // The alternatives are declared in GuidanceMode order.
  return static_cast<GuidanceMode>(law.index());
}

GuidanceLaw default_guidance_law(GuidanceMode mode) {
  switch (mode) {
    case GuidanceMode::fixed:
      break;
    case GuidanceMode::fading:
      return FadingGuidance{};
    case GuidanceMode::replay:
      return ReplayGuidance{};
    case GuidanceMode::assist_as_needed:
      return AssistAsNeededGuidance{};
    case GuidanceMode::error_amplification:
      return ErrorAmplificationGuidance{};
    case GuidanceMode::timing:
      return TimingGuidance{};
  }
  return FixedGuidance{};
}

void validate_guidance_law(const GuidanceLaw& law, double constraint_radius_m) {
  std::visit(Validator{constraint_radius_m}, law);
}

}  // namespace calligraphy
