// core: the exception hierarchy (include/calligraphy/core/errors.hpp) and the device value types
// (device_types.hpp).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/device_types.hpp"
#include "calligraphy/core/errors.hpp"
#include "parameter_class.hpp"

namespace calligraphy::python {
namespace {

// A Python exception class `calligraphy.<name>` with the given bases, shown with the C++ message as is
// (KeyError's own __str__ would quote it).
py::object new_exception(py::module_& m, const char* name, const py::tuple& bases, const std::string& doc) {
  const std::string qualified = std::string("calligraphy.") + name;
  py::dict dict;
  dict["__doc__"] = doc;
  dict["__module__"] = "calligraphy";
  dict["__str__"] = py::module_::import("builtins").attr("BaseException").attr("__str__");
  py::object type =
      py::reinterpret_steal<py::object>(PyErr_NewException(qualified.c_str(), bases.ptr(), dict.ptr()));
  if (!type) throw py::error_already_set();
  m.attr(name) = type;
  return type;
}

struct ExceptionTypes {
  py::object error, invalid_argument, data_error, character_not_found, device_error, device_not_found,
      device_unavailable, communication_error, safety_fault, calibration_needed, realtime_error, state_error;
};

void bind_exceptions(py::module_& m) {
  // Leaked on purpose: the translator may run until the interpreter is gone.
  static auto* types = new ExceptionTypes();
  const auto builtin = [](PyObject* type) { return py::handle(type); };
  types->error = new_exception(m, "Error", py::make_tuple(builtin(PyExc_Exception)),
                               "Base of every error the library raises (C++ calligraphy::Error).");
  types->invalid_argument =
      new_exception(m, "InvalidArgument", py::make_tuple(types->error, builtin(PyExc_ValueError)),
                    "A value outside a documented precondition (C++ calligraphy::InvalidArgument); a "
                    "ValueError.");
  types->data_error = new_exception(
      m, "DataError", py::make_tuple(types->error, builtin(PyExc_RuntimeError)),
      "Character data could not be read: missing folder or file, malformed JSON or store, impossible "
      "geometry (C++ calligraphy::DataError); a RuntimeError. The message names the file and position.");
  types->character_not_found = new_exception(
      m, "CharacterNotFound", py::make_tuple(types->data_error, builtin(PyExc_KeyError)),
      "A character is not in the library asked for it (C++ calligraphy::CharacterNotFound); a KeyError "
      "and a DataError.");
  types->device_error =
      new_exception(m, "DeviceError", py::make_tuple(types->error, builtin(PyExc_RuntimeError)),
                    "Base of haptic-device faults (C++ calligraphy::DeviceError); a RuntimeError.");
  types->device_not_found = new_exception(
      m, "DeviceNotFound", py::make_tuple(types->device_error, builtin(PyExc_LookupError)),
      "No device of the requested name is attached (C++ calligraphy::DeviceNotFound); a LookupError.");
  types->device_unavailable = new_exception(
      m, "DeviceUnavailable", py::make_tuple(types->device_error),
      "A known device its backend cannot give now: the driver found no arm, a damaged driver library, a "
      "refused USB device (C++ calligraphy::DeviceUnavailable); the message has the reason and what to try.");
  types->communication_error = new_exception(
      m, "CommunicationError", py::make_tuple(types->device_error, builtin(PyExc_ConnectionError)),
      "The transport to the device failed: timeout, unplug, malformed packets (C++ "
      "calligraphy::CommunicationError); a ConnectionError.");
  types->safety_fault =
      new_exception(m, "SafetyFault", py::make_tuple(types->device_error),
                    "A safety limit tripped and forces were turned off (C++ calligraphy::SafetyFault).");
  types->calibration_needed =
      new_exception(m, "CalibrationNeeded", py::make_tuple(types->device_error),
                    "The device must be calibrated before use (C++ calligraphy::CalibrationNeeded).");

  types->realtime_error = new_exception(
      m, "RealtimeError", py::make_tuple(types->device_error),
      "Realtime settings (SCHED_FIFO, CPU pinning, locked memory) were required and could not be applied "
      "(C++ calligraphy::RealtimeError).");
  types->state_error =
      new_exception(m, "StateError", py::make_tuple(types->error, builtin(PyExc_RuntimeError)),
                    "A call in the wrong state, e.g. starting a servo loop that already runs (C++ "
                    "calligraphy::StateError); "
                    "a RuntimeError.");

  py::register_exception_translator([](std::exception_ptr p) {
    const auto raise = [](const py::object& type, const std::exception& e) {
      PyErr_SetString(type.ptr(), e.what());
    };
    try {
      if (p) std::rethrow_exception(p);
    } catch (const CharacterNotFound& e) {
      raise(types->character_not_found, e);
    } catch (const DataError& e) {
      raise(types->data_error, e);
    } catch (const InvalidArgument& e) {
      raise(types->invalid_argument, e);
    } catch (const DeviceNotFound& e) {
      raise(types->device_not_found, e);
    } catch (const DeviceUnavailable& e) {
      raise(types->device_unavailable, e);
    } catch (const CommunicationError& e) {
      raise(types->communication_error, e);
    } catch (const SafetyFault& e) {
      raise(types->safety_fault, e);
    } catch (const CalibrationNeeded& e) {
      raise(types->calibration_needed, e);
    } catch (const RealtimeError& e) {
      raise(types->realtime_error, e);
    } catch (const StateError& e) {
      raise(types->state_error, e);
    } catch (const DeviceError& e) {
      raise(types->device_error, e);
    } catch (const Error& e) {
      raise(types->error, e);
    }
  });
}

void check_device_info(const DeviceInfo& info) {
  const auto check = [](double value, const char* field) {
    if (!std::isfinite(value) || value < 0.0) {
      throw InvalidArgument(std::string("DeviceInfo.") + field + " = " + std::to_string(value) +
                            " must be finite and >= 0");
    }
  };
  check(info.max_force_n, "max_force_n");
  check(info.max_continuous_force_n, "max_continuous_force_n");
  check(info.max_stiffness_n_per_m, "max_stiffness_n_per_m");
  check(info.max_damping_n_s_per_m, "max_damping_n_s_per_m");
  check(info.intrinsic_damping_n_s_per_m, "intrinsic_damping_n_s_per_m");
  check(info.workspace_radius_m, "workspace_radius_m");
  for (Eigen::Index k = 0; k < 3; ++k) check(info.workspace_size_m[k], "workspace_size_m");
}

}  // namespace

void bind_core(py::module_& m) {
  bind_exceptions(m);
  // The project's version (CMake's PROJECT_VERSION), as the C++ library it was built from.
  m.attr("__version__") = CALLIGRAPHY_VERSION;

  ParameterClass<DeviceInfo>(m, "DeviceInfo",
                             "What a haptic device can do, in SI units (after CHAI3D's cHapticDeviceInfo). "
                             "A renderer needs max_force_n > 0.",
                             check_device_info)
      .field("model", &DeviceInfo::model, "e.g. 'Phantom Desktop (simulated)'")
      .field("manufacturer", &DeviceInfo::manufacturer, "e.g. 'calligraphy'")
      .field("max_force_n", &DeviceInfo::max_force_n, "peak force [N]")
      .field("max_continuous_force_n", &DeviceInfo::max_continuous_force_n,
             "force sustainable for minutes [N]")
      .field("max_stiffness_n_per_m", &DeviceInfo::max_stiffness_n_per_m,
             "highest stable stiffness at 1 kHz [N/m]")
      .field("max_damping_n_s_per_m", &DeviceInfo::max_damping_n_s_per_m, "highest stable damping [N s/m]")
      .field(
          "intrinsic_damping_n_s_per_m", &DeviceInfo::intrinsic_damping_n_s_per_m,
          "the device's own physical damping b for Colgate's bound K <= 2 (b - B) / T [N s/m]; 0 = unknown")
      .field("workspace_radius_m", &DeviceInfo::workspace_radius_m,
             "radius of a sphere inside the workspace [m]")
      .field("workspace_size_m", &DeviceInfo::workspace_size_m, "box of the usable workspace, x y z [m].")
      .finish();

  ParameterClass<DeviceState>(
      m, "DeviceState",
      "A snapshot of the device as read once per servo tick, SI units. Device frame: x right, y away "
      "from the writer, z up out of the paper. Any value is accepted (a renderer rejects non-finite "
      "states by commanding zero force).",
      [](const DeviceState&) {})
      .field("position_m", &DeviceState::position_m, "tip (HIP) position [m].")
      .field("velocity_m_s", &DeviceState::velocity_m_s, "tip velocity [m/s].")
      .field("buttons", &DeviceState::buttons, "bit i set when button i is pressed")
      .field("time_s", &DeviceState::time_s, "device time stamp [s], monotonic")
      .finish();

  // The one writer of a set of files (core/atomic_file.hpp, AtomicFileSet), for the Python modules that
  // write a set (study_report): the same temporaries, second names, journal and folder locks as the C++
  // commands, so a Python report is replaced whole or not at all, as theirs.
  m.def(
      "_write_files_together",
      [](const std::vector<std::pair<std::string, py::bytes>>& files) {
        std::vector<std::pair<std::string, std::string>> contents;
        contents.reserve(files.size());
        for (const auto& [path, data] : files) contents.emplace_back(path, std::string(data));
        const py::gil_scoped_release released;
        AtomicFileSet set;
        for (const auto& [path, data] : contents) set.add(path, data);
        set.commit();
      },
      py::arg("files"),
      "Writes [(path, bytes)] as one set: every file or none replaced (AtomicFileSet). Raises DataError "
      "naming the file at fault.");
}

}  // namespace calligraphy::python
