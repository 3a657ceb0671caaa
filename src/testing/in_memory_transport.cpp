#include "testing/in_memory_transport.hpp"

#include <utility>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::devices {

InMemoryTransport::InMemoryTransport(std::shared_ptr<InMemoryPeer> peer) : peer_(std::move(peer)) {
  if (!peer_) throw InvalidArgument("InMemoryTransport: the peer must not be null");
}

void InMemoryTransport::open() {
  if (!peer_->connected()) throw DeviceNotFound("in-memory transport: the peer is unplugged");
  open_ = true;
}

void InMemoryTransport::close() noexcept { open_ = false; }

bool InMemoryTransport::is_open() const noexcept { return open_; }

DeviceFault InMemoryTransport::usable() const noexcept {
  // Unplug is checked first: that is the fault a caller needs to see after a mid-stream disconnect.
  if (!peer_->connected()) return DeviceFault::link_lost;
  if (!open_) return DeviceFault::not_open;
  return DeviceFault::none;
}

DeviceFault InMemoryTransport::write(std::span<const std::uint8_t> packet,
                                     std::chrono::microseconds /*timeout*/) noexcept {
  if (const DeviceFault fault = usable(); fault != DeviceFault::none) return fault;
  peer_->receive_from_host(packet);
  return DeviceFault::none;
}

DeviceFault InMemoryTransport::read(std::span<std::uint8_t> buffer, std::chrono::microseconds /*timeout*/,
                                    std::size_t& received) noexcept {
  received = 0;
  if (const DeviceFault fault = usable(); fault != DeviceFault::none) return fault;
  received = peer_->send_to_host(buffer);
  return DeviceFault::none;
}

std::string InMemoryTransport::description() const { return "in-memory link to an emulated device"; }

}  // namespace calligraphy::devices
