#pragma once
/// \file device_fault.hpp
/// The one taxonomy of device faults. On the servo path (`HapticDevice::read_state`, `write_force`, the
/// servo loop's tick) a fault is a `DeviceFault` code: returned, never thrown, with a fixed message
/// (`to_string`), so that a failing tick allocates nothing and builds no string. Off the servo path the
/// same code becomes the library's typed exception through one mapping, `throw_device_fault`
/// (errors.hpp: `CommunicationError` for the link faults, `SafetyFault` for the safety faults). The servo
/// loop's `LoopFault::device` and a trial's `TrialResult::device_fault` carry the same code.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace calligraphy {

/// Why a servo-path device call failed. After any fault other than `none` the device has turned its
/// forces off (zero force, `forces_enabled()` false); after a link fault it is also closed.
enum class DeviceFault : std::uint8_t {
  none,  ///< no fault
  // Link faults: CommunicationError off the servo path.
  not_open,         ///< read or write on a device that is not open (or was closed by an earlier link fault)
  link_lost,        ///< the transport failed: unplugged, a transfer refused or timed out
  no_valid_status,  ///< too many reads in a row without a valid status packet (timeouts, rejected packets)
  driver_error,     ///< the device's driver reported a link, timing or usage error in its servo loop
  // Safety faults: SafetyFault off the servo path.
  watchdog,          ///< forces were on and no force command came within the device's watchdog timeout
  non_finite_force,  ///< a force command with a NaN or infinite component; zero force sent instead
  safety_limit,      ///< the device tripped a safety limit of its own (force, impulse, velocity, warm motors)
  // A usage fault: CommunicationError off the servo path (the device's time source is the program).
  not_advanced,  ///< a simulated device held by a hand read again with no `advance` since its last force
};

/// Number of `DeviceFault` values (for tables indexed by the code).
inline constexpr std::size_t kDeviceFaultCount = 9;

/// Whether the fault is a link fault (`CommunicationError`) rather than a safety fault (`SafetyFault`).
[[nodiscard]] constexpr bool is_link_fault(DeviceFault fault) noexcept {
  return fault == DeviceFault::not_open || fault == DeviceFault::link_lost ||
         fault == DeviceFault::no_valid_status || fault == DeviceFault::driver_error ||
         fault == DeviceFault::not_advanced;
}

/// The code's name, e.g. "link_lost" (for JSON, logs and tests). Static storage.
[[nodiscard]] const char* device_fault_name(DeviceFault fault) noexcept;

/// The fixed message of a code, e.g. "link lost: the device was unplugged or a transfer failed; forces
/// off". Static storage: usable on the servo path.
[[nodiscard]] const char* to_string(DeviceFault fault) noexcept;

/// "<device_name>: <to_string(fault)> (<detail>)"; without "<device_name>: " when the name is empty and
/// without " (<detail>)" when the detail is empty. Allocates: off the servo path. What
/// `throw_device_fault` throws and what a trial keeps as `abort_reason`.
[[nodiscard]] std::string device_fault_message(DeviceFault fault, std::string_view device_name,
                                               std::string_view detail = {});

/// The one mapping from a fault code to the typed exceptions of errors.hpp: throws CommunicationError
/// for a link fault, SafetyFault for a safety fault, with `device_fault_message(fault, device_name,
/// detail)`. `detail` is what the device recorded about the fault, formatted off the servo path (e.g.
/// the last rejected packet's problem). Off the servo path only (after the loop, in `open()`, in
/// bindings, in tests). Precondition: fault != none (`none` throws InvalidArgument, a caller's bug).
[[noreturn]] void throw_device_fault(DeviceFault fault, std::string_view device_name,
                                     std::string_view detail = {});

}  // namespace calligraphy
