// render: the force law (include/calligraphy/render/force_law.hpp, paper section 5, eqs. 7-9) and the
// interaction states (interaction_state.hpp, paper section 2.3).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_law.hpp"
#include "calligraphy/render/interaction_state.hpp"
#include "calligraphy/render/renderer.hpp"
#include "log_forwarding.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {
namespace {

void bind_guidance(py::module_& m) {
  py::enum_<GuidanceMode>(m, "GuidanceMode", "How F_et attracts (docs/force-rendering.md, Guidance modes).")
      .value("fixed", GuidanceMode::fixed, "eq. (8): the paper's fixed virtual fixture")
      .value("fading", GuidanceMode::fading,
             "eq. (8) scaled by FadingGuidance.gain (Marchal-Crespo & Reinkensmeyer)")
      .value(
          "replay", GuidanceMode::replay,
          "the attraction point follows a teacher's recording in time (Henmi & Yoshikawa 1998; Feygin et al. "
          "2002)")
      .value("assist_as_needed", GuidanceMode::assist_as_needed,
             "eq. (8) on the deviation beyond AssistAsNeededGuidance.band_m only (Emken, Bobrow & "
             "Reinkensmeyer 2005)")
      .value("error_amplification", GuidanceMode::error_amplification,
             "a bounded repulsive field, ErrorAmplificationGuidance.gain x eq. (8) turned round (Patton et "
             "al. 2006)")
      .value(
          "timing", GuidanceMode::timing,
          "a minimum-jerk target along the stroke at TimingGuidance.speed_m_s, pulling along the stroke only "
          "(Flash & Hogan 1985)");
  py::class_<TeacherSample>(m, "TeacherSample", "One sample of a teacher's recorded pen.")
      .def(py::init([](double time_s, const py::object& position_m) {
             return TeacherSample{time_s, as_vec3(position_m, "position_m")};
           }),
           py::kw_only(), py::arg("time_s"), py::arg("position_m"),
           "time_s [s]; position_m, 3 floats, the pen in the device frame [m]")
      .def_readonly("time_s", &TeacherSample::time_s, "time [s]")
      .def_property_readonly(
          "position_m", [](const TeacherSample& t) { return read_only(to_array(t.position_m)); },
          "(3,) float64, the pen in the device frame [m]")
      .def("__repr__", [](const TeacherSample& t) {
        return "TeacherSample(time_s=" + std::to_string(t.time_s) + ", position_m=[" +
               std::to_string(t.position_m.x()) + ", " + std::to_string(t.position_m.y()) + ", " +
               std::to_string(t.position_m.z()) + "])";
      });
  ParameterClass<FadingRule>(
      m, "FadingRule",
      "The performance-based fading rule g(n+1) = clamp(f g(n) + k e(n), 0, 1) of next_guidance_gain: the "
      "error-based controller with a forgetting factor of Emken, Benitez & Reinkensmeyer 2007 (J NeuroEng "
      "Rehabil 4:8), applied once per repetition.",
      [](const FadingRule& rule) { rule.validate(); })
      .field(&FadingRule::forgetting_factor)
      .field(&FadingRule::error_gain_per_m)
      .finish();
  m.def(
      "next_guidance_gain",
      [](const PyArgument<double>& gain, const PyArgument<double>& error_m,
         const std::optional<PyArgument<FadingRule>>& rule) {
        return next_guidance_gain(take(gain, "gain"), take(error_m, "error_m"),
                                  rule ? take(*rule, "rule") : FadingRule{});
      },
      py::arg("gain"), py::arg("error_m"), py::arg("rule") = py::none(),
      R"(The fading guidance gain of the next repetition (include/calligraphy/render/guidance_mode.hpp):
clamp(f gain + k error_m, 0, 1) with f, k of `rule` (a FadingRule, default f = 0.8, k = 200 1/m; Emken,
Benitez & Reinkensmeyer 2007). gain: this repetition's gain in [0, 1]; error_m: its error [m] >= 0, for
example the trial's mean deviation (metrics['mean_deviation_m']). Returns a float in [0, 1].
Raises InvalidArgument (a ValueError) for a gain outside [0, 1], a negative or non-finite error or a bad
rule; TypeError naming the argument for a value of the wrong type.)");
  ParameterClass<AssistBandRule>(
      m, "AssistBandRule",
      "The assist-as-needed band rule b(n+1) = clamp(b(n) + k (e* - e(n)), b_min, b_max) of "
      "next_assist_band: "
      "an error below the target widens the band (less help), above it narrows it (Emken, Bobrow & "
      "Reinkensmeyer 2005; Banala et al. 2009).",
      [](const AssistBandRule& rule) { rule.validate(); })
      .field(&AssistBandRule::target_error_m)
      .field(&AssistBandRule::rate)
      .field(&AssistBandRule::min_band_m)
      .field(&AssistBandRule::max_band_m)
      .finish();
  m.def(
      "next_assist_band",
      [](const PyArgument<double>& band_m, const PyArgument<double>& error_m,
         const std::optional<PyArgument<AssistBandRule>>& rule) {
        return next_assist_band(take(band_m, "band_m"), take(error_m, "error_m"),
                                rule ? take(*rule, "rule") : AssistBandRule{});
      },
      py::arg("band_m"), py::arg("error_m"), py::arg("rule") = py::none(),
      R"(The assist-as-needed band [m] of the next repetition (include/calligraphy/render/guidance_mode.hpp)
from this repetition's band_m >= 0 and error_m >= 0 [m] (e.g. the mean deviation) under `rule` (an
AssistBandRule). Returns a float in [min_band_m, max_band_m]. Raises InvalidArgument (a ValueError) for a
negative or non-finite band or error or a bad rule.)");
  ParameterClass<SkillAdaptiveRule>(
      m, "SkillAdaptiveRule",
      "Skill-adaptive selection (Milot et al. 2010): fixed guidance at or above threshold_m of error, error "
      "amplification below.",
      [](const SkillAdaptiveRule& rule) { rule.validate(); })
      .field(&SkillAdaptiveRule::threshold_m)
      .finish();
  m.def(
      "skill_adaptive_mode",
      [](double previous_error_m, const std::optional<PyArgument<SkillAdaptiveRule>>& rule) {
        return skill_adaptive_mode(previous_error_m, rule ? take(*rule, "rule") : SkillAdaptiveRule{});
      },
      py::arg("previous_error_m"), py::arg("rule") = py::none(),
      R"(The GuidanceMode of the next repetition from the previous one's error [m] (NaN: nothing written):
GuidanceMode.fixed at or above rule.threshold_m, else GuidanceMode.error_amplification (Milot et al. 2010).
Raises InvalidArgument (a ValueError) for a negative error or a bad rule.)");
}

