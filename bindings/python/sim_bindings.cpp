// sim: the simulated device and writer (include/calligraphy/sim/) and the device registry with the
// simulated device registered (devices/device_registry.hpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <string>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/sim/simulated_device.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "log_forwarding.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {
namespace {

// WriterProfile::validate leaves some fields unchecked (tremor frequency, infinities of the offsets);
// a non-finite value would make the writer's hand force NaN and the trial meaningless.
void check_writer(const WriterProfile& w) {
  w.validate();
  const std::pair<double, const char*> values[] = {
      {w.hand_stiffness_n_per_m, "hand_stiffness_n_per_m"},
      {w.hand_damping_n_s_per_m, "hand_damping_n_s_per_m"},
      {w.writing_speed_m_s, "writing_speed_m_s"},
      {w.travel_speed_m_s, "travel_speed_m_s"},
      {w.press_depth_m, "press_depth_m"},
      {w.lift_height_m, "lift_height_m"},
      {w.bias_offset_m, "bias_offset_m"},
      {w.scale_error, "scale_error"},
      {w.stroke_jitter_m, "stroke_jitter_m"},
      {w.noise_fraction, "noise_fraction"},
      {w.tremor_amplitude_n, "tremor_amplitude_n"},
      {w.tremor_frequency_hz, "tremor_frequency_hz"},
      {w.overshoot_m, "overshoot_m"},
      {w.correction_per_attempt, "correction_per_attempt"},
  };
  for (const auto& [value, name] : values) {
    if (!std::isfinite(value))
      throw InvalidArgument(std::string("WriterProfile.") + name + " must be finite");
  }
  if (w.tremor_frequency_hz < 0.0) throw InvalidArgument("WriterProfile.tremor_frequency_hz must be >= 0");
}

void bind_writer_profile(py::module_& m) {
  ParameterClass<WriterProfile>(
      m, "WriterProfile",
      "How a simulated writer writes (include/calligraphy/sim/simulated_writer.hpp): a hand impedance "
      "F = k (x_d - x) + b (x_d' - x') + noise + tremor holding the stylus, moving x_d with minimum-jerk "
      "timing (Flash & Hogan 1985) along a biased copy of the reference; force noise grows with the force "
      "(Harris & Wolpert 1998). Units as named. WriterProfile.novice() and .skilled() are the presets.",
      check_writer)
      .field("name", &WriterProfile::name, "a label, reported as the trial's 'writer'")
      .field("hand_stiffness_n_per_m", &WriterProfile::hand_stiffness_n_per_m,
             "k of the hand impedance [N/m], > 0")
      .field("hand_damping_n_s_per_m", &WriterProfile::hand_damping_n_s_per_m,
             "b of the hand impedance [N s/m]")
      .field("writing_speed_m_s", &WriterProfile::writing_speed_m_s,
             "mean speed along an element while writing [m/s]")
      .field("travel_speed_m_s", &WriterProfile::travel_speed_m_s, "mean speed of pen-up moves [m/s]")
      .field("press_depth_m", &WriterProfile::press_depth_m,
             "how far below the paper the hand aims while writing [m]")
      .field("lift_height_m", &WriterProfile::lift_height_m, "pen-up height above the paper [m], > 0")
      .field("bias_offset_m", &WriterProfile::bias_offset_m,
             "systematic offset of the whole character copy [m]")
      .field("scale_error", &WriterProfile::scale_error,
             "relative mis-scale of the copy about the character centre, in (-0.5, 0.5)")
      .field("stroke_jitter_m", &WriterProfile::stroke_jitter_m, "std dev of a per-stroke random offset [m]")
      .field("noise_fraction", &WriterProfile::noise_fraction,
             "signal-dependent force noise, std dev / |F_hand|")
      .field("tremor_amplitude_n", &WriterProfile::tremor_amplitude_n, "in-plane tremor force amplitude [N]")
      .field("tremor_frequency_hz", &WriterProfile::tremor_frequency_hz,
             "tremor frequency [Hz] (8-12 Hz physiological)")
      .field("overshoot_m", &WriterProfile::overshoot_m, "follow-through past each feature point [m]")
      .field("correction_per_attempt", &WriterProfile::correction_per_attempt,
             "share of the bias removed on each re-aim after a missed stroke, in [0, 1]")
      .field("max_attempts_per_stroke", &WriterProfile::max_attempts_per_stroke,
             "attempts before giving up, >= 1")
      .finish()
      .def_static(
          "novice", &WriterProfile::novice,
          "A relaxed learner with a visible bias (150 N/m, 3 N s/m: assumed grip figures, not measured).")
      .def_static("skilled", &WriterProfile::skilled,
                  "A stiffer, faster, nearly unbiased writer (600 N/m, 8 N s/m).");
}

void bind_simulated_device(py::module_& m) {
  ParameterClass<SimulatedDeviceParameters>(
      m, "SimulatedDeviceParameters",
      "Physics of the simulated device: a point mass with viscous damping, m x'' = F_hand + F_device - b x' "
      "(Colgate & Schenkel 1997), the force held for each tick and saturated at info.max_force_n, the "
      "position quantised to the encoder. Ranges are checked.",
      [](const SimulatedDeviceParameters& p) { p.validate(); })
      .field("moving_mass_kg", &SimulatedDeviceParameters::moving_mass_kg,
             "stylus, linkage and hand [kg], in [1e-4, 1e3]")
      .field("damping_n_s_per_m", &SimulatedDeviceParameters::damping_n_s_per_m,
             "viscous damping b [N s/m], in [0, 1e4]")
      .field("encoder_resolution_m", &SimulatedDeviceParameters::encoder_resolution_m,
             "position quantum [m], 0 or in [1e-9, 1e-3]")
      .field("velocity_cutoff_hz", &SimulatedDeviceParameters::velocity_cutoff_hz,
             "low-pass on the differenced velocity [Hz], in (0, 1e6]")
      .field("physics_substeps", &SimulatedDeviceParameters::physics_substeps,
             "least integration steps per advance, in [1, 10000]")
      .field("physics_rate_hz", &SimulatedDeviceParameters::physics_rate_hz,
             "least physics rate [Hz], in [1e3, 1e8]")
      .field("initial_position_m", &SimulatedDeviceParameters::initial_position_m,
             "where the stylus starts [m].")
      .field("info", &SimulatedDeviceParameters::info, "the DeviceInfo it reports (Phantom Desktop figures)")
      .finish();

  py::class_<SimulatedDevice>(m, "SimulatedDevice",
                              "A simulated Phantom Desktop (include/calligraphy/sim/simulated_device.hpp), "
                              "no hand attached: it moves only under the commanded force. Deterministic; no "
                              "wall clock.")
      .def(py::init([](const std::optional<Checked<SimulatedDeviceParameters>>& parameters) {
             auto device = std::make_unique<SimulatedDevice>(parameters ? take(*parameters, "parameters")
                                                                        : SimulatedDeviceParameters{});
             device->open();
             return device;
           }),
           py::arg("parameters") = py::none(),
           "Opened on creation. Raises InvalidArgument (a ValueError) for parameters out of range.")
      .def("read_state", &SimulatedDevice::read_state,
           "The DeviceState: position quantised to the encoder [m], low-passed velocity [m/s], time [s].")
      .def(
          "write_force",
          [](SimulatedDevice& d, const ArrayLike& force) { d.write_force(as_vec3(force.object, "force_n")); },
          py::arg("force_n"),
          "Commands a force (3,) [N], held until the next command, saturated at info.max_force_n.")
      .def(
          "advance", [](SimulatedDevice& d, const Checked<double>& dt) { d.advance(take(dt, "dt_s")); },
          py::arg("dt_s"),
          "Integrates the physics over dt_s [s] (stable for any finite dt_s >= 0; InvalidArgument "
          "otherwise).")
      .def(
          "enable_forces",
          [](SimulatedDevice& d, const Checked<bool>& on) { d.enable_forces(take(on, "enabled")); },
          py::arg("enabled"), "Forces on or off (off: the commanded force is not applied).")
      .def_property_readonly("forces_enabled", &SimulatedDevice::forces_enabled)
      .def_property_readonly("is_open", &SimulatedDevice::is_open)
      .def("close", &SimulatedDevice::close, "Forces off and closed.")
      .def("open", &SimulatedDevice::open, "Opens it again after close().")
      .def_property_readonly("info", &SimulatedDevice::info, "its DeviceInfo")
      .def_property_readonly(
          "true_position_m", [](const SimulatedDevice& d) { return to_array(d.true_position()); },
          "(3,) float64, the unquantised position [m]")
      .def_property_readonly(
          "true_velocity_m_s", [](const SimulatedDevice& d) { return to_array(d.true_velocity()); },
          "(3,) float64, the velocity [m/s]")
      .def_property_readonly(
          "applied_force_n", [](const SimulatedDevice& d) { return to_array(d.applied_force()); },
          "(3,) float64, the force applied after saturation [N]")
      .def_property_readonly("time_s", &SimulatedDevice::time, "device time [s]");
}

void bind_registry(py::module_& m) {
  py::class_<DeviceListing>(m, "DeviceListing", "One device a backend of the registry can create.")
      .def_readonly("name", &DeviceListing::name, "unique, e.g. 'simulated' or 'phantom-hid:/dev/hidraw3'")
      .def_readonly("backend", &DeviceListing::backend, "the backend that found it")
      .def_readonly("info", &DeviceListing::info, "its DeviceInfo, SI units")
      .def_readonly("hardware", &DeviceListing::hardware,
                    "a physical device (False for simulated and emulated)")
      .def_readonly("details", &DeviceListing::details, "free text: transport, caveats")
      .def("__repr__", [](const DeviceListing& d) {
        return "<DeviceListing " + d.name + " (" + d.info.model + (d.hardware ? ", hardware" : "") + ")>";
      });
  py::class_<DeviceSurvey>(m, "DeviceSurvey", "What a scan of the device backends found.")
      .def_readonly("devices", &DeviceSurvey::devices, "list of DeviceListing")
      .def_readonly("notes", &DeviceSurvey::notes, "list of str: what was checked and not found")
      .def_property_readonly("any_hardware", &DeviceSurvey::any_hardware,
                             "True when a physical device is attached")
      .def("__repr__", [](const DeviceSurvey& s) {
        std::string names;
        for (const DeviceListing& d : s.devices) names += (names.empty() ? "" : ", ") + d.name;
        return "<DeviceSurvey " + names + ">";
      });
  m.def(
      "list_devices",
      []() {
        py::gil_scoped_release release;  // a scan may enumerate USB devices and load OpenHaptics
        return device_registry_with_simulation().survey();
      },
      py::call_guard<ForwardLog>(),
      "Scans every registered backend (the simulated device, Phantoms over HID or USB, OpenHaptics) as "
      "`calligraphy devices` does (which also lists its Phantom emulator). Returns a DeviceSurvey; a backend "
      "that fails adds "
      "a note instead of raising.");
}

}  // namespace

void bind_sim(py::module_& m) {
  bind_writer_profile(m);
  bind_simulated_device(m);
  bind_registry(m);
}

}  // namespace calligraphy::python
