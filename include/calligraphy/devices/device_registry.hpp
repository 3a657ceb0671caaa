#pragma once
/// \file device_registry.hpp
/// Discovery of haptic devices: backends register factories; the registry lists every device they find
/// (name and DeviceInfo) and creates one by name.
///
/// Built-in backends (registered on first use of `device_registry()`, see src/devices/builtin_backends.cpp):
///   "emulated-phantom"   the Phantom emulator behind the real PhantomDevice code path (always present)
///   "phantom-hid:<path>" each HID device with the Touch's reported USB ids (when built with hidapi)
///   "phantom-usb:<bus>-<address>" each such USB device over libusb bulk transfers (when built with libusb)
///   "openhaptics"        the default OpenHaptics device when libHD.so loads at run time
/// The simulated device registers itself the same way (`register_device`, name "simulated").
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

/// One device a backend can create.
struct DeviceListing {
  std::string name;       ///< unique, what `create` takes, e.g. "phantom-hid:/dev/hidraw3"
  std::string backend;    ///< the backend that found it
  DeviceInfo info;        ///< SI units
  bool hardware = false;  ///< a physical device (false for simulated and emulated ones)
  std::string details;    ///< free text for people: transport, caveats
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

/// Thread-safe list of backends.
class DeviceRegistry {
 public:
  /// Adds a backend. Throws InvalidArgument when the name is empty or taken, or a function is empty.
  void register_backend(DeviceBackend backend);
  /// Adds a backend with exactly one always-present device of the same name (e.g. "simulated").
  /// Throws InvalidArgument like register_backend.
  void register_device(std::string name, DeviceInfo info,
                       std::function<std::unique_ptr<HapticDevice>()> factory, bool hardware = false,
                       std::string details = {});
  /// As register_device, but a device of that name registered before (by another thread, say) is kept
  /// and false returned; true when this call added it. Throws InvalidArgument for an empty factory.
  bool register_device_if_absent(std::string name, DeviceInfo info,
                                 std::function<std::unique_ptr<HapticDevice>()> factory,
                                 bool hardware = false, std::string details = {});
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
  /// what find() throws, or what the factory throws.
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

/// The process-wide registry, with the built-in backends registered on first use.
[[nodiscard]] DeviceRegistry& device_registry();
/// device_registry().register_backend(backend).
void register_device_backend(DeviceBackend backend);

/// Prints a survey for people: one block per device with its DeviceInfo in SI units, then the notes;
/// says plainly when no hardware is attached.
void print_device_survey(std::ostream& out, const DeviceSurvey& survey);

}  // namespace calligraphy
