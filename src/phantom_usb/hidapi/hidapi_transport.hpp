#pragma once
// ByteTransport over hidapi (one HID report per packet). Built only when pkg-config finds hidapi.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "devices/byte_transport.hpp"

struct hid_device_;

namespace calligraphy::phantom {

/// A HID device found by enumeration.
struct HidDeviceEntry {
  std::string path;  ///< OS path, e.g. /dev/hidraw3; what HidapiTransport opens
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string product;  ///< product string (ASCII part), may be empty
  std::string serial;   ///< serial number (ASCII part), may be empty
};

/// HID devices with the Touch's reported ids. Throws CommunicationError when hidapi cannot start.
[[nodiscard]] std::vector<HidDeviceEntry> find_hid_phantoms();

class HidapiTransport final : public devices::ByteTransport {
 public:
  explicit HidapiTransport(HidDeviceEntry entry);
  ~HidapiTransport() override;

  /// Throws DeviceNotFound when the path cannot be opened (unplugged, or no permission: udev rules).
  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return device_ != nullptr; }
  /// Sends the packet as an output report with report id 0. hidapi's write has no timeout: `timeout`
  /// is not enforced (hidraw writes return at once unless the kernel queue is full). `link_lost` on
  /// failure (e.g. unplugged) or when the packet exceeds 64 bytes; `not_open` when closed.
  [[nodiscard]] DeviceFault write(std::span<const std::uint8_t> packet,
                                  std::chrono::microseconds timeout) noexcept override;
  /// One input report, `received` 0 on timeout. `link_lost` on failure (e.g. unplugged).
  [[nodiscard]] DeviceFault read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                 std::size_t& received) noexcept override;
  [[nodiscard]] std::string description() const override;

 private:
  HidDeviceEntry entry_;
  hid_device_* device_ = nullptr;
  std::array<std::uint8_t, 65> report_{};  // report id + 64 bytes, preallocated for the servo path
};

}  // namespace calligraphy::phantom