// A single law is checked as far as it can be alone: a moving target's lead against the constraint radius,
// and a replay's teacher once it has one, are ForceLawParameters.validate()'s.
void validate_alone(const GuidanceLaw& law) {
  GuidanceLaw probe = law;
  if (auto* replay = std::get_if<ReplayGuidance>(&probe); replay && replay->teacher_trajectory.empty())
    replay->teacher_trajectory = {TeacherSample{}, TeacherSample{}};
  validate_guidance_law(probe, std::numeric_limits<double>::infinity());
}

void bind_guidance_laws(py::module_& m) {
  const auto check = [](const auto& law) { validate_alone(law); };
  ParameterClass<FixedGuidance>(m, "FixedGuidance",
                                "The fixed guidance law: the paper's virtual fixture, eq. (8); no parameter.",
                                check)
      .finish();
  ParameterClass<FadingGuidance>(
      m, "FadingGuidance", "The fading guidance law: eq. (8) scaled by a gain (next_guidance_gain).", check)
      .field(&FadingGuidance::gain)
      .finish();
  ParameterClass<ReplayGuidance>(
      m, "ReplayGuidance",
      "The replay guidance law: the attraction point follows a teacher's recorded pen in time.", check)
      .field(&ReplayGuidance::max_lead_m)
      .finish()
      // Not a ParameterClass field (a list, not a value): not in to_dict() or the constructor.
      .def_property(
          "teacher_trajectory", [](const ReplayGuidance& g) { return g.teacher_trajectory; },
          [](ReplayGuidance& g, const std::vector<TeacherSample>& samples) {
            ReplayGuidance copy = g;
            copy.teacher_trajectory = samples;
            validate_alone(copy);
            g = std::move(copy);
          },
          "The teacher's recorded pen, a list of TeacherSample in the device frame [m]");
  ParameterClass<AssistAsNeededGuidance>(
      m, "AssistAsNeededGuidance",
      "The assist-as-needed guidance law: eq. (8) on the deviation beyond a band only (next_assist_band).",
      check)
      .field(&AssistAsNeededGuidance::band_m)
      .finish();
  ParameterClass<ErrorAmplificationGuidance>(
      m, "ErrorAmplificationGuidance",
      "The error-amplification guidance law: a bounded repulsive field, gain x eq. (8) turned round.", check)
      .field(&ErrorAmplificationGuidance::gain)
      .field(&ErrorAmplificationGuidance::max_force_n)
      .finish();
  ParameterClass<TimingGuidance>(
      m, "TimingGuidance",
      "The timing guidance law: a minimum-jerk target along the stroke, pulled towards along it only.", check)
      .field(&TimingGuidance::speed_m_s)
      .field(&TimingGuidance::max_lead_m)
      .finish();
  m.def(
      "default_guidance_law",
      [](const PyArgument<GuidanceMode>& mode) {
        return std::visit([](const auto& law) { return py::cast(law); },
                          default_guidance_law(take(mode, "mode")));
      },
      py::arg("mode"),
      "The guidance law of `mode` (a GuidanceMode or its name) with its default parameters.");
}

