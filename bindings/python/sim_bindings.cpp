// sim: the simulated device and writer (include/calligraphy/sim/), labelled person-like pen paths
// (person_traces.hpp) and the device registry with the simulated device registered
// (devices/device_registry.hpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"
#include "calligraphy/sim/person_traces.hpp"
#include "calligraphy/sim/simulated_writer.hpp"
#include "log_forwarding.hpp"
#include "model_bindings.hpp"
#include "numpy_arrays.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {

const DeviceRegistry& python_device_registry() {
  // The module's one registry, as the command line has its own: built once, never changed after.
  static const DeviceRegistry registry = [] {
    DeviceRegistry built = standard_device_registry();
    register_phantom_usb_backends(built);
    return built;
  }();
  return registry;
}

namespace {

void bind_writer_profile(py::module_& m) {
  ParameterClass<WriterProfile>(
      m, "WriterProfile",
      "How a simulated writer writes (include/calligraphy/trial/writer_profile.hpp, docs/writer.md): a hand "
      "impedance "
      "F = k (x_d - x) + b (x_d' - x') + noise + tremor holding the stylus, moving x_d with minimum-jerk "
      "timing (Flash & Hogan 1985) along a biased copy of the reference; force noise grows with the force "
      "(Harris & Wolpert 1998). Units as named. WriterProfile.novice(), .skilled() and .foreign() are the "
      "presets.",
      [](const WriterProfile& w) { w.validate(); })
      .field("name", &WriterProfile::name, "a label, reported as the trial's 'writer'")
      .field(&WriterProfile::hand_stiffness_n_per_m)
      .field(&WriterProfile::hand_damping_n_s_per_m)
      .field(&WriterProfile::noise_fraction)
      .field(&WriterProfile::tremor_amplitude_n)
      .field(&WriterProfile::tremor_frequency_hz)
      .field(&WriterProfile::writing_speed_m_s)
      .field(&WriterProfile::travel_speed_m_s)
      .field(&WriterProfile::press_depth_m)
      .field(&WriterProfile::lift_height_m)
      .field(&WriterProfile::corner_cut_m)
      .field(&WriterProfile::end_short_m)
      .field(&WriterProfile::end_past_m)
      .field(&WriterProfile::follow_through_m)
      .field(&WriterProfile::bias_offset_m)
      .field(&WriterProfile::scale_error)
      .field(&WriterProfile::stroke_jitter_m)
      .field(&WriterProfile::visual_delay_s)
      .field(&WriterProfile::vision_period_s)
      .field(&WriterProfile::correction_rate_per_s)
      .field(&WriterProfile::error_tolerance_m)
      .field(&WriterProfile::steering_width_m)
      .field(&WriterProfile::min_speed_fraction)
      .field(&WriterProfile::error_filter_s)
      .field(&WriterProfile::speed_time_constant_s)
      .field(&WriterProfile::reaction_time_s)
      .field(&WriterProfile::resistance_threshold_n)
      .field(&WriterProfile::expected_drag_ratio)
      .field(&WriterProfile::correction_per_attempt)
      .field("max_attempts_per_stroke", &WriterProfile::max_attempts_per_stroke,
             "attempts at one stroke before the writer gives up, >= 1")
      .field(&WriterProfile::order_error_probability)
      .field(&WriterProfile::backwards_probability)
      .field(&WriterProfile::mid_stroke_lift_probability)
      .field(&WriterProfile::outside_touch_probability)
      .field(&WriterProfile::hesitation_probability)
      .field(&WriterProfile::hesitation_s)
      .field(&WriterProfile::learning_rate)
      .finish()
      .def_static(
          "novice", &WriterProfile::novice,
          "A relaxed learner with a visible bias (150 N/m, 3 N s/m: assumed grip figures, not measured).")
      .def_static("skilled", &WriterProfile::skilled,
                  "A stiffer, faster, nearly unbiased writer without errors.")
      .def_static("foreign", &WriterProfile::foreign,
                  "The paper's foreign student (section 7): larger bias, strokes out of order and backwards, "
                  "slower.");
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
             "where the stylus starts [m], each coordinate in [-1, 1]")
      .field("info", &SimulatedDeviceParameters::info, "the DeviceInfo it reports (Phantom Desktop figures)")
      .finish();

