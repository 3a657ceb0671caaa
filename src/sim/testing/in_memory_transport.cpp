#include "sim/testing/in_memory_transport.hpp"

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

void InMemoryTransport::throw_if_unusable(const char* /*operation*/) const {
  // Unplug is checked first: that is the fault a caller needs to see after a mid-stream disconnect.
  // Fixed messages: the servo path builds no strings, also when it fails.
  if (!peer_->connected()) throw CommunicationError("in-memory transport: device unplugged");
  if (!open_) throw CommunicationError("in-memory transport: closed link");
}

void InMemoryTransport::write(std::span<const std::uint8_t> packet, std::chrono::microseconds /*timeout*/) {
  throw_if_unusable("write");
  peer_->receive_from_host(packet);
}

std::size_t InMemoryTransport::read(std::span<std::uint8_t> buffer, std::chrono::microseconds /*timeout*/) {
  throw_if_unusable("read");
  return peer_->send_to_host(buffer);
}

std::string InMemoryTransport::description() const { return "in-memory link to an emulated device"; }

}  // namespace calligraphy::devices
