#pragma once
/// \file in_memory_transport.hpp
/// A transport that hands packets directly to an in-process peer (a device emulator), for tests.
/// Synchronous and single-threaded: `write` delivers the packet to the peer at once and `read` asks
/// the peer for its next packet, so a test is deterministic and needs no sleeping.

#include <memory>

#include "devices/byte_transport.hpp"

namespace calligraphy::devices {

/// The device side of an `InMemoryTransport`.
class InMemoryPeer {
 public:
  virtual ~InMemoryPeer() = default;
  /// False once the peer has been unplugged; the transport then returns `DeviceFault::link_lost`.
  [[nodiscard]] virtual bool connected() const noexcept = 0;
  /// The device receives one packet from the host.
  virtual void receive_from_host(std::span<const std::uint8_t> packet) noexcept = 0;
  /// The device produces its next packet into `buffer` and returns its length; 0 means "nothing to
  /// send" (the host sees a read timeout).
  virtual std::size_t send_to_host(std::span<std::uint8_t> buffer) noexcept = 0;
};

/// Host side of an in-memory link. Throws InvalidArgument when `peer` is null.
class InMemoryTransport final : public ByteTransport {
 public:
  explicit InMemoryTransport(std::shared_ptr<InMemoryPeer> peer);

  /// Throws DeviceNotFound when the peer is already unplugged.
  void open() override;
  void close() noexcept override;
  [[nodiscard]] bool is_open() const noexcept override;
  /// `link_lost` when the peer was unplugged, `not_open` when closed. `timeout` is ignored.
  [[nodiscard]] DeviceFault write(std::span<const std::uint8_t> packet,
                                  std::chrono::microseconds timeout) noexcept override;
  /// `link_lost` when the peer was unplugged, `not_open` when closed. `timeout` is ignored.
  [[nodiscard]] DeviceFault read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout,
                                 std::size_t& received) noexcept override;
  [[nodiscard]] std::string description() const override;

 private:
  [[nodiscard]] DeviceFault usable() const noexcept;

  std::shared_ptr<InMemoryPeer> peer_;
  bool open_ = false;
};

}  // namespace calligraphy::devices
