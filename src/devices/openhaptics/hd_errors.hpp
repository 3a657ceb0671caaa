#pragma once
// HDAPI error codes mapped onto the library's exception hierarchy (errors.hpp).
#include <string_view>

#include "calligraphy/core/device_fault.hpp"
#include "devices/openhaptics/hd_api.hpp"

namespace calligraphy::openhaptics {

enum class HdErrorKind {
  none,           ///< HD_SUCCESS
  communication,  ///< link or timing: HD_COMM_ERROR, HD_COMM_CONFIG_ERROR, HD_TIMER_ERROR, HD_DEVICE_FAULT
  safety,         ///< HD_WARM_MOTORS, HD_EXCEEDED_MAX_FORCE / _FORCE_IMPULSE / _VELOCITY, HD_FORCE_ERROR
  usage,          ///< a programming error: invalid enum/value/operation/handle, frame and scheduler errors
  setup,          ///< HD_DEVICE_ALREADY_INITIATED, HD_INVALID_LICENSE, unknown codes
};

/// The kind of an HD error code.
[[nodiscard]] HdErrorKind classify_hd_error(hd::HDerror code) noexcept;
/// "HD_COMM_ERROR" etc.; "HD_UNKNOWN_ERROR" for codes not listed in hd_api.hpp. Static storage.
[[nodiscard]] const char* hd_error_name(hd::HDerror code) noexcept;

/// What to try when hdInitDevice fails with `code`, for people ("check that the arm is connected ...").
/// Static storage.
[[nodiscard]] const char* hd_init_advice(hd::HDerror code) noexcept;

/// Throws the exception of the error's kind: CommunicationError, SafetyFault, or DeviceError (usage,
/// setup). The message names `context`, the code and the internal code. Precondition: an error.
[[noreturn]] void throw_hd_error(const hd::HDErrorInfo& error, std::string_view context);
/// Servo-path variant, a code instead of an exception: `safety_limit` for the safety kind, and
/// `driver_error` for every other kind (the servo loop's reaction is the same: stop, forces off).
/// Off the servo path, `throw_device_fault` turns it into SafetyFault or CommunicationError.
[[nodiscard]] DeviceFault hd_servo_fault(hd::HDerror code) noexcept;

}  // namespace calligraphy::openhaptics
