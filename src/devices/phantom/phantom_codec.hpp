#pragma once
/// \file phantom_codec.hpp
/// Encoding of the Phantom Omni (FireWire) command and status packets.
///
/// Source of the field list: the reverse-engineered protocol published by ytsutano/raw_omni (ISC) and
/// scottsharris/phantom-drivers (LGPL-3), as described in those projects. That description
/// names the fields and their sizes; it does not pin their order inside the status packet nor the byte
/// order. The offsets and the byte order below are THIS LIBRARY'S CHOICE where the description is
/// silent (marked "choice"); docs/devices.md lists them. Nothing here was checked against hardware.
///
/// Command packet, 16 bytes, little-endian (choice):
///   0  int16 DAC joint 1   12-bit offset binary, 0x07FF = zero force (published)
///   2  int16 DAC joint 2
///   4  int16 DAC joint 3
///   6  uint16 status       bit 3 force enable, bits 0-1 dock LED (published)
///   8  8 bytes padding, zero (published)
/// Status packet, 44 bytes, little-endian (choice), offsets (choice):
///   0  int16 encoder joint 1, 15,000 counts per joint revolution (published)
///   2  int16 encoder joint 2
///   4  int16 encoder joint 3 = theta_z, the absolute angle of the second link (published)
///   6  3 x (uint16 a, uint16 b) gimbal potentiometer pairs, angle ratio a/(a+b), top 11 bits usable
///  18  uint16 switches: bit 0 button 1, bit 1 button 2 (active-low, published), bit 2 docked in the
///      inkwell (1 = docked; polarity is a choice)
///  20  uint16 packet counter, +1 per status packet, wraps at 65536
///  22  22 bytes reserved, must be zero (choice: lets the decoder reject garbage)

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace calligraphy::phantom {

inline constexpr std::size_t kCommandPacketBytes = 16;
inline constexpr std::size_t kStatusPacketBytes = 44;
/// Raw DAC value of zero force (12-bit offset binary).
inline constexpr std::uint16_t kDacZeroRaw = 0x07FF;
/// Signed DAC counts representable in 12-bit offset binary around 0x07FF.
inline constexpr int kDacMinCounts = -0x07FF;
inline constexpr int kDacMaxCounts = 0x0FFF - 0x07FF;
inline constexpr int kEncoderCountsPerRevolution = 15000;
inline constexpr std::uint16_t kCommandForceEnableBit = 1U << 3;
inline constexpr std::uint16_t kCommandDockLedMask = 0x3;
/// Only the top 11 bits of a potentiometer reading are meaningful.
inline constexpr std::uint16_t kPotentiometerMask = 0xFFE0;

/// Host -> device. `dac_counts` are signed (0 = no force); the codec adds the 0x07FF offset.
struct CommandPacket {
  std::array<std::int16_t, 3> dac_counts{};
  bool force_enable = false;
  std::uint8_t dock_led = 0;  ///< 0..3, bits 0-1 of the status word
};

/// Device -> host, decoded.
struct StatusPacket {
  std::array<std::int16_t, 3> encoder_counts{};  ///< raw joint encoders (joint 3: absolute theta_z)
  std::array<std::array<std::uint16_t, 2>, 3> potentiometer_pairs{};  ///< raw (a, b) per gimbal axis
  std::uint32_t buttons_pressed = 0;  ///< bit i set while button i+1 is pressed (active-low undone)
  bool docked = false;                ///< stylus in the inkwell
  std::uint16_t packet_counter = 0;
};

/// Why a packet was rejected.
enum class PacketError : std::uint8_t {
  none,
  too_short,          ///< fewer bytes than the packet size
  too_long,           ///< more bytes than the packet size
  bad_potentiometer,  ///< a potentiometer pair with a + b == 0 (no ratio defined)
  nonzero_reserved,   ///< reserved or padding bytes are not zero
  bad_dac_value,      ///< a DAC field outside 0x0000..0x0FFF
};

/// Short name of a packet error, e.g. "too_short". Static storage, never allocates.
[[nodiscard]] const char* packet_error_name(PacketError error) noexcept;

/// Gimbal angle fraction a/(a+b) in [0, 1] from the top 11 bits of each reading; NaN when a + b == 0.
[[nodiscard]] double potentiometer_fraction(std::uint16_t a, std::uint16_t b) noexcept;

/// Encodes a command. Counts outside kDacMinCounts..kDacMaxCounts are saturated (callers scale first).
void encode_command(const CommandPacket& command, std::span<std::uint8_t, kCommandPacketBytes> out) noexcept;
/// Decodes a command (the emulator's side). Leaves `out` untouched on error.
[[nodiscard]] PacketError decode_command(std::span<const std::uint8_t> bytes, CommandPacket& out) noexcept;

/// Encodes a status packet (the emulator's side). Reserved bytes are zero.
void encode_status(const StatusPacket& status, std::span<std::uint8_t, kStatusPacketBytes> out) noexcept;
/// Decodes a status packet of exactly kStatusPacketBytes. Leaves `out` untouched on error.
[[nodiscard]] PacketError decode_status(std::span<const std::uint8_t> bytes, StatusPacket& out) noexcept;

/// Rejected-packet and link counters, kept by the receiving side and reported on request.
struct PacketErrorCounts {
  std::uint64_t too_short = 0;
  std::uint64_t too_long = 0;
  std::uint64_t malformed = 0;     ///< right size, bad content (bad_potentiometer, nonzero_reserved, ...)
  std::uint64_t timeouts = 0;      ///< reads that returned nothing in time
  std::uint64_t lost_packets = 0;  ///< gaps in the packet counter
  [[nodiscard]] std::uint64_t rejected() const noexcept { return too_short + too_long + malformed; }
};

}  // namespace calligraphy::phantom
