#include "phantom_usb/hidapi/hidapi_transport.hpp"

#include <hidapi.h>

#include <algorithm>
#include <cstdio>
#include <cwchar>
#include <mutex>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "devices/phantom/usb_ids.hpp"

namespace calligraphy::phantom {
namespace {

// hidapi reports strings as wchar_t; the ASCII part is all a log line needs.
std::string narrow(const wchar_t* text) {
  std::string out;
  if (text == nullptr) return out;
  for (; *text != L'\0'; ++text) out.push_back(*text < 128 ? static_cast<char>(*text) : '?');
  return out;
}

int hid_timeout_ms(std::chrono::microseconds timeout) noexcept {
  return static_cast<int>(std::max<std::int64_t>(1, (timeout.count() + 999) / 1000));
}

// hidapi's library state (hid_init, the enumeration, opening a path) is global and not thread-safe (hidapi's
// README: call hid_init before threads use the library); a registry may be asked from several threads at once
// (simulated cohorts, Python threads), so these calls take turns. Reads and writes on an open handle do not.
std::mutex& hidapi_library_mutex() {
  static std::mutex mutex;
  return mutex;
}

std::string hex_id(std::uint16_t vendor, std::uint16_t product) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%04x:%04x", vendor, product);
  return buffer;
}

}  // namespace

std::vector<HidDeviceEntry> find_hid_phantoms() {
  const std::lock_guard<std::mutex> lock(hidapi_library_mutex());
  if (hid_init() != 0) throw CommunicationError("hidapi: hid_init failed");
  std::vector<HidDeviceEntry> found;
  hid_device_info* list = hid_enumerate(kTouchUsbVendorId, 0);
  for (const hid_device_info* info = list; info != nullptr; info = info->next) {
    if (!is_reported_touch_id(info->vendor_id, info->product_id)) continue;
    found.push_back({info->path != nullptr ? info->path : "", info->vendor_id, info->product_id,
                     narrow(info->product_string), narrow(info->serial_number)});
  }
  hid_free_enumeration(list);
  return found;
}

HidapiTransport::HidapiTransport(HidDeviceEntry entry) : entry_(std::move(entry)) {}

HidapiTransport::~HidapiTransport() { close(); }

void HidapiTransport::open() {
  if (device_ != nullptr) return;
  const std::lock_guard<std::mutex> lock(hidapi_library_mutex());
  if (hid_init() != 0) throw CommunicationError("hidapi: hid_init failed");
  device_ = hid_open_path(entry_.path.c_str());
  if (device_ == nullptr) {
    throw DeviceNotFound("hidapi: cannot open " + entry_.path + " (" +
                         hex_id(entry_.vendor_id, entry_.product_id) +
                         "): unplugged, or no permission (a udev rule granting access to hidraw is needed)");
  }
}

void HidapiTransport::close() noexcept {
  if (device_ != nullptr) hid_close(device_);
  device_ = nullptr;
}

DeviceFault HidapiTransport::write(std::span<const std::uint8_t> packet,
                                   std::chrono::microseconds /*timeout*/) noexcept {
  // Codes, not exceptions: the servo path neither throws nor builds a string, also when it fails.
  if (device_ == nullptr) return DeviceFault::not_open;
  if (packet.size() + 1 > report_.size()) return DeviceFault::link_lost;  // longer than 64 bytes: refused
  report_[0] = 0;  // report id 0: the device uses unnumbered reports (assumption, unverified)
  std::copy(packet.begin(), packet.end(), report_.begin() + 1);
  if (hid_write(device_, report_.data(), packet.size() + 1) < 0) return DeviceFault::link_lost;  // unplugged?
  return DeviceFault::none;
}

DeviceFault HidapiTransport::read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                  std::size_t& received) noexcept {
  received = 0;
  if (device_ == nullptr) return DeviceFault::not_open;
  const int count = hid_read_timeout(device_, buffer.data(), buffer.size(), hid_timeout_ms(timeout));
  if (count < 0) return DeviceFault::link_lost;  // unplugged?
  received = static_cast<std::size_t>(count);
  return DeviceFault::none;
}

std::string HidapiTransport::description() const {
  return "hidapi " + entry_.path + " (" + hex_id(entry_.vendor_id, entry_.product_id) + ")";
}

}  // namespace calligraphy::phantom
