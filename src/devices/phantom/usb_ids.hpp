#pragma once
// USB ids reported for the 3D Systems (Geomagic) Touch. UNCONFIRMED: they come from user reports
// on public forums, not from a vendor document or a device on this bench.
#include <array>
#include <cstdint>

namespace calligraphy::phantom {

inline constexpr std::uint16_t kTouchUsbVendorId = 0x2988;
inline constexpr std::array<std::uint16_t, 2> kTouchUsbProductIds = {0x0301, 0x0302};

[[nodiscard]] inline bool is_reported_touch_id(std::uint16_t vendor, std::uint16_t product) noexcept {
  return vendor == kTouchUsbVendorId &&
         (product == kTouchUsbProductIds[0] || product == kTouchUsbProductIds[1]);
}

}  // namespace calligraphy::phantom