  py::class_<SimulatedDevice>(
      m, "SimulatedDevice",
      "A simulated Phantom Desktop (include/calligraphy/devices/simulated_device.hpp), "
      "no hand attached: it moves only under the commanded force. Deterministic; no "
      "wall clock.")
      .def(py::init([](const std::optional<PyArgument<SimulatedDeviceParameters>>& parameters) {
             auto device = std::make_unique<SimulatedDevice>(parameters ? take(*parameters, "parameters")
                                                                        : SimulatedDeviceParameters{});
             device->open();
             return device;
           }),
           py::arg("parameters") = py::none(),
           "Opened on creation. Raises InvalidArgument (a ValueError) for parameters out of range.")
      // The C++ calls return a DeviceFault code (the servo path never throws); Python raises the typed
      // exception of a fault through the library's one mapping, throw_device_fault.
      .def(
          "read_state",
          [](SimulatedDevice& d) {
            DeviceState state;
            if (const DeviceFault fault = d.read_state(state); fault != DeviceFault::none)
              throw_device_fault(fault, d.info().model);
            return state;
          },
          "The DeviceState: position quantised to the encoder [m], low-passed velocity [m/s], time [s]. "
          "A device fault raises CommunicationError (not_open once closed: the state is not read).")
      .def(
          "write_force",
          [](SimulatedDevice& d, const ArrayLike& force) {
            if (const DeviceFault fault = d.write_force(as_vec3(force.object, "force_n"));
                fault != DeviceFault::none)
              throw_device_fault(fault, d.info().model);
          },
          py::arg("force_n"),
          "Commands a force (3,) [N], held until the next command, saturated at info.max_force_n. A device "
          "fault raises CommunicationError (not_open once closed: zero force is applied).")
      .def(
          "advance", [](SimulatedDevice& d, const PyArgument<double>& dt) { d.advance(take(dt, "dt_s")); },
          py::arg("dt_s"),
          "Integrates the physics over dt_s [s] (stable for any finite dt_s >= 0; InvalidArgument "
          "otherwise).")
      .def(
          "enable_forces",
          [](SimulatedDevice& d, const PyArgument<bool>& on) { d.enable_forces(take(on, "enabled")); },
          py::arg("enabled"), "Forces on or off (off: the commanded force is not applied).")
      .def_property_readonly("forces_enabled", &SimulatedDevice::forces_enabled,
                             "True while commanded forces are applied (enable_forces; True when made)")
      .def_property_readonly("is_open", &SimulatedDevice::is_open, "True between open() and close()")
      .def("close", &SimulatedDevice::close,
           "Zero force and closed: read_state and write_force then raise CommunicationError (not_open) "
           "until open().")
      .def("open", &SimulatedDevice::open, "Opens it again after close().")
      .def_property_readonly("info", &SimulatedDevice::info, "its DeviceInfo")
      .def_property_readonly(
          "true_position_m", [](const SimulatedDevice& d) { return read_only(to_array(d.true_position())); },
          "(3,) float64, the unquantised position [m]")
      .def_property_readonly(
          "true_velocity_m_s",
          [](const SimulatedDevice& d) { return read_only(to_array(d.true_velocity())); },
          "(3,) float64, the velocity [m/s]")
      .def_property_readonly(
          "applied_force_n", [](const SimulatedDevice& d) { return read_only(to_array(d.applied_force())); },
          "(3,) float64, the force applied after saturation [N]")
      .def_property_readonly("time_s", &SimulatedDevice::time, "device time [s]");
}

void bind_registry(py::module_& m) {
  py::class_<DeviceListing>(m, "DeviceListing", "One device a backend of the registry can create.")
      .def_readonly("name", &DeviceListing::name, "unique, e.g. 'simulated' or 'phantom-hid:/dev/hidraw3'")
      .def_readonly("backend", &DeviceListing::backend, "the backend that found it")
      .def_readonly("info", &DeviceListing::info, "its DeviceInfo, SI units")
      .def_property_readonly(
          "hardware", [](const DeviceListing& d) { return d.capabilities.hardware; },
          "a physical device (False for simulated and emulated)")
      .def_property_readonly(
          "moved_by_simulated_hand",
          [](const DeviceListing& d) { return d.capabilities.moved_by_simulated_hand; },
          "a simulated hand moves it and its time passes only when advanced (a simulated writer can write on "
          "it)")
      .def_property_readonly(
          "needs_calibration", [](const DeviceListing& d) { return d.capabilities.needs_calibration; },
          "its encoders must be homed (e.g. a Phantom's stylus in the inkwell) before forces")
      .def_readonly("details", &DeviceListing::details, "free text: transport, caveats")
      .def_readonly("limits_known", &DeviceListing::limits_known,
                    "False when info's limits are read only when the device is opened (they are 0 here)")
      .def("__repr__", [](const DeviceListing& d) {
        return "<DeviceListing " + d.name + " (" + d.info.model +
               (d.capabilities.hardware ? ", hardware" : "") + ")>";
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
        return python_device_registry().survey();
      },
      py::call_guard<ForwardLog>(),
      "Scans every registered backend (the simulated device, Phantoms over HID or USB, OpenHaptics) as "
      "`calligraphy devices` does (which also lists its Phantom emulator). Returns a DeviceSurvey; a backend "
      "that fails adds "
      "a note instead of raising.");
}

