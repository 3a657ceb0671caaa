#include "calligraphy/render/guidance_law.hpp"

#include <array>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// A moving target's attraction point must stay within R_res of the pen: the table's range narrowed.
void check_max_lead(std::string_view law_name, double max_lead_m, double constraint_radius_m) {
  check_parameter(std::string(law_name) + ".max_lead_m (at most constraint_radius_m)", max_lead_m, "m",
                  ParameterRange{.low = 0.0, .high = constraint_radius_m, .low_open = true});
}

constexpr ParameterRange kShare{.low = 0.0, .high = 1.0};
constexpr ParameterRange kBand{.low = 0.0, .high = 0.1};
// The upper bounds are what a protocol has always accepted: a lead beyond 0.1 m (more than the 60 mm
// character box) and a pen pace beyond 1 m/s mean nothing for handwriting; a repulsive force beyond 10 N is
// three times the largest a Phantom-class device makes.
constexpr ParameterRange kLead{.low = 0.0, .high = 0.1, .low_open = true};
constexpr std::string_view kMaxLeadDoc =
    "the distance at which the pull towards the moving point saturates, at most constraint_radius_m";

constexpr std::array kFadingFields{
    ParameterField<FadingGuidance>{"gain", "", kShare, "gain g on the guiding force F_et",
                                   &FadingGuidance::gain},
};
constexpr std::array kReplayFields{
    ParameterField<ReplayGuidance>{"max_lead_m", "m", kLead, kMaxLeadDoc, &ReplayGuidance::max_lead_m},
};
constexpr std::array kAssistFields{
    ParameterField<AssistAsNeededGuidance>{"band_m", "m", kBand,
                                           "half-width of the band without force around the active element",
                                           &AssistAsNeededGuidance::band_m},
};
constexpr std::array kAmplificationFields{
    ParameterField<ErrorAmplificationGuidance>{
        "gain", "", kShare, "the repulsive stiffness as a share of K_et", &ErrorAmplificationGuidance::gain},
    ParameterField<ErrorAmplificationGuidance>{"max_force_n", "N", ParameterRange{.low = 0.0, .high = 10.0},
                                               "bound of the repulsive force",
                                               &ErrorAmplificationGuidance::max_force_n},
};
constexpr std::array kTimingFields{
    ParameterField<TimingGuidance>{"speed_m_s", "m/s",
                                   ParameterRange{.low = 0.0, .high = 1.0, .low_open = true},
                                   "mean speed of the target along each stroke", &TimingGuidance::speed_m_s},
    ParameterField<TimingGuidance>{"max_lead_m", "m", kLead, kMaxLeadDoc, &TimingGuidance::max_lead_m},
};

struct Validator {
  double constraint_radius_m;
  void operator()(const ReplayGuidance& law) const {
    validate_teacher_trajectory(law.teacher_trajectory);
    check_parameters(law);
    check_max_lead(ParameterTable<ReplayGuidance>::name, law.max_lead_m, constraint_radius_m);
  }
  void operator()(const TimingGuidance& law) const {
    check_parameters(law);
    check_max_lead(ParameterTable<TimingGuidance>::name, law.max_lead_m, constraint_radius_m);
  }
  template <typename Law>
  void operator()(const Law& law) const {
    check_parameters(law);
  }
};

}  // namespace

std::span<const ParameterField<FadingGuidance>> ParameterTable<FadingGuidance>::fields() noexcept {
  return kFadingFields;
}
std::span<const ParameterField<ReplayGuidance>> ParameterTable<ReplayGuidance>::fields() noexcept {
  return kReplayFields;
}
std::span<const ParameterField<AssistAsNeededGuidance>>
ParameterTable<AssistAsNeededGuidance>::fields() noexcept {
  return kAssistFields;
}
std::span<const ParameterField<ErrorAmplificationGuidance>>
ParameterTable<ErrorAmplificationGuidance>::fields() noexcept {
  return kAmplificationFields;
}
std::span<const ParameterField<TimingGuidance>> ParameterTable<TimingGuidance>::fields() noexcept {
  return kTimingFields;
}

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
