#pragma once
// ByteTransport over libusb bulk transfers. Built only when pkg-config finds libusb-1.0.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "devices/byte_transport.hpp"

struct libusb_context;
struct libusb_device_handle;

namespace calligraphy::phantom {

/// A USB device found by enumeration.
struct UsbDeviceEntry {
  std::uint8_t bus = 0;
  std::uint8_t address = 0;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
};

/// USB devices with the Touch's reported ids. Throws CommunicationError when libusb cannot start.
[[nodiscard]] std::vector<UsbDeviceEntry> find_usb_phantoms();

class LibusbTransport final : public devices::ByteTransport {
 public:
  explicit LibusbTransport(UsbDeviceEntry entry);
  ~LibusbTransport() override;

  /// Opens the device at its bus and address, detaches a kernel driver (e.g. cdc_acm) and claims the
  /// first interface that has a bulk IN and a bulk OUT endpoint. Throws DeviceNotFound when the device
  /// is gone, access is denied (udev rules) or no such interface exists; CommunicationError otherwise.
  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override { return handle_ != nullptr; }
  /// One bulk OUT transfer. `link_lost` when unplugged, on timeout or a short write; `not_open` when
  /// closed. Note: libusb's synchronous API allocates a transfer internally on every call (the one
  /// allocation on this path that is not ours: the asynchronous API with preallocated transfers would
  /// remove it).
  [[nodiscard]] DeviceFault write(std::span<const std::uint8_t> packet,
                                  std::chrono::microseconds timeout) noexcept override;
  /// One bulk IN transfer; `received` 0 on timeout, buffer.size() for a packet longer than `buffer`.
  /// `link_lost` when unplugged or on any other libusb error.
  [[nodiscard]] DeviceFault read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                 std::size_t& received) noexcept override;
  [[nodiscard]] std::string description() const override;

 private:
  UsbDeviceEntry entry_;
  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int interface_number_ = -1;
  std::uint8_t endpoint_in_ = 0;
  std::uint8_t endpoint_out_ = 0;
  std::array<std::uint8_t, 64> out_buffer_{};  // libusb takes a non-const buffer; preallocated
};

}  // namespace calligraphy::phantom
