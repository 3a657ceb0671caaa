// Registers "openhaptics": listed when libHD.so loads and the default device initialises.
#include <memory>

#include "calligraphy/core/errors.hpp"
#include "devices/openhaptics/hd_errors.hpp"
#include "devices/openhaptics/hd_library.hpp"
#include "devices/openhaptics/openhaptics_device.hpp"
#include "devices/standard_backends.hpp"

namespace calligraphy::openhaptics {
namespace {

DeviceSurvey scan() {
  std::shared_ptr<const HdLibrary> library;
  try {
    library = HdLibrary::load();
  } catch (const DeviceError& e) {  // not found, or a damaged CALLIGRAPHY_LIBHD
    return DeviceSurvey{{}, {std::string("openhaptics: ") + e.what()}};
  }
  // Like CHAI3D: initialise the default device to learn whether one is there and what it can do (the
  // probe in load() did so first in a process of its own, so a driver that crashes there is named).
  const hd::HHD handle = library->init_device(nullptr);
  if (const hd::HDErrorInfo error = library->get_error(); error.errorCode != hd::HD_SUCCESS) {
    return DeviceSurvey{
        {},
        {"openhaptics: " + library->path + " loaded, but hdInitDevice(default device) failed with " +
         hd_error_name(error.errorCode) + ": " + hd_init_advice(error.errorCode)}};
  }
  library->disable_device(handle);
  DeviceListing listing;
  listing.name = "openhaptics";
  listing.capabilities = DeviceCapabilities{.hardware = true, .needs_calibration = true};
  listing.info.model = "OpenHaptics default device";
  listing.info.manufacturer = "see info() after open()";
  listing.limits_known = false;
  listing.details =
      "via " + library->path +
      "; the force is computed in the HD scheduler's own frame; tested against a stand-in libHD "
      "written from the public HDAPI reference, not against a real arm";
  return DeviceSurvey{{listing}, {}};
}

}  // namespace

void register_backend(DeviceRegistry& registry) {
  registry.register_backend_if_absent(
      {"openhaptics", scan, [](const DeviceListing&) { return std::make_unique<OpenHapticsDevice>(); }});
}

}  // namespace calligraphy::openhaptics
