#include "devices/phantom/phantom_codec.hpp"

#include <algorithm>
#include <limits>

namespace calligraphy::phantom {
namespace {

// Little-endian field access (byte order is this library's choice, see the header).
std::uint16_t load_u16(std::span<const std::uint8_t> bytes, std::size_t offset) noexcept {
  return static_cast<std::uint16_t>(bytes[offset] | (bytes[offset + 1] << 8));
}
std::int16_t load_i16(std::span<const std::uint8_t> bytes, std::size_t offset) noexcept {
  return static_cast<std::int16_t>(load_u16(bytes, offset));
}
void store_u16(std::span<std::uint8_t> bytes, std::size_t offset, std::uint16_t value) noexcept {
  bytes[offset] = static_cast<std::uint8_t>(value & 0xFF);
  bytes[offset + 1] = static_cast<std::uint8_t>(value >> 8);
}

bool all_zero(std::span<const std::uint8_t> bytes) noexcept {
  return std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t b) { return b == 0; });
}

PacketError check_size(std::size_t size, std::size_t expected) noexcept {
  if (size < expected) return PacketError::too_short;
  if (size > expected) return PacketError::too_long;
  return PacketError::none;
}

constexpr std::size_t kCommandStatusOffset = 6;
constexpr std::size_t kCommandPaddingOffset = 8;
constexpr std::size_t kStatusPotentiometerOffset = 6;
constexpr std::size_t kStatusSwitchesOffset = 18;
constexpr std::size_t kStatusCounterOffset = 20;
constexpr std::size_t kStatusReservedOffset = 22;
constexpr std::uint16_t kSwitchButton1 = 1U << 0;
constexpr std::uint16_t kSwitchButton2 = 1U << 1;
constexpr std::uint16_t kSwitchDocked = 1U << 2;

}  // namespace

const char* packet_error_name(PacketError error) noexcept {
  switch (error) {
    case PacketError::none:
      return "none";
    case PacketError::too_short:
      return "too_short";
    case PacketError::too_long:
      return "too_long";
    case PacketError::bad_potentiometer:
      return "bad_potentiometer";
    case PacketError::nonzero_reserved:
      return "nonzero_reserved";
    case PacketError::bad_dac_value:
      return "bad_dac_value";
  }
  return "unknown";
}

double potentiometer_fraction(std::uint16_t a, std::uint16_t b) noexcept {
  const double usable_a = a & kPotentiometerMask;
  const double usable_b = b & kPotentiometerMask;
  if (usable_a + usable_b == 0.0) return std::numeric_limits<double>::quiet_NaN();
  return usable_a / (usable_a + usable_b);
}

void encode_command(const CommandPacket& command, std::span<std::uint8_t, kCommandPacketBytes> out) noexcept {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  for (std::size_t joint = 0; joint < 3; ++joint) {
    const int counts = std::clamp<int>(command.dac_counts[joint], kDacMinCounts, kDacMaxCounts);
    store_u16(out, 2 * joint, static_cast<std::uint16_t>(kDacZeroRaw + counts));
  }
  std::uint16_t status = command.dock_led & kCommandDockLedMask;
  if (command.force_enable) status |= kCommandForceEnableBit;
  store_u16(out, kCommandStatusOffset, status);
}

PacketError decode_command(std::span<const std::uint8_t> bytes, CommandPacket& out) noexcept {
  if (const auto error = check_size(bytes.size(), kCommandPacketBytes); error != PacketError::none)
    return error;
  if (!all_zero(bytes.subspan(kCommandPaddingOffset))) return PacketError::nonzero_reserved;
  CommandPacket decoded;
  for (std::size_t joint = 0; joint < 3; ++joint) {
    const std::uint16_t raw = load_u16(bytes, 2 * joint);
    if (raw > 0x0FFF) return PacketError::bad_dac_value;
    decoded.dac_counts[joint] = static_cast<std::int16_t>(static_cast<int>(raw) - kDacZeroRaw);
  }
  const std::uint16_t status = load_u16(bytes, kCommandStatusOffset);
  decoded.force_enable = (status & kCommandForceEnableBit) != 0;
  decoded.dock_led = static_cast<std::uint8_t>(status & kCommandDockLedMask);
  out = decoded;
  return PacketError::none;
}

void encode_status(const StatusPacket& status, std::span<std::uint8_t, kStatusPacketBytes> out) noexcept {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  for (std::size_t joint = 0; joint < 3; ++joint) {
    store_u16(out, 2 * joint, static_cast<std::uint16_t>(status.encoder_counts[joint]));
  }
  for (std::size_t axis = 0; axis < 3; ++axis) {
    store_u16(out, kStatusPotentiometerOffset + 4 * axis, status.potentiometer_pairs[axis][0]);
    store_u16(out, kStatusPotentiometerOffset + 4 * axis + 2, status.potentiometer_pairs[axis][1]);
  }
  // Buttons are active-low on the wire: a released button reads 1.
  std::uint16_t switches = 0;
  if ((status.buttons_pressed & 1U) == 0) switches |= kSwitchButton1;
  if ((status.buttons_pressed & 2U) == 0) switches |= kSwitchButton2;
  if (status.docked) switches |= kSwitchDocked;
  store_u16(out, kStatusSwitchesOffset, switches);
  store_u16(out, kStatusCounterOffset, status.packet_counter);
}

PacketError decode_status(std::span<const std::uint8_t> bytes, StatusPacket& out) noexcept {
  if (const auto error = check_size(bytes.size(), kStatusPacketBytes); error != PacketError::none)
    return error;
  if (!all_zero(bytes.subspan(kStatusReservedOffset))) return PacketError::nonzero_reserved;
  StatusPacket decoded;
  for (std::size_t joint = 0; joint < 3; ++joint) decoded.encoder_counts[joint] = load_i16(bytes, 2 * joint);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const std::uint16_t a = load_u16(bytes, kStatusPotentiometerOffset + 4 * axis);
    const std::uint16_t b = load_u16(bytes, kStatusPotentiometerOffset + 4 * axis + 2);
    if (((a & kPotentiometerMask) + (b & kPotentiometerMask)) == 0) return PacketError::bad_potentiometer;
    decoded.potentiometer_pairs[axis] = {a, b};
  }
  const std::uint16_t switches = load_u16(bytes, kStatusSwitchesOffset);
  if ((switches & kSwitchButton1) == 0) decoded.buttons_pressed |= 1U;
  if ((switches & kSwitchButton2) == 0) decoded.buttons_pressed |= 2U;
  decoded.docked = (switches & kSwitchDocked) != 0;
  decoded.packet_counter = load_u16(bytes, kStatusCounterOffset);
  out = decoded;
  return PacketError::none;
}

}  // namespace calligraphy::phantom