void bind_force_law_parameters(py::module_& m) {
  ParameterClass<ForceLawParameters>(
      m, "ForceLawParameters",
      "Parameters of the force model of paper section 5 (F_e = F_en + F_et, eq. 7), SI units as named. "
      "The paper plane is z = paper_z_m, +z out of the paper. The smoothing fields (section 6) and "
      "friction are described in docs/force-rendering.md.",
      [](const ForceLawParameters& p) { p.validate(); })
      .field(&ForceLawParameters::guidance_stiffness_n_per_m)
      .field(&ForceLawParameters::paper_stiffness_n_per_m)
      .field(&ForceLawParameters::constraint_radius_m)
      .field(&ForceLawParameters::resistance_damping_n_s_per_m)
      .field(&ForceLawParameters::contact_hysteresis_m)
      .field("guidance", &ForceLawParameters::guidance,
             "in-plane guidance on (F_et and the resistance force); the paper force is always rendered")
      .variant_field("guidance_law", &ForceLawParameters::guidance_law,
                     "how F_et acts, with the mode's own parameters (FixedGuidance as eq. 8, "
                     "FadingGuidance, ReplayGuidance, AssistAsNeededGuidance, ErrorAmplificationGuidance, "
                     "TimingGuidance)")
      .field(&ForceLawParameters::off_stroke_force_n)
      .field(&ForceLawParameters::off_stroke_travel_m)
      .field(&ForceLawParameters::off_stroke_damping_n_s_per_m)
      .field(&ForceLawParameters::off_stroke_speed_m_s)
      .field(&ForceLawParameters::off_stroke_velocity_cutoff_hz)
      .field(&ForceLawParameters::constraint_taper_m)
      .field(&ForceLawParameters::crossfade_s)
      .field(&ForceLawParameters::paper_fade_s)
      .field("acceptance", &ForceLawParameters::acceptance,
             "StrokeAcceptance: when a corner counts as gone round and a stroke as written")
      .field(&ForceLawParameters::paper_damping_n_s_per_m)
      .field(&ForceLawParameters::max_foot_speed_m_s)
      .field(&ForceLawParameters::friction_coefficient)
      .field(&ForceLawParameters::friction_stick_speed_m_s)
      .field("nearest", &ForceLawParameters::nearest,
             "NearestPointOptions: how the foot point X_S on curve elements is found")
      .finish()
      .def_property_readonly(
          "guidance_mode", [](const ForceLawParameters& p) { return mode_of(p.guidance_law); },
          "The GuidanceMode of guidance_law.");
}

double number(const PyArgument<double>& value, const char* name) { return take(value, name); }

struct FloatOrArrayTag {
  static constexpr auto name = py::detail::const_name("Union[float, numpy.ndarray[numpy.float64]]");
};

