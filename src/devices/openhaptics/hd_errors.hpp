#pragma once
// HDAPI error codes mapped onto the library's exception hierarchy (errors.hpp).
#include <string_view>

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

/// Throws the exception of the error's kind: CommunicationError, SafetyFault, or DeviceError (usage,
/// setup). The message names `context`, the code and the internal code. Precondition: an error.
[[noreturn]] void throw_hd_error(const hd::HDErrorInfo& error, std::string_view context);
/// Servo-path variant: only CommunicationError or SafetyFault (every non-safety kind is reported as
/// a CommunicationError, since the servo loop's reaction is the same: stop, forces off).
[[noreturn]] void throw_hd_servo_error(hd::HDerror code);

}  // namespace calligraphy::openhaptics
