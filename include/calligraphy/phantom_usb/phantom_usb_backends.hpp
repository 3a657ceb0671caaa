#pragma once
/// \file phantom_usb_backends.hpp
/// The Phantom (Touch) over USB, package `calligraphy::phantom_usb`: its own target because it links hidapi
/// and libusb-1.0, which an application that never talks to a USB arm should not depend on.
///   "phantom-hid:<path>"          each HID device with the Touch's reported USB ids (built with hidapi)
///   "phantom-usb:<bus>-<address>" each such device over libusb bulk transfers (built with libusb-1.0)
/// A transport that was not found at build time still registers, and its survey says so.
#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy {

/// Adds the "phantom-hid" and "phantom-usb" backends to `registry`. Throws InvalidArgument when a backend
/// of either name is already there.
void register_phantom_usb_backends(DeviceRegistry& registry);

}  // namespace calligraphy