void bind_force_functions(py::module_& m) {
  m.def(
      "paper_force",
      [](const ArrayLike& z_object, const PyArgument<double>& paper_z, const PyArgument<double>& stiffness) {
        const Scalars z = as_scalars(z_object.object, "tip_z_m");
        const double z0 = number(paper_z, "paper_z_m");
        const double k = number(stiffness, "stiffness_n_per_m");
        auto out = z.single ? new_array({3}) : new_array({z.count, 3});
        double* o = out.mutable_data();
        for (py::ssize_t i = 0; i < z.count; ++i) {
          const Vec3 f = paper_force(z.array.data()[i], z0, k);
          for (int c = 0; c < 3; ++c) o[i * 3 + c] = f[c];
        }
        return out;
      },
      py::arg("tip_z_m"), py::arg("paper_z_m"), py::arg("stiffness_n_per_m"),
      "Eq. (9), pushing out of the paper: K_en (z0 - z) e_z when the tip is below the paper plane z0, "
      "else 0 [N]. tip_z_m: a number -> (3,), shape (N,) -> (N, 3), float64 [m]; paper_z_m z0 [m]; "
      "stiffness_n_per_m K_en [N/m].");
  m.def(
      "attraction_force",
      [](const ArrayLike& tip_object, const ArrayLike& foot_object, const PyArgument<double>& stiffness,
         const PyArgument<double>& factor) {
        const Vectors tip = as_vectors(tip_object.object, 2, "tip_m");
        const Vectors foot = as_vectors(foot_object.object, 2, "foot_m");
        check_broadcast(tip, foot, "tip_m", "foot_m");
        const double k = number(stiffness, "stiffness_n_per_m");
        const double a = number(factor, "attraction_factor");
        return map_rows<2>(tip, [&](py::ssize_t i) {
          return attraction_force(tip.vec2(i), foot.vec2(foot.single ? 0 : i), k, a);
        });
      },
      py::arg("tip_m"), py::arg("foot_m"), py::arg("stiffness_n_per_m"), py::arg("attraction_factor") = 1.0,
      "Eq. (8) with the attracting sign: K_et a (X_S - X_p) [N], in the paper plane. tip_m (2,) or (N, 2) "
      "[m]; foot_m, the foot point X_S, the same shape or (2,) [m]; returns the tip's shape, float64.");
  m.def(
      "resistance_force",
      [](const ArrayLike& v_object, const ArrayLike& tangent_object, const PyArgument<double>& damping) {
        const Vectors v = as_vectors(v_object.object, 2, "velocity_m_s");
        const Vectors tangent = as_vectors(tangent_object.object, 2, "tangent");
        check_broadcast(v, tangent, "velocity_m_s", "tangent");
        const double b = number(damping, "damping_n_s_per_m");
        return map_rows<2>(v, [&](py::ssize_t i) {
          return resistance_force(v.vec2(i), tangent.vec2(tangent.single ? 0 : i), b);
        });
      },
      py::arg("velocity_m_s"), py::arg("tangent"), py::arg("damping_n_s_per_m"),
      "Resistance against writing backwards (section 2.2, Fig. 4): -b (v.t) t when v.t < 0, else 0 [N]. "
      "velocity_m_s (2,) or (N, 2) [m/s]; tangent the unit writing direction, the same shape or (2,); "
      "returns the velocity's shape, float64.");
  m.def(
      "friction_force",
      [](const ArrayLike& v_object, const ArrayLike& normal_object, const PyArgument<double>& coefficient,
         const PyArgument<double>& stick_speed) {
        const Vectors v = as_vectors(v_object.object, 2, "velocity_m_s");
        const Scalars normal = as_scalars(normal_object.object, "normal_force_n");
        if (!normal.single && normal.count != v.count) {
          throw InvalidArgument("normal_force_n: expected a number or as many as velocity_m_s (" +
                                std::to_string(v.count) + "), got " + std::to_string(normal.count));
        }
        const double mu = number(coefficient, "coefficient");
        const double band = number(stick_speed, "stick_speed_m_s");
        return map_rows<2>(v, [&](py::ssize_t i) {
          return friction_force(v.vec2(i), normal.array.data()[normal.single ? 0 : i], mu, band);
        });
      },
      py::arg("velocity_m_s"), py::arg("normal_force_n"), py::arg("coefficient"), py::arg("stick_speed_m_s"),
      "Paper friction, Coulomb with a stick band: -mu N v / |v| when |v| > v_band, else -mu N v / v_band "
      "[N], in the paper plane. velocity_m_s (2,) or (N, 2) [m/s]; normal_force_n N >= 0, a number or "
      "(N,) [N]; returns the velocity's shape, float64.");
  m.def(
      "constraint_taper",
      [](const ArrayLike& d_object, const PyArgument<double>& radius,
         const PyArgument<double>& band) -> Annotated<FloatOrArrayTag> {
        const Scalars d = as_scalars(d_object.object, "distance_m");
        const double r = number(radius, "radius_m");
        const double w = number(band, "band_m");
        if (d.single) return {py::float_(constraint_taper(*d.array.data(), r, w))};
        auto out = new_array({d.count});
        for (py::ssize_t i = 0; i < d.count; ++i)
          out.mutable_at(i) = constraint_taper(d.array.data()[i], r, w);
        return {out};
      },
      py::arg("distance_m"), py::arg("radius_m"), py::arg("band_m"),
      "Taper of F_et at the constraint-space edge, in [0, 1]: 1 up to radius_m - band_m, 0 from radius_m, "
      "a smoothstep between (lengths [m]). distance_m: a number -> float, (N,) -> (N,) float64.");
  m.def(
      "clamp_force",
      [](const ArrayLike& force_object, const PyArgument<double>& max_force) {
        const Vectors f = as_vectors(force_object.object, 3, "force_n");
        const double limit = number(max_force, "max_force_n");
        return map_rows<3>(f, [&](py::ssize_t i) { return clamp_force(f.vec3(i), limit); });
      },
      py::arg("force_n"), py::arg("max_force_n"),
      "Scales each force (3,) or (N, 3) [N] down to at most max_force_n [N], keeping its direction; a "
      "non-finite force gives zero. Returns the input's shape, float64.");
}

