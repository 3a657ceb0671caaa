#include "calligraphy/trial/whole_trial.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <variant>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// The force law's default stiffnesses capped at the device's stable maximum (the Phantom Omni's 700 N/m
// against the paper's K_en = 800 N/m); a stiffness set on purpose is kept, and the renderer warns about it.
void fit_default_stiffness(ForceLawParameters& force, const DeviceInfo& device) {
  const double limit = device.max_stiffness_n_per_m;
  if (!(limit > 0.0)) return;  // 0: the device states no limit
  const ForceLawParameters defaults;
  if (force.paper_stiffness_n_per_m == defaults.paper_stiffness_n_per_m) {
    force.paper_stiffness_n_per_m = std::min(force.paper_stiffness_n_per_m, limit);
  }
  if (force.guidance_stiffness_n_per_m == defaults.guidance_stiffness_n_per_m) {
    force.guidance_stiffness_n_per_m = std::min(force.guidance_stiffness_n_per_m, limit);
  }
}

// The specification's mode with the parameters it sets; a replay's teacher is the runner's to add.
GuidanceLaw guidance_law_of(const TrialSpec& spec) {
  switch (spec.guidance_mode) {
    case GuidanceMode::fixed:
      break;
    case GuidanceMode::fading:
      return FadingGuidance{.gain = spec.guidance_gain};
    case GuidanceMode::replay:
      return ReplayGuidance{};
    case GuidanceMode::assist_as_needed:
      return AssistAsNeededGuidance{.band_m = spec.assist_band_m};
    case GuidanceMode::error_amplification:
      return ErrorAmplificationGuidance{.gain = spec.amplification_gain};
    case GuidanceMode::timing:
      return TimingGuidance{.speed_m_s = spec.timing_speed_m_s};
  }
  return FixedGuidance{};
}

// Runs `check` (a part's validate()) and names the part `name` when it refuses.
template <typename Check>
void part(const char* name, Check&& check) {
  try {
    check();
  } catch (const InvalidArgument& e) {
    std::string message(name);
    message.append(": ").append(e.what());
    throw InvalidArgument(message);
  }
}

std::string guidance_name(bool guidance, GuidanceMode mode) {
  return guidance ? std::string(to_string(mode)) : std::string("off");
}

}  // namespace

ForceLawParameters stated_force_law(const TrialSpec& spec, const DeviceInfo& device) {
  ForceLawParameters force;
  force.guidance = spec.guidance;
  force.guidance_law = guidance_law_of(spec);
  force.guidance_stiffness_n_per_m = spec.guidance_stiffness_n_per_m;
  fit_default_stiffness(force, device);
  force.acceptance = spec.acceptance;  // checked with the specification (its table's ranges and rules)
  return force;
}

void WholeTrial::validate() const {
  // A replay's teacher comes from the file the specification names, or as samples when it names none.
  part("trial", [&] { spec.validate(spec.teacher.empty() ? TeacherSource::samples : TeacherSource::file); });
  part("force_law", [&] {
    // The teacher is not held here (the runner is given it, and checks it then): a replay's own values are
    // checked with a stand-in trajectory of two samples.
    ForceLawParameters check = force_law;
    if (auto* replay = std::get_if<ReplayGuidance>(&check.guidance_law))
      replay->teacher_trajectory = {TeacherSample{0.0, Vec3::Zero()}, TeacherSample{1.0, Vec3::Zero()}};
    check.validate();
    const GuidanceMode mode = mode_of(force_law.guidance_law);
    if (force_law.guidance != spec.guidance || (spec.guidance && mode != spec.guidance_mode)) {
      std::string message = "its guidance (";
      message.append(guidance_name(force_law.guidance, mode))
          .append(") is not the specification's (")
          .append(guidance_name(spec.guidance, spec.guidance_mode))
          .append(")");
      throw InvalidArgument(message);
    }
    if (!(force_law.acceptance == spec.acceptance))
      throw InvalidArgument("its acceptance is not the specification's (acceptance)");
  });
  part("safety", [&] {
    safety.validate();
    check_low_pass_cutoff(safety.low_pass_cutoff_hz, spec.rate_hz);
  });
  part("passivity", [&] { passivity.validate(); });
  if (writer) {
    part("writer", [&] {
      if (spec.writer == TrialWriter::person)
        throw InvalidArgument("a simulated writer's profile for a trial a person writes (writer 'person')");
      writer->validate();
    });
  }
  if (simulated_device) {
    part("simulated_device", [&] {
      if (spec.device != "simulated") {
        std::string message = "simulated device physics for the device '";
        message.append(spec.device).append("' (only for 'simulated')");
        throw InvalidArgument(message);
      }
      simulated_device->validate();
    });
  }
}

Checked<WholeTrial> build_whole_trial(const Checked<TrialSpec>& spec, const DeviceInfo& device,
                                      WholeTrialParts parts) {
  WholeTrial whole;
  whole.spec = *spec;
  whole.force_law = parts.force_law ? std::move(*parts.force_law) : stated_force_law(*spec, device);
  // The specification states the acceptance the trial runs with: a given force law's (a study condition's
  // quiz) replaces the one stated.
  whole.spec.acceptance = whole.force_law.acceptance;
  if (auto* replay = std::get_if<ReplayGuidance>(&whole.force_law.guidance_law))
    replay->teacher_trajectory.clear();  // the runner's input (TrialRunInputs::teacher)
  if (parts.safety) whole.safety = *parts.safety;
  if (parts.passivity) whole.passivity = *parts.passivity;
  whole.writer = std::move(parts.writer);
  whole.simulated_device = std::move(parts.simulated_device);
  return Checked<WholeTrial>::check(std::move(whole));
}

}  // namespace calligraphy
