// Registers the Phantom backends over the USB transports that were built (the emulator registers itself
// from the testing target, calligraphy/testing/emulated_phantom.hpp).
#include <cstdio>
#include <memory>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/phantom_models.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"
#include "devices/phantom/phantom_device.hpp"
#include "devices/phantom/usb_ids.hpp"
#if defined(CALLIGRAPHY_WITH_HIDAPI)
#include "phantom_usb/hidapi/hidapi_transport.hpp"
#endif
#if defined(CALLIGRAPHY_WITH_LIBUSB)
#include "phantom_usb/libusb/libusb_transport.hpp"
#endif

namespace calligraphy::phantom {
namespace {

// A physical arm whose encoders are homed in the inkwell.
[[maybe_unused]] constexpr DeviceCapabilities kPhantomCapabilities{.hardware = true, .needs_calibration = true};

[[maybe_unused]] constexpr const char* kUsbCaveat =
    "UNVERIFIED: USB id reported by users, not confirmed; the packet codec is the FireWire Omni's, the USB "
    "Touch's framing is not public; never run on hardware";

[[maybe_unused]] DeviceInfo usb_touch_info(std::uint16_t vendor, std::uint16_t product) {
  DeviceInfo info = touch_info();
  char ids[48];
  std::snprintf(ids, sizeof ids, " (USB %04x:%04x, unconfirmed)", vendor, product);
  info.model += ids;
  return info;
}

[[maybe_unused]] DeviceSurvey not_built(const char* backend, const char* library) {
  return DeviceSurvey{
      {}, {std::string(backend) + ": not built (pkg-config found no " + library + " at build time)"}};
}

[[maybe_unused]] std::unique_ptr<HapticDevice> cannot_create(const DeviceListing& listing) {
  throw DeviceNotFound("device '" + listing.name + "': its backend was not built");
}

#if defined(CALLIGRAPHY_WITH_HIDAPI)
DeviceSurvey scan_hid() {
  DeviceSurvey survey;
  for (const auto& entry : find_hid_phantoms()) {
    survey.devices.push_back(
        {"phantom-hid:" + entry.path, "", usb_touch_info(entry.vendor_id, entry.product_id), kPhantomCapabilities,
         "hidapi " + entry.path + (entry.product.empty() ? "" : ", \"" + entry.product + "\"") + "; " +
             kUsbCaveat});
  }
  if (survey.devices.empty())
    survey.notes.push_back("phantom-hid: no HID device with USB id 2988:0301 or 2988:0302");
  return survey;
}

std::unique_ptr<HapticDevice> create_hid(const DeviceListing& listing) {
  for (const auto& entry : find_hid_phantoms()) {
    if ("phantom-hid:" + entry.path != listing.name) continue;
    auto config = touch_config();
    config.info = listing.info;
    return std::make_unique<PhantomDevice>(std::make_unique<HidapiTransport>(entry), std::move(config));
  }
  throw DeviceNotFound("device '" + listing.name + "' is no longer attached");
}
#endif

#if defined(CALLIGRAPHY_WITH_LIBUSB)
std::string usb_name(const UsbDeviceEntry& entry) {
  return "phantom-usb:" + std::to_string(entry.bus) + "-" + std::to_string(entry.address);
}

DeviceSurvey scan_usb() {
  DeviceSurvey survey;
  for (const auto& entry : find_usb_phantoms()) {
    survey.devices.push_back(
        {usb_name(entry), "", usb_touch_info(entry.vendor_id, entry.product_id), kPhantomCapabilities,
         std::string("libusb bulk; the same device may also be listed as phantom-hid; ") + kUsbCaveat});
  }
  if (survey.devices.empty())
    survey.notes.push_back("phantom-usb: no USB device with id 2988:0301 or 2988:0302");
  return survey;
}

std::unique_ptr<HapticDevice> create_usb(const DeviceListing& listing) {
  for (const auto& entry : find_usb_phantoms()) {
    if (usb_name(entry) != listing.name) continue;
    auto config = touch_config();
    config.info = listing.info;
    return std::make_unique<PhantomDevice>(std::make_unique<LibusbTransport>(entry), std::move(config));
  }
  throw DeviceNotFound("device '" + listing.name + "' is no longer attached");
}
#endif

}  // namespace
}  // namespace calligraphy::phantom

namespace calligraphy {

void register_phantom_usb_backends(DeviceRegistry& registry) {
  using namespace phantom;
#if defined(CALLIGRAPHY_WITH_HIDAPI)
  registry.register_backend({"phantom-hid", scan_hid, create_hid});
#else
  registry.register_backend(
      {"phantom-hid", [] { return not_built("phantom-hid", "hidapi"); }, cannot_create});
#endif
#if defined(CALLIGRAPHY_WITH_LIBUSB)
  registry.register_backend({"phantom-usb", scan_usb, create_usb});
#else
  registry.register_backend(
      {"phantom-usb", [] { return not_built("phantom-usb", "libusb-1.0"); }, cannot_create});
#endif
}

}  // namespace calligraphy