py::object state_equals(InteractionState a, const py::object& b) {
  if (py::isinstance<InteractionState>(b)) return py::bool_(a == b.cast<InteractionState>());
  if (PyIndex_Check(b.ptr()) && !PyBool_Check(b.ptr())) {
    return py::int_(static_cast<int>(a))
        .attr("__eq__")(py::reinterpret_steal<py::object>(PyNumber_Index(b.ptr())));
  }
  return py::reinterpret_borrow<py::object>(Py_NotImplemented);
}

void bind_interaction_state(py::module_& m) {
  py::enum_<InteractionState> states(
      m, "InteractionState", py::arithmetic(),
      "Interaction state of the virtual pen tip and the paper (paper section 2.3, "
      "Tables 1-2, Fig. 6). Its int value is what TrialResult.state stores.");
  states.value("separation", InteractionState::separation, "SS: not touching the paper; zero force")
      .value("adjusting", InteractionState::adjusting,
             "AS: touching, outside the active character's bounding box; zero force")
      .value("calibration", InteractionState::calibration,
             "CS: touching, inside the box, not at the active stroke's start; normal force only")
      .value("writing", InteractionState::writing,
             "WS: touching, entered at the start neighbourhood, writing; normal and in-plane forces")
      .def_property_readonly(
          "short_name", [](InteractionState s) { return std::string(to_string(s)); },
          "the paper's abbreviation: 'SS', 'AS', 'CS' or 'WS'");
  // Replaced, not overloaded: pybind11's own comparisons would answer first.
  for (const char* name : {"__eq__", "__ne__", "__hash__"}) py::delattr(states, name);
  states
      // Equal to its int value too, so that `result.state == InteractionState.writing` compares a numpy
      // array elementwise (a scoped enum's binding compares equal only to its own type).
      .def(
          "__eq__", [](InteractionState a, const py::object& b) { return Comparison{state_equals(a, b)}; },
          py::is_operator())
      .def(
          "__ne__",
          [](InteractionState a, const py::object& b) -> Comparison {
            const py::object equal = state_equals(a, b);
            if (equal.is(py::reinterpret_borrow<py::object>(Py_NotImplemented))) return {equal};
            return {py::bool_(!equal.cast<bool>())};
          },
          py::is_operator())
      .def("__hash__", [](InteractionState a) { return static_cast<int>(a); });
}

std::vector<std::string> limit_names(std::uint8_t limits) {
  static const std::pair<std::uint8_t, const char*> names[] = {
      {safety_non_finite, "non_finite"}, {safety_low_pass, "low_pass"},
      {safety_continuous, "continuous"}, {safety_peak, "peak"},
      {safety_start_ramp, "start_ramp"}, {safety_rate, "rate"}};
  std::vector<std::string> out;
  for (const auto& [bit, name] : names) {
    if ((limits & bit) != 0) out.emplace_back(name);
  }
  return out;
}

