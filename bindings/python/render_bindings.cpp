// render: the force law (include/calligraphy/render/force_law.hpp, paper section 5, eqs. 7-9) and the
// interaction states (interaction_state.hpp, paper section 2.3).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/interaction_state.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {
namespace {

void bind_force_law_parameters(py::module_& m) {
  ParameterClass<ForceLawParameters>(
      m, "ForceLawParameters",
      "Parameters of the force model of paper section 5 (F_e = F_en + F_et, eq. 7), SI units as named. "
      "The paper plane is z = paper_z_m, +z out of the paper. The smoothing fields (section 6) and "
      "friction are described in docs/force-rendering.md.",
      [](const ForceLawParameters& p) { p.validate(); })
      .field("guidance_stiffness_n_per_m", &ForceLawParameters::guidance_stiffness_n_per_m,
             "K_et per unit attraction factor (eq. 8) [N/m]")
      .field("paper_stiffness_n_per_m", &ForceLawParameters::paper_stiffness_n_per_m,
             "K_en, stiffness of the virtual paper (eq. 9) [N/m]")
      .field("constraint_radius_m", &ForceLawParameters::constraint_radius_m,
             "R_res, radius of the constraint space around the active element (section 4.3) [m], > 0")
      .field("resistance_damping_n_s_per_m", &ForceLawParameters::resistance_damping_n_s_per_m,
             "damping against writing backwards along the active element (Fig. 4) [N s/m]")
      .field("contact_hysteresis_m", &ForceLawParameters::contact_hysteresis_m,
             "height above the paper at which a touching tip counts as lifted (section 6) [m]")
      .field("guidance", &ForceLawParameters::guidance,
             "in-plane guidance on (F_et and the resistance force); the paper force is always rendered")
      .field("constraint_taper_m", &ForceLawParameters::constraint_taper_m,
             "band at R_res over which F_et tapers to zero [m], in [0, R_res]; 0 = the paper's step")
      .field("crossfade_s", &ForceLawParameters::crossfade_s,
             "cross-fade time of the in-plane force when the active element or state changes [s]; 0 = off")
      .field("paper_fade_s", &ForceLawParameters::paper_fade_s,
             "fade time of the paper force when it starts or stops pushing (AS <-> CS) [s]; 0 = off")
      .field("feature_plane_margin_m", &ForceLawParameters::feature_plane_margin_m,
             "hysteresis of the feature planes (eq. 6) [m]")
      .field("paper_damping_n_s_per_m", &ForceLawParameters::paper_damping_n_s_per_m,
             "damping of the paper on inward motion only [N s/m]; 0 = off")
      .field("max_foot_speed_m_s", &ForceLawParameters::max_foot_speed_m_s,
             "highest speed of the rendered attraction target X_S [m/s]")
      .field("friction_coefficient", &ForceLawParameters::friction_coefficient,
             "Coulomb friction coefficient mu of the paper (not in the paper), dimensionless")
      .field("friction_stick_speed_m_s", &ForceLawParameters::friction_stick_speed_m_s,
             "stick band of the friction [m/s], > 0: viscous below it")
      .field("nearest", &ForceLawParameters::nearest,
             "NearestPointOptions: how the foot point X_S on curve elements is found")
      .finish();
}

double number(const Checked<double>& value, const char* name) { return take(value, name); }

void bind_force_functions(py::module_& m) {
  m.def(
      "paper_force",
      [](const ArrayLike& z_object, const Checked<double>& paper_z, const Checked<double>& stiffness) {
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
      [](const ArrayLike& tip_object, const ArrayLike& foot_object, const Checked<double>& stiffness,
         const Checked<double>& factor) {
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
      [](const ArrayLike& v_object, const ArrayLike& tangent_object, const Checked<double>& damping) {
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
      [](const ArrayLike& v_object, const ArrayLike& normal_object, const Checked<double>& coefficient,
         const Checked<double>& stick_speed) {
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
      [](const ArrayLike& d_object, const Checked<double>& radius,
         const Checked<double>& band) -> py::object {
        const Scalars d = as_scalars(d_object.object, "distance_m");
        const double r = number(radius, "radius_m");
        const double w = number(band, "band_m");
        if (d.single) return py::float_(constraint_taper(*d.array.data(), r, w));
        auto out = new_array({d.count});
        for (py::ssize_t i = 0; i < d.count; ++i)
          out.mutable_at(i) = constraint_taper(d.array.data()[i], r, w);
        return out;
      },
      py::arg("distance_m"), py::arg("radius_m"), py::arg("band_m"),
      "Taper of F_et at the constraint-space edge, in [0, 1]: 1 up to radius_m - band_m, 0 from radius_m, "
      "a smoothstep between (lengths [m]). distance_m: a number -> float, (N,) -> (N,) float64.");
  m.def(
      "clamp_force",
      [](const ArrayLike& force_object, const Checked<double>& max_force) {
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
          "__eq__", [](InteractionState a, const py::object& b) { return state_equals(a, b); },
          py::is_operator())
      .def(
          "__ne__",
          [](InteractionState a, const py::object& b) -> py::object {
            const py::object equal = state_equals(a, b);
            if (equal.is(py::reinterpret_borrow<py::object>(Py_NotImplemented))) return equal;
            return py::bool_(!equal.cast<bool>());
          },
          py::is_operator())
      .def("__hash__", [](InteractionState a) { return static_cast<int>(a); });
}

}  // namespace

void bind_render(py::module_& m) {
  bind_force_law_parameters(m);
  bind_force_functions(m);
  bind_interaction_state(m);
}

}  // namespace calligraphy::python