void bind_person_traces(py::module_& m) {
  py::enum_<TraceKind>(m, "TraceKind",
                       "Kinds of labelled pen paths for testing stroke acceptance "
                       "(include/calligraphy/sim/person_traces.hpp, docs/stroke-acceptance.md): "
                       "positives write the stroke, negatives must be refused (is_positive).")
      .value("median", TraceKind::median, "positive: the data's median vertices as they are")
      .value("human", TraceKind::human,
             "positive: human pace: offset, turn and scale of the copy, drift, tremor, ends short or past")
      .value("corners_cut", TraceKind::corners_cut,
             "positive: as 'human', corners rounded inside by 2-5 mm of smoothing")
      .value("corners_overshot", TraceKind::corners_overshot,
             "positive: as 'human', each corner overshot outside by 1-2.5 mm before turning")
      .value("ends_short", TraceKind::ends_short,
             "positive: as 'human', lifted 0.5-3 mm short of the end (at most a fifth of the stroke)")
      .value("ends_past", TraceKind::ends_past, "positive: as 'human', carried 0.5-4 mm past the end")
      .value("pointer", TraceKind::pointer,
             "positive: a mouse: 60 Hz samples at 60-110 mm/s, wobble, 0.15 mm pixels, lifted short")
      .value("reversed", TraceKind::reversed, "negative: a 'human' path from the end to the start")
      .value("half", TraceKind::half,
             "negative: the first or the second half of the stroke, written as 'human' (ends exact)")
      .value("shifted", TraceKind::shifted,
             "negative: a 'human' path (without its own offset), every point moved 4-8 mm across it")
      .value("other_stroke", TraceKind::other_stroke,
             "negative: a 'human' path of another stroke of the character")
      .value("swapped_order", TraceKind::swapped_order,
             "negative: a 'human' path of the next stroke, written first")
      .value("scribble", TraceKind::scribble, "negative: a zig-zag from the stroke's start")
      .value("shifted_8mm", TraceKind::shifted_8mm,
             "negative: as 'shifted', every point moved exactly 8 mm across (the acceptance target's shift)");

  m.def(
      "is_positive", [](const PyArgument<TraceKind>& kind) { return is_positive(take(kind, "kind")); },
      py::arg("kind"),
      "True for the TraceKinds that write the stroke (median .. pointer), False for those a matcher must "
      "refuse. kind: a TraceKind or its name. Raises InvalidArgument (a ValueError) for an unknown name, "
      "TypeError naming `kind` for another type.");
  m.def(
      "trace_applies",
      [](const PyArgument<Scene>& scene, const PyArgument<long long>& character_index,
         const PyArgument<long long>& stroke_index, const PyArgument<TraceKind>& kind) {
        const StrokeOfScene target = stroke_of_scene(scene, character_index, stroke_index);
        return trace_applies(target.character, target.stroke, take(kind, "kind"));
      },
      py::arg("scene"), py::arg("character_index"), py::arg("stroke_index"), py::arg("kind"),
      "True when person_trace can make `kind` for this stroke: other_stroke needs a character of two "
      "strokes or more, swapped_order a next stroke. Raises IndexError naming character_index or "
      "stroke_index out of range, InvalidArgument or TypeError naming `kind`.");
  m.def(
      "person_trace",
      [](const PyArgument<Scene>& scene, const PyArgument<long long>& character_index,
         const PyArgument<long long>& stroke_index, const PyArgument<TraceKind>& kind,
         const PyArgument<std::uint64_t>& seed) {
        const StrokeOfScene target = stroke_of_scene(scene, character_index, stroke_index);
        const TraceKind chosen = take(kind, "kind");
        std::mt19937_64 random(take(seed, "seed"));
        return points_to_array(person_trace(target.character, target.stroke, chosen, random));
      },
      py::arg("scene"), py::arg("character_index"), py::arg("stroke_index"), py::arg("kind"),
      py::arg("seed") = 0,
      R"(A labelled pen-down path for stroke `stroke_index` of character `character_index` of `scene`
(include/calligraphy/sim/person_traces.hpp): what a person writing it would draw (the positive kinds),
or a mistake a matcher must refuse (the negative kinds). Built from the stroke's median_m only, never
from the fitted elements or the centre line match_stroke reads.

kind: a TraceKind or its name, e.g. 'human' or 'shifted'.
seed: int in 0..2**64-1, seeds the std::mt19937_64 the path is drawn from: the same seed gives the
      same path.
Returns an (N, 2) float64 array, points on the paper in writing order [m], for match_stroke.
Raises IndexError naming character_index or stroke_index out of range; InvalidArgument (a ValueError)
naming `kind` or `seed` for an unknown name or a seed out of range, or when the kind does not apply to
the stroke (trace_applies) or the stroke has no median (a corpus store of format 1.0); TypeError naming
the argument for a value of the wrong type.)");
}

}  // namespace

void bind_sim(py::module_& m) {
  bind_writer_profile(m);
  bind_simulated_device(m);
  bind_registry(m);
  bind_person_traces(m);
}

}  // namespace calligraphy::python