void bind_renderer(py::module_& m) {
  ParameterClass<SafetyChainParameters>(
      m, "SafetyChainParameters",
      "The safety chain between the force law and the device (paper section 6: force steps as a source of "
      "instability), applied each tick: non-finite check, low-pass, continuous-force limit, peak clamp, "
      "start ramp, per-tick change limit (include/calligraphy/render/safety_chain.hpp). A stage set to 0 is "
      "off; max_force_n and max_continuous_force_n left at 0 take the device's figures.",
      [](const SafetyChainParameters& p) { p.validate(); })
      .field(&SafetyChainParameters::max_force_n)
      .field(&SafetyChainParameters::max_continuous_force_n)
      .field(&SafetyChainParameters::continuous_time_constant_s)
      .field(&SafetyChainParameters::start_ramp_n_per_s)
      .field(&SafetyChainParameters::max_force_change_n_per_tick)
      .field(&SafetyChainParameters::low_pass_cutoff_hz)
      .finish();

  ParameterClass<PassivityParameters>(
      m, "PassivityParameters",
      "The time-domain passivity observer and controller of Hannaford & Ryu (2002): a variable damper "
      "dissipates the energy the rendered force has produced (include/calligraphy/render/passivity.hpp).",
      [](const PassivityParameters& p) { p.validate(); })
      .field("enabled", &PassivityParameters::enabled, "observer and controller on")
      .field(&PassivityParameters::max_damping_n_s_per_m)
      .field(&PassivityParameters::min_speed_m_s)
      .finish();

  ParameterClass<RendererOptions>(m, "RendererOptions",
                                  "How a Renderer is run: the servo rate and the stages after the force law "
                                  "(include/calligraphy/render/renderer.hpp).",
                                  [](const RendererOptions& o) {
                                    o.validate();
                                    o.safety.validate();
                                  })
      .field("rate_hz", &RendererOptions::rate_hz, "servo rate [Hz], in [100, 100000]")
      .field("safety", &RendererOptions::safety, "SafetyChainParameters")
      .field("passivity", &RendererOptions::passivity, "PassivityParameters (off by default)")
      .finish();

  py::class_<RenderOutput>(m, "RenderOutput", "Everything one Renderer.tick decided.")
      .def_property_readonly(
          "force_n", [](const RenderOutput& o) { return read_only(to_array(o.force_n)); },
          "(3,) float64, the command for the device [N]: finite, within the safety chain's limits")
      .def_readonly("state", &RenderOutput::state, "the InteractionState after this tick")
      .def_readonly("state_changed", &RenderOutput::state_changed, "the state changed this tick")
      .def_readonly("character", &RenderOutput::character, "active character index (valid unless finished)")
      .def_readonly("stroke", &RenderOutput::stroke, "active stroke index within the character")
      .def_readonly("element", &RenderOutput::element, "active element index within the stroke")
      .def_readonly("finished", &RenderOutput::finished, "every stroke of the scene has been written")
      .def_readonly("in_constraint_space", &RenderOutput::in_constraint_space,
                    "the tip is inside R_res of the active element")
      .def_property_readonly(
          "foot_m", [](const RenderOutput& o) { return read_only(to_array(o.foot_m)); },
          "(2,) float64, the foot point X_S on the active element (WS only) [m]")
      .def_readonly("stroke_completed", &RenderOutput::stroke_completed,
                    "this tick wrote the last feature point of a stroke")
      .def_readonly("stroke_abandoned", &RenderOutput::stroke_abandoned,
                    "the pen was lifted in WS: the stroke was reloaded")
      .def_readonly("stroke_assisted", &RenderOutput::stroke_assisted,
                    "the abandoned stroke was refused assist_after_misses times: credited as assisted, the "
                    "next stroke is active")
      .def_readonly("missed_off_start", &RenderOutput::missed_off_start,
                    "the pen was lifted from a pen-down that never entered WS, counted as a miss "
                    "(StrokeAcceptance.miss_min_path_m)")
      .def_readonly("misses", &RenderOutput::misses, "refused attempts at the active stroke")
      .def_readonly("hint_shown", &RenderOutput::hint_shown,
                    "the active stroke is to be shown as a hint (misses >= hint_after_misses)")
      .def_readonly("input_rejected", &RenderOutput::input_rejected,
                    "the device state was not finite: zero force")
      .def_readonly("force_error", &RenderOutput::force_error,
                    "the force law gave a non-finite force: zero force")
      .def_readonly("limits", &RenderOutput::limits, "bits of the safety stages that acted (see limit_names)")
      .def_property_readonly(
          "limit_names", [](const RenderOutput& o) { return limit_names(o.limits); },
          "list of str: the safety stages that acted, of 'non_finite', 'low_pass', 'continuous', 'peak', "
          "'start_ramp', 'rate'")
      .def_readonly("passivity_damping_n_s_per_m", &RenderOutput::passivity_damping_n_s_per_m,
                    "damper added by the passivity controller [N s/m]")
      .def("__repr__", [](const RenderOutput& o) {
        return std::string("<RenderOutput ") + to_string(o.state) +
               " |F| = " + std::to_string(o.force_n.norm()) + " N, stroke " + std::to_string(o.stroke) +
               " element " + std::to_string(o.element) + ">";
      });

  py::class_<Renderer>(
      m, "Renderer",
      "The per-tick haptic renderer (paper section 4, Fig. 15): a DeviceState in, a force out. Call tick "
      "once per servo tick at options.rate_hz from your own loop. Pipeline per tick: state machine "
      "(Fig. 6) -> collision with the active element (section 4.3) -> force law (eqs. 7-9) with the "
      "smoothing of section 6 and paper friction -> optional passivity controller -> safety chain. Not "
      "thread-safe; keeps its Scene alive.")
      .def(
          py::init([](const PyArgument<Scene>& scene,
                      const std::optional<PyArgument<ForceLawParameters>>& force_law,
                      const std::optional<PyArgument<DeviceInfo>>& device,
                      const std::optional<PyArgument<RendererOptions>>& options) {
            if (!py::isinstance<Scene>(scene.object)) throw_type_error("scene", "Scene", scene.object);
            return std::make_unique<Renderer>(
                scene.object.cast<const Scene&>(),
                force_law ? take(*force_law, "force_law") : ForceLawParameters{},
                device ? take(*device, "device") : SimulatedDevice{}.info(),
                options ? take(*options, "options") : RendererOptions{});
          }),
          py::arg("scene"), py::arg("force_law") = py::none(), py::arg("device") = py::none(),
          py::arg("options") = py::none(), py::keep_alive<1, 2>(), py::call_guard<ForwardLog>(),
          "scene: the Scene to render. force_law: ForceLawParameters (default the C++ defaults). device: the "
          "DeviceInfo whose limits the safety chain takes and whose intrinsic damping sets the passivity "
          "bound (default the simulated Phantom Desktop's as SimulatedDevice().info reports it, with its "
          "own damping, 0.5 N s/m). options: RendererOptions. Raises InvalidArgument (a ValueError) for "
          "values out of range or a device with max_force_n <= 0; logs a warning when a stiffness exceeds "
          "the device's stable maximum or Colgate's bound 2 (b - B) / T.")
      .def(
          "tick",
          [](Renderer& r, const PyArgument<DeviceState>& state) { return r.tick(take(state, "state")); },
          py::arg("state"),
          "One servo tick: the DeviceState read from the device (SI units) -> RenderOutput. Never raises "
          "for any state values: a non-finite state gives zero force (input_rejected).")
      .def("reset", &Renderer::reset, "Back to the first stroke, state SS; the safety chain's ramp restarts.")
      .def_property_readonly("state", &Renderer::state, "the current InteractionState")
      .def_property_readonly("parameters", &Renderer::parameters, "its ForceLawParameters (a copy)")
      .def_property_readonly("options", &Renderer::options, "its RendererOptions (a copy)")
      .def_property_readonly(
          "scene", [](const Renderer& r) -> const Scene& { return r.scene(); },
          py::return_value_policy::reference_internal, "the Scene it renders");
}

}  // namespace

void bind_render(py::module_& m) {
  bind_guidance(m);
  bind_guidance_laws(m);
  bind_force_law_parameters(m);
  bind_force_functions(m);
  bind_interaction_state(m);
  bind_renderer(m);
}

}  // namespace calligraphy::python
