#include "calligraphy/devices/device_registry.hpp"

#include <algorithm>
#include <optional>
#include <ostream>
#include <utility>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

bool DeviceSurvey::any_hardware() const {
  return std::any_of(devices.begin(), devices.end(), [](const DeviceListing& d) { return d.capabilities.hardware; });
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
                                    std::function<std::unique_ptr<HapticDevice>()> factory,
                                    DeviceCapabilities capabilities, std::string details) {
  if (!factory) throw InvalidArgument("device '" + name + "': the factory must be set");
  DeviceListing listing{name, name, std::move(info), capabilities, std::move(details)};
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

DeviceRegistry::DeviceRegistry(DeviceRegistry&& other) noexcept {
  const std::lock_guard lock(other.mutex_);
  backends_ = std::move(other.backends_);
}

DeviceRegistry& DeviceRegistry::operator=(DeviceRegistry&& other) noexcept {
  if (this == &other) return *this;
  const std::scoped_lock lock(mutex_, other.mutex_);
  backends_ = std::move(other.backends_);
  return *this;
}

bool DeviceRegistry::register_backend_if_absent(DeviceBackend backend) { return add_if_absent(std::move(backend)); }

void DeviceRegistry::register_backend(DeviceBackend backend) {
  const std::string name = backend.name;
  if (!add_if_absent(std::move(backend))) {
    throw InvalidArgument("device backend '" + name + "' is already registered");
  }
}

void DeviceRegistry::register_device(std::string name, DeviceInfo info,
                                     std::function<std::unique_ptr<HapticDevice>()> factory,
                                     DeviceCapabilities capabilities, std::string details) {
  register_backend(single_device_backend(std::move(name), std::move(info), std::move(factory), capabilities,
                                         std::move(details)));
}

bool DeviceRegistry::register_device_if_absent(std::string name, DeviceInfo info,
                                               std::function<std::unique_ptr<HapticDevice>()> factory,
                                               DeviceCapabilities capabilities, std::string details) {
  return add_if_absent(single_device_backend(std::move(name), std::move(info), std::move(factory), capabilities,
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

namespace {

// True when `backend` names its devices so that `name` is one of them: "<backend>" or "<backend>:<id>".
bool names_device(const DeviceBackend& backend, std::string_view name) {
  return name == backend.name ||
         (name.size() > backend.name.size() && name.substr(0, backend.name.size()) == backend.name &&
          name[backend.name.size()] == ':');
}

std::optional<DeviceListing> listed(DeviceSurvey& survey, const DeviceBackend& backend,
                                    std::string_view name) {
  for (auto& device : survey.devices) {
    if (device.name != name) continue;
    device.backend = backend.name;
    return std::move(device);
  }
  return std::nullopt;
}

}  // namespace

DeviceRegistry::Found DeviceRegistry::find_with_backend(std::string_view name) const {
  const std::vector<DeviceBackend> backends = snapshot();
  // Only the backend that makes devices of this name is scanned: opening the simulated device must not
  // load a driver library or touch USB devices.
  for (const auto& backend : backends) {
    if (!names_device(backend, name)) continue;
    DeviceSurvey survey = scan_one(backend);  // a backend that throws gives its reason as a note
    if (auto device = listed(survey, backend, name)) return {std::move(*device), backend};
    std::string why;
    for (const auto& note : survey.notes) why += (why.empty() ? "" : "; ") + note;
    throw DeviceUnavailable("device '" + std::string(name) + "' cannot be used now: " +
                            (why.empty() ? "its backend '" + backend.name + "' found no such device" : why) +
                            " (`calligraphy devices` lists what each backend finds)");
  }
  // Backends that name their devices otherwise: every one is asked.
  std::string available;
  for (const auto& backend : backends) {
    DeviceSurvey survey = scan_one(backend);
    if (auto device = listed(survey, backend, name)) return {std::move(*device), backend};
    for (const auto& device : survey.devices) available += (available.empty() ? "" : ", ") + device.name;
  }
  throw DeviceNotFound("no haptic device named '" + std::string(name) +
                       "'; available: " + (available.empty() ? "none" : available));
}

DeviceListing DeviceRegistry::find(std::string_view name) const { return find_with_backend(name).listing; }

std::unique_ptr<HapticDevice> DeviceRegistry::create(std::string_view name) const {
  const Found found = find_with_backend(name);
  auto created = found.backend.create(found.listing);
  if (!created) throw DeviceError("device '" + found.listing.name + "': the backend returned no device");
  // The listing is what callers decide by (a simulated writer or a person); it must say what the device is.
  const bool hand_port = created->hand_port() != nullptr;
  if (hand_port != found.listing.capabilities.moved_by_simulated_hand) {
    throw InvalidArgument("device '" + found.listing.name + "': its listing says it is " +
                          (hand_port ? "not " : "") + "moved by a simulated hand, but the device has " +
                          (hand_port ? "a hand port" : "none") +
                          "; register it with DeviceCapabilities::moved_by_simulated_hand = " +
                          (hand_port ? "true" : "false"));
  }
  return created;
}

std::unique_ptr<HapticDevice> DeviceRegistry::open(std::string_view name) const {
  auto device = create(name);
  device->open();
  return device;
}

void print_device_survey(std::ostream& out, const DeviceSurvey& survey) {
  for (const auto& device : survey.devices) {
    const auto& info = device.info;
    out << device.name << (device.capabilities.hardware ? "" : "  (not hardware)") << '\n'
        << "  model:              " << info.model << " (" << info.manufacturer << ")\n";
    if (!device.limits_known) {
      out << "  limits:             read from the device when it is opened\n";
    } else {
      out << "  max force:          " << info.max_force_n << " N (continuous " << info.max_continuous_force_n
          << " N)\n"
          << "  max stiffness:      " << info.max_stiffness_n_per_m << " N/m\n"
          << "  max damping:        " << info.max_damping_n_s_per_m << " N s/m\n"
          << "  workspace:          radius " << info.workspace_radius_m << " m, box "
          << info.workspace_size_m.x() << " x " << info.workspace_size_m.y() << " x "
          << info.workspace_size_m.z() << " m\n";
    }
    if (!device.details.empty()) out << "  details:            " << device.details << '\n';
  }
  if (!survey.any_hardware()) {
    out << "No haptic hardware attached." << (survey.devices.empty() ? " No devices available at all." : "")
        << '\n';
  }
  for (const auto& note : survey.notes) out << "note: " << note << '\n';
}

}  // namespace calligraphy
