#pragma once
/// \file byte_transport.hpp
/// A packet link to a device: one call moves one HID report or one USB bulk transfer. Implementations:
/// `InMemoryTransport` (tests, emulator), and in the Phantom backend the hidapi and libusb transports.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "calligraphy/core/device_fault.hpp"

namespace calligraphy::devices {

/// Abstract, message-oriented byte transport. Not thread-safe: one thread (the servo thread) uses it
/// once it is open.
class ByteTransport {
 public:
  virtual ~ByteTransport() = default;
  ByteTransport() = default;
  ByteTransport(const ByteTransport&) = delete;
  ByteTransport& operator=(const ByteTransport&) = delete;

  /// Connects to the device. Throws DeviceNotFound when it is not attached (or cannot be opened, e.g.
  /// for lack of permission: the message says which), CommunicationError when it answers wrongly.
  virtual void open() = 0;
  /// Releases the device. Never throws.
  virtual void close() noexcept = 0;
  [[nodiscard]] virtual bool is_open() const noexcept = 0;

  /// Sends one packet. Servo path: never throws, allocates or builds a string. Returns
  /// `DeviceFault::none`; `not_open` when the transport is closed; `link_lost` when the device is gone
  /// (unplugged), or the packet is refused or not accepted within `timeout`.
  [[nodiscard]] virtual DeviceFault write(std::span<const std::uint8_t> packet,
                                          std::chrono::microseconds timeout) noexcept = 0;

  /// Receives one packet into `buffer` and sets `received` to its length in bytes; 0 when nothing
  /// arrived within `timeout` (not a fault). A packet longer than `buffer` is cut to `buffer.size()`, so
  /// pass a buffer longer than the expected packet to detect over-long packets. Servo path: never
  /// throws, allocates or builds a string. Returns `DeviceFault::none`; `not_open` when the transport is
  /// closed; `link_lost` when the device is gone (unplugged) or the transfer failed (`received` is 0).
  [[nodiscard]] virtual DeviceFault read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                         std::size_t& received) noexcept = 0;

  /// Human-readable description for logs, e.g. "hidraw /dev/hidraw3 (2988:0301)". Not servo path.
  [[nodiscard]] virtual std::string description() const = 0;
};

}  // namespace calligraphy::devices
