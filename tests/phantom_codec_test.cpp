#include "devices/phantom/phantom_codec.hpp"

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>

using namespace calligraphy::phantom;

namespace {
std::uint16_t u16_at(const std::array<std::uint8_t, 64>& bytes, std::size_t offset) {
  return static_cast<std::uint16_t>(bytes[offset] | (bytes[offset + 1] << 8));
}
}  // namespace

TEST_CASE("Command packets: 12-bit offset binary DAC, enable bit 3, dock LED, zero padding",
          "[phantom][codec]") {
  CommandPacket command;
  command.dac_counts = {0, -100, 1000};
  command.force_enable = true;
  command.dock_led = 2;
  std::array<std::uint8_t, 64> bytes{};
  bytes.fill(0xAA);
  encode_command(command, std::span<std::uint8_t, kCommandPacketBytes>(bytes.data(), kCommandPacketBytes));
  CHECK(u16_at(bytes, 0) == 0x07FF);  // zero force
  CHECK(u16_at(bytes, 2) == 0x07FF - 100);
  CHECK(u16_at(bytes, 4) == 0x07FF + 1000);
  CHECK(u16_at(bytes, 6) == ((1U << 3) | 2U));
  for (std::size_t i = 8; i < 16; ++i) CHECK(bytes[i] == 0);
  CHECK(bytes[16] == 0xAA);  // nothing written past the packet

  CommandPacket decoded;
  REQUIRE(decode_command(std::span<const std::uint8_t>(bytes.data(), 16), decoded) == PacketError::none);
  CHECK(decoded.dac_counts == command.dac_counts);
  CHECK(decoded.force_enable);
  CHECK(decoded.dock_led == 2);
}

TEST_CASE("Command DAC counts saturate at the 12-bit range", "[phantom][codec]") {
  CommandPacket command;
  command.dac_counts = {5000, -5000, 0};
  std::array<std::uint8_t, kCommandPacketBytes> bytes{};
  encode_command(command, bytes);
  CommandPacket decoded;
  REQUIRE(decode_command(bytes, decoded) == PacketError::none);
  CHECK(decoded.dac_counts[0] == kDacMaxCounts);
  CHECK(decoded.dac_counts[1] == kDacMinCounts);
  bytes[1] = 0x10;  // raw 0x10xx > 0x0FFF
  CHECK(decode_command(bytes, decoded) == PacketError::bad_dac_value);
}

TEST_CASE("Status packets round-trip, buttons are active-low on the wire", "[phantom][codec]") {
  StatusPacket status;
  status.encoder_counts = {-32768, 12345, -1};
  status.potentiometer_pairs = {{{0x8000, 0x4000}, {0x0020, 0xFFE0}, {0x1234, 0x5678}}};
  status.buttons_pressed = 1;  // button 1 pressed, button 2 released
  status.docked = true;
  status.packet_counter = 65535;
  std::array<std::uint8_t, kStatusPacketBytes> bytes{};
  encode_status(status, bytes);
  const std::uint16_t switches = static_cast<std::uint16_t>(bytes[18] | (bytes[19] << 8));
  CHECK((switches & 1U) == 0);  // pressed reads 0
  CHECK((switches & 2U) != 0);  // released reads 1
  CHECK((switches & 4U) != 0);  // docked

  StatusPacket decoded;
  REQUIRE(decode_status(bytes, decoded) == PacketError::none);
  CHECK(decoded.encoder_counts == status.encoder_counts);
  CHECK(decoded.potentiometer_pairs == status.potentiometer_pairs);
  CHECK(decoded.buttons_pressed == 1U);
  CHECK(decoded.docked);
  CHECK(decoded.packet_counter == 65535);
}

TEST_CASE("Short, long and malformed status packets are rejected without touching the output",
          "[phantom][codec]") {
  StatusPacket good;
  good.potentiometer_pairs = {{{0x8000, 0x8000}, {0x8000, 0x8000}, {0x8000, 0x8000}}};
  good.encoder_counts = {1, 2, 3};
  std::array<std::uint8_t, kStatusPacketBytes + 8> bytes{};
  encode_status(good, std::span<std::uint8_t, kStatusPacketBytes>(bytes.data(), kStatusPacketBytes));

  StatusPacket out;
  out.encoder_counts = {7, 7, 7};
  const std::span<const std::uint8_t> all(bytes);
  CHECK(decode_status(all.first(0), out) == PacketError::too_short);
  CHECK(decode_status(all.first(kStatusPacketBytes - 1), out) == PacketError::too_short);
  CHECK(decode_status(all.first(kStatusPacketBytes + 1), out) == PacketError::too_long);

  auto corrupt = bytes;
  corrupt[30] = 1;  // reserved byte
  CHECK(decode_status(std::span<const std::uint8_t>(corrupt).first(kStatusPacketBytes), out) ==
        PacketError::nonzero_reserved);
  corrupt = bytes;
  // Second pair: a = b = 0x001F, i.e. zero once the 5 unusable low bits are dropped.
  corrupt[10] = 0x1F, corrupt[11] = 0, corrupt[12] = 0x1F, corrupt[13] = 0;
  CHECK(decode_status(std::span<const std::uint8_t>(corrupt).first(kStatusPacketBytes), out) ==
        PacketError::bad_potentiometer);
  CHECK(out.encoder_counts == std::array<std::int16_t, 3>{7, 7, 7});

  REQUIRE(decode_status(all.first(kStatusPacketBytes), out) == PacketError::none);
  CHECK(out.encoder_counts == good.encoder_counts);
}

TEST_CASE("Potentiometer ratio a/(a+b) uses the top 11 bits only", "[phantom][codec]") {
  CHECK(potentiometer_fraction(0x8000, 0x8000) == Approx(0.5));
  CHECK(potentiometer_fraction(0x801F, 0x8000) == Approx(0.5));  // low 5 bits ignored
  CHECK(potentiometer_fraction(0x4000, 0xC000) == Approx(0.25));
  CHECK(std::isnan(potentiometer_fraction(0x001F, 0x0010)));
  CHECK(std::string(packet_error_name(PacketError::too_short)) == "too_short");
}
