#include "calligraphy/study/guidance_share.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

namespace {

// The share across the stroke, for guidance that is on.
double shape_share(const ForceLawParameters& force, double k, double e, bool written) {
  const double stiffness = force.guidance_stiffness_n_per_m;
  const GuidanceLaw& law = force.guidance_law;
  switch (mode_of(law)) {
    case GuidanceMode::timing:
      return 0.0;
    case GuidanceMode::fixed:
    case GuidanceMode::replay:
      return guidance_assistance_share(1.0, stiffness, k);
    case GuidanceMode::fading:
      return guidance_assistance_share(std::get<FadingGuidance>(law).gain, stiffness, k);
    case GuidanceMode::assist_as_needed: {
      // Within the band the deviation is the writer's own to correct; a trial with no stroke got all help.
      double beyond = 1.0;
      const double band_m = std::get<AssistAsNeededGuidance>(law).band_m;
      if (written) beyond = e > 0.0 ? std::max(0.0, 1.0 - band_m / e) : 0.0;
      return beyond * guidance_assistance_share(1.0, stiffness, k);
    }
    case GuidanceMode::error_amplification: {
      if (!written) return 0.0;
      const ErrorAmplificationGuidance& amplification = std::get<ErrorAmplificationGuidance>(law);
      const double repulsive = amplification.gain * stiffness;
      const double linear = repulsive < k ? k / (k - repulsive) : std::numeric_limits<double>::infinity();
      const double saturated =
          e > 0.0 ? 1.0 + amplification.max_force_n / (k * e) : std::numeric_limits<double>::infinity();
      const double factor = std::min({linear, saturated, 1.0 - kMinAssistanceShare});
      return 1.0 - factor;
    }
  }
  return 0.0;
}

}  // namespace

AssistanceShares guidance_shares(const ForceLawParameters& force, double hand_stiffness_n_per_m,
                                 double mean_deviation_m) {
  force.validate();
  const double k = hand_stiffness_n_per_m;
  if (!(k > 0.0) || !std::isfinite(k)) {
    throw InvalidArgument("guidance_shares: hand stiffness " + shortest_decimal(k) +
                          " N/m must be finite and > 0");
  }
  const double e = mean_deviation_m;
  const bool written = !std::isnan(e);
  if (written && (!(e >= 0.0) || !std::isfinite(e))) {
    throw InvalidArgument("guidance_shares: mean deviation " + shortest_decimal(e) +
                          " m must be finite and >= 0");
  }
  if (!force.guidance) return {};
  const GuidanceMode mode = mode_of(force.guidance_law);
  const bool along = mode == GuidanceMode::timing || mode == GuidanceMode::replay;
  // A guide that moves the pen along the stroke in time takes that share of the timing correction and
  // demonstrates it: the writer feels the time course done.
  const double along_share =
      along ? guidance_assistance_share(1.0, force.guidance_stiffness_n_per_m, k) : 0.0;
  return {shape_share(force, k, e, written), along_share, along_share};
}

}  // namespace calligraphy
