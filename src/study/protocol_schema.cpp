// The schemas of a protocol's parts (schema.hpp): each range is the trial's, the force law's or the guidance
// law's own where the protocol's value becomes one of theirs, so that a protocol a trial would refuse is
// refused when it is read, naming its file and JSON pointer.
#include <array>

#include "calligraphy/core/servo_rate.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy {

const Schema& SchemaOf<ProtocolTrialSettings>::get() {
  using T = ProtocolTrialSettings;
  // TrialSpec's range of the same value: a session's trials are TrialSpecs.
  static const std::array fields{
      number_field<&T::max_duration_s>("max_duration_s",
                                       SchemaOf<TrialSpec>::get().field("max_duration_s")->range,
                                       {.unit = "s", .doc = "every trial ends after this much device time"}),
      // A protocol's trials may run in real time with a person: the real-time range.
      number_field<&T::rate_hz>("rate_hz", {.low = kMinServoRateHz, .high = kMaxRealTimeServoRateHz},
                                {.unit = "Hz", .doc = "servo rate of every trial (real-time range)"}),
  };
  static const Schema schema{.name = "ProtocolTrialSettings",
                             .doc = "settings of every trial of the study",
                             .fields = fields,
                             .defaults = default_of<T>};
  return schema;
}

const Schema& SchemaOf<BreakRules>::get() {
  using B = BreakRules;
  static const std::array fields{
      number_field<&B::between_blocks_s>("between_blocks_s", {.low = 0.0, .high = 86400.0},
                                         {.unit = "s", .doc = "rest before every block after the first"}),
      integer_field<&B::every_trials>("every_trials", 0, 100000,
                                      {.doc = "a rest of duration_s after every this many trials; 0: none"}),
      number_field<&B::duration_s>("duration_s", {.low = 0.0, .high = 86400.0},
                                   {.unit = "s", .doc = "the rest taken every every_trials trials"}),
  };
  static const Schema schema{.name = "BreakRules",
                             .doc = "rests between trials (taken by a person; a simulated writer logs them)",
                             .fields = fields,
                             .defaults = default_of<B>};
  return schema;
}

ParameterRange protocol_max_lead_range() noexcept {
  ParameterRange range = parameter_field(&ReplayGuidance::max_lead_m).range;
  const double radius = ForceLawParameters{}.constraint_radius_m;
  if (radius < range.high) {
    range.high = radius;
    range.high_open = false;
  }
  return range;
}

}  // namespace calligraphy
