#include "calligraphy/devices/device_registry.hpp"

#include <algorithm>
#include <ostream>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "devices/builtin_backends.hpp"

namespace calligraphy {

bool DeviceSurvey::any_hardware() const {
  return std::any_of(devices.begin(), devices.end(), [](const DeviceListing& d) { return d.hardware; });
}

namespace {

void check_backend(const DeviceBackend& backend) {
  if (backend.name.empty()) throw InvalidArgument("device backend: the name must not be empty");
  if (!backend.scan || !backend.create) {
    throw InvalidArgument("device backend '" + backend.name + "': scan and create must both be set");
  }
}

// A backend that always lists exactly one device, named as the backend.
DeviceBackend single_device_backend(std::string name, DeviceInfo info,
                                    std::function<std::unique_ptr<HapticDevice>()> factory, bool hardware,
                                    std::string details) {
  if (!factory) throw InvalidArgument("device '" + name + "': the factory must be set");
  DeviceListing listing{name, name, std::move(info), hardware, std::move(details)};
  DeviceBackend backend;
  backend.name = std::move(name);
  backend.scan = [listing] { return DeviceSurvey{{listing}, {}}; };
  backend.create = [factory = std::move(factory)](const DeviceListing&) { return factory(); };
  return backend;
}

}  // namespace

bool DeviceRegistry::add_if_absent(DeviceBackend backend) {
  check_backend(backend);
  const std::lock_guard lock(mutex_);
  const bool taken = std::any_of(backends_.begin(), backends_.end(),
                                 [&](const DeviceBackend& b) { return b.name == backend.name; });
  if (taken) return false;
  backends_.push_back(std::move(backend));
  return true;
}

void DeviceRegistry::register_backend(DeviceBackend backend) {
  const std::string name = backend.name;
  if (!add_if_absent(std::move(backend))) {
    throw InvalidArgument("device backend '" + name + "' is already registered");
  }
}

void DeviceRegistry::register_device(std::string name, DeviceInfo info,
                                     std::function<std::unique_ptr<HapticDevice>()> factory, bool hardware,
                                     std::string details) {
  register_backend(single_device_backend(std::move(name), std::move(info), std::move(factory), hardware,
                                         std::move(details)));
}

bool DeviceRegistry::register_device_if_absent(std::string name, DeviceInfo info,
                                               std::function<std::unique_ptr<HapticDevice>()> factory,
                                               bool hardware, std::string details) {
  return add_if_absent(single_device_backend(std::move(name), std::move(info), std::move(factory), hardware,
                                             std::move(details)));
}

bool DeviceRegistry::unregister_backend(std::string_view name) {
  const std::lock_guard lock(mutex_);
  const auto it = std::find_if(backends_.begin(), backends_.end(),
                               [&](const DeviceBackend& b) { return b.name == name; });
  if (it == backends_.end()) return false;
  backends_.erase(it);
  return true;
}

std::vector<std::string> DeviceRegistry::backend_names() const {
  std::vector<std::string> names;
  for (const auto& backend : snapshot()) names.push_back(backend.name);
  return names;
}

std::vector<DeviceBackend> DeviceRegistry::snapshot() const {
  const std::lock_guard lock(mutex_);
  return backends_;  // scanning runs unlocked: backends may be slow
}

namespace {

DeviceSurvey scan_one(const DeviceBackend& backend) {
  try {
    return backend.scan();
  } catch (const Error& e) {
    return DeviceSurvey{{}, {backend.name + ": " + e.what()}};
  }
}

}  // namespace

DeviceSurvey DeviceRegistry::survey() const {
  DeviceSurvey all;
  for (const auto& backend : snapshot()) {
    auto found = scan_one(backend);
    for (auto& device : found.devices) {
      device.backend = backend.name;
      all.devices.push_back(std::move(device));
    }
    for (auto& note : found.notes) all.notes.push_back(std::move(note));
  }
  return all;
}

std::unique_ptr<HapticDevice> DeviceRegistry::create(std::string_view name) const {
  std::string available;
  for (const auto& backend : snapshot()) {
    for (const auto& device : scan_one(backend).devices) {
      if (device.name == name) {
        auto created = backend.create(device);
        if (!created) throw DeviceError("device '" + device.name + "': the backend returned no device");
        return created;
      }
      available += (available.empty() ? "" : ", ") + device.name;
    }
  }
  throw DeviceNotFound("no haptic device named '" + std::string(name) +
                       "'; available: " + (available.empty() ? "none" : available));
}

std::unique_ptr<HapticDevice> DeviceRegistry::open(std::string_view name) const {
  auto device = create(name);
  device->open();
  return device;
}

DeviceRegistry& device_registry() {
  static DeviceRegistry* const registry = [] {
    auto* created = new DeviceRegistry;  // never destroyed: backends may be used during static destruction
    register_builtin_device_backends(*created);
    return created;
  }();
  return *registry;
}

void register_device_backend(DeviceBackend backend) {
  device_registry().register_backend(std::move(backend));
}

void print_device_survey(std::ostream& out, const DeviceSurvey& survey) {
  for (const auto& device : survey.devices) {
    const auto& info = device.info;
    out << device.name << (device.hardware ? "" : "  (not hardware)") << '\n'
        << "  model:              " << info.model << " (" << info.manufacturer << ")\n"
        << "  max force:          " << info.max_force_n << " N (continuous " << info.max_continuous_force_n
        << " N)\n"
        << "  max stiffness:      " << info.max_stiffness_n_per_m << " N/m\n"
        << "  max damping:        " << info.max_damping_n_s_per_m << " N s/m\n"
        << "  workspace:          radius " << info.workspace_radius_m << " m, box "
        << info.workspace_size_m.x() << " x " << info.workspace_size_m.y() << " x "
        << info.workspace_size_m.z() << " m\n";
    if (!device.details.empty()) out << "  details:            " << device.details << '\n';
  }
  if (!survey.any_hardware()) {
    out << "No haptic hardware attached." << (survey.devices.empty() ? " No devices available at all." : "")
        << '\n';
  }
  for (const auto& note : survey.notes) out << "note: " << note << '\n';
}

}  // namespace calligraphy
