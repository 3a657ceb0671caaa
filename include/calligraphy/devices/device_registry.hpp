#pragma once
/// \file device_registry.hpp
/// Discovery of haptic devices: backends register factories; the registry lists every device they find
/// (name and DeviceInfo) and creates one by name.
///
/// A registry is a value its owner fills and passes to whatever opens devices by name (the trial runner's
/// `TrialRunInputs::registry`, the session runner's): there is no process-wide registry to register into.
/// `register_standard_device_backends` adds the backends of this module:
///   "simulated"          the simulated device (simulated_device.hpp), moved by a simulated hand
///   "openhaptics"        the default OpenHaptics device when libHD.so loads at run time (dlopen)
/// Other backends live in their own packages and add themselves to a registry they are given:
///   "phantom-hid:<path>", "phantom-usb:<bus>-<address>": `calligraphy::phantom_usb`
///     (calligraphy/phantom_usb/phantom_usb_backends.hpp; links hidapi and libusb)
///   "emulated-phantom": `calligraphy::testing` (calligraphy/testing/emulated_phantom.hpp)
/// Nothing here is on the servo path.

#include <functional>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy {

/// What a listed device is, so that nobody has to create one to find out.
struct DeviceCapabilities {
  bool hardware = false;  ///< a physical device (false for simulated and emulated ones)
  /// A simulated hand moves it and its time passes only when told to (`HapticDevice::hand_port()` is
  /// not null): trials on it run lock-step with a simulated writer.
  bool moved_by_simulated_hand = false;
  /// Its encoders must be homed (`HapticDevice::calibrate()`, e.g. a Phantom's stylus in the inkwell)
  /// before forces can be enabled.
  bool needs_calibration = false;
  bool operator==(const DeviceCapabilities&) const = default;
};

/// One device a backend can create.
struct DeviceListing {
  std::string name;                 ///< unique, what `create` takes, e.g. "phantom-hid:/dev/hidraw3"
  std::string backend;              ///< the backend that found it
  DeviceInfo info;                  ///< SI units
  DeviceCapabilities capabilities;  ///< hardware, moved by a simulated hand, needs calibration
  std::string details;              ///< free text for people: transport, caveats
  /// False when `info`'s limits are read from the device only when it is opened (OpenHaptics): they are
  /// zero here, and listings say so instead of printing them.
  bool limits_known = true;
};

/// What a scan of the backends found, plus notes on what was checked and not found.
struct DeviceSurvey {
  std::vector<DeviceListing> devices;
  std::vector<std::string> notes;  ///< e.g. "openhaptics: OpenHaptics not found (tried ...)"
  [[nodiscard]] bool any_hardware() const;
};

/// A source of devices. A backend names its devices as itself ("simulated") or "<backend>:<id>"
/// ("phantom-hid:/dev/hidraw3"), so that opening one device scans only its backend. `scan` may be slow (USB
/// enumeration, dlopen) and may throw DeviceError, which the registry turns into a note. `create` gets a
/// listing that `scan` returned and returns an unopened device; it throws DeviceError subclasses.
struct DeviceBackend {
  std::string name;
  std::function<DeviceSurvey()> scan;
  std::function<std::unique_ptr<HapticDevice>(const DeviceListing&)> create;
};

/// Thread-safe list of backends. Movable (not while another thread uses the source), not copyable.
class DeviceRegistry {
 public:
  DeviceRegistry() = default;
  DeviceRegistry(DeviceRegistry&& other) noexcept;
  DeviceRegistry& operator=(DeviceRegistry&& other) noexcept;
  DeviceRegistry(const DeviceRegistry&) = delete;
  DeviceRegistry& operator=(const DeviceRegistry&) = delete;

  /// Adds a backend. Throws InvalidArgument when the name is empty or taken, or a function is empty.
  void register_backend(DeviceBackend backend);
  /// As register_backend, but a backend of that name already there is kept and false returned; true when
  /// this call added it. Throws InvalidArgument for an empty name or function.
  bool register_backend_if_absent(DeviceBackend backend);
  /// Adds a backend with exactly one always-present device of the same name (e.g. "simulated").
  /// Throws InvalidArgument like register_backend.
  void register_device(std::string name, DeviceInfo info,
                       std::function<std::unique_ptr<HapticDevice>()> factory,
                       DeviceCapabilities capabilities = {}, std::string details = {});
  /// As register_device, but a device of that name registered before (by another thread, say) is kept
  /// and false returned; true when this call added it. Throws InvalidArgument for an empty factory.
  bool register_device_if_absent(std::string name, DeviceInfo info,
                                 std::function<std::unique_ptr<HapticDevice>()> factory,
                                 DeviceCapabilities capabilities = {}, std::string details = {});
  /// Removes a backend; returns false when there was none of that name.
  bool unregister_backend(std::string_view name);
  [[nodiscard]] std::vector<std::string> backend_names() const;

  /// Scans every backend. A backend that throws adds a note instead of failing the survey.
  [[nodiscard]] DeviceSurvey survey() const;
  /// The listing of the device called `name`. Only the backend whose devices are named so is scanned
  /// (a device of another backend's driver is never loaded or touched); a name no backend claims asks
  /// every backend. Throws DeviceUnavailable when its backend exists but cannot give the device now (the
  /// message has the backend's reason and what to try: a driver that found no arm, a damaged library, a
  /// USB permission), DeviceNotFound when no backend has such a device (naming those that exist).
  [[nodiscard]] DeviceListing find(std::string_view name) const;
  /// Creates (does not open) the device called `name`: find(name), then the backend's factory. Throws
  /// what find() throws, or what the factory throws; InvalidArgument when the device's hand port
  /// (`HapticDevice::hand_port()`) contradicts its listing's `moved_by_simulated_hand`.
  [[nodiscard]] std::unique_ptr<HapticDevice> create(std::string_view name) const;
  /// create(name), then open(). Throws what either throws.
  [[nodiscard]] std::unique_ptr<HapticDevice> open(std::string_view name) const;

 private:
  struct Found {
    DeviceListing listing;
    DeviceBackend backend;
  };
  [[nodiscard]] Found find_with_backend(std::string_view name) const;
  [[nodiscard]] std::vector<DeviceBackend> snapshot() const;
  // Adds a checked backend under the lock; false when its name is taken.
  bool add_if_absent(DeviceBackend backend);

  mutable std::mutex mutex_;
  std::vector<DeviceBackend> backends_;
};

/// Adds this module's backends to `registry`: "simulated" (a `SimulatedDevice` with default parameters) and,
/// when built with it, "openhaptics". A backend of the same name already there is kept. Thread-safe.
void register_standard_device_backends(DeviceRegistry& registry);
/// A new registry with the standard backends (`register_standard_device_backends`).
[[nodiscard]] DeviceRegistry standard_device_registry();

/// Prints a survey for people: one block per device with its DeviceInfo in SI units, then the notes;
/// says plainly when no hardware is attached.
void print_device_survey(std::ostream& out, const DeviceSurvey& survey);

}  // namespace calligraphy
