#include "devices/openhaptics/hd_errors.hpp"

#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::openhaptics {

HdErrorKind classify_hd_error(hd::HDerror code) noexcept {
  using namespace hd;
  switch (code) {
    case HD_SUCCESS:
      return HdErrorKind::none;
    case HD_COMM_ERROR:
    case HD_COMM_CONFIG_ERROR:
    case HD_TIMER_ERROR:
    case HD_DEVICE_FAULT:
      return HdErrorKind::communication;
    case HD_WARM_MOTORS:
    case HD_EXCEEDED_MAX_FORCE:
    case HD_EXCEEDED_MAX_FORCE_IMPULSE:
    case HD_EXCEEDED_MAX_VELOCITY:
    case HD_FORCE_ERROR:
      return HdErrorKind::safety;
    case HD_INVALID_ENUM:
    case HD_INVALID_VALUE:
    case HD_INVALID_OPERATION:
    case HD_INVALID_INPUT_TYPE:
    case HD_BAD_HANDLE:
    case HD_ILLEGAL_BEGIN:
    case HD_ILLEGAL_END:
    case HD_FRAME_ERROR:
    case HD_INVALID_PRIORITY:
    case HD_SCHEDULER_FULL:
      return HdErrorKind::usage;
    default:
      return HdErrorKind::setup;  // HD_DEVICE_ALREADY_INITIATED, HD_INVALID_LICENSE, unknown
  }
}

const char* hd_error_name(hd::HDerror code) noexcept {
  using namespace hd;
  switch (code) {
    case HD_SUCCESS:
      return "HD_SUCCESS";
    case HD_INVALID_ENUM:
      return "HD_INVALID_ENUM";
    case HD_INVALID_VALUE:
      return "HD_INVALID_VALUE";
    case HD_INVALID_OPERATION:
      return "HD_INVALID_OPERATION";
    case HD_INVALID_INPUT_TYPE:
      return "HD_INVALID_INPUT_TYPE";
    case HD_BAD_HANDLE:
      return "HD_BAD_HANDLE";
    case HD_WARM_MOTORS:
      return "HD_WARM_MOTORS";
    case HD_EXCEEDED_MAX_FORCE:
      return "HD_EXCEEDED_MAX_FORCE";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE:
      return "HD_EXCEEDED_MAX_FORCE_IMPULSE";
    case HD_EXCEEDED_MAX_VELOCITY:
      return "HD_EXCEEDED_MAX_VELOCITY";
    case HD_FORCE_ERROR:
      return "HD_FORCE_ERROR";
    case HD_DEVICE_FAULT:
      return "HD_DEVICE_FAULT";
    case HD_DEVICE_ALREADY_INITIATED:
      return "HD_DEVICE_ALREADY_INITIATED";
    case HD_COMM_ERROR:
      return "HD_COMM_ERROR";
    case HD_COMM_CONFIG_ERROR:
      return "HD_COMM_CONFIG_ERROR";
    case HD_TIMER_ERROR:
      return "HD_TIMER_ERROR";
    case HD_ILLEGAL_BEGIN:
      return "HD_ILLEGAL_BEGIN";
    case HD_ILLEGAL_END:
      return "HD_ILLEGAL_END";
    case HD_FRAME_ERROR:
      return "HD_FRAME_ERROR";
    case HD_INVALID_PRIORITY:
      return "HD_INVALID_PRIORITY";
    case HD_SCHEDULER_FULL:
      return "HD_SCHEDULER_FULL";
    case HD_INVALID_LICENSE:
      return "HD_INVALID_LICENSE";
    default:
      return "HD_UNKNOWN_ERROR";
  }
}

const char* hd_init_advice(hd::HDerror code) noexcept {
  using namespace hd;
  switch (code) {
    case HD_COMM_CONFIG_ERROR:
      return "no arm answers under that configuration: check that the device is plugged in and powered, and "
             "that its configuration (Touch Setup / Geomagic Touch Diagnostic) names it";
    case HD_COMM_ERROR:
    case HD_DEVICE_FAULT:
    case HD_TIMER_ERROR:
      return "the link to the arm failed: re-plug it, check its power, and run the vendor's diagnostic";
    case HD_DEVICE_ALREADY_INITIATED:
      return "another program (or another part of this one) holds the device: close it and try again";
    case HD_INVALID_LICENSE:
      return "the OpenHaptics licence was refused: check the installation of OpenHaptics";
    default:
      return "run the vendor's diagnostic tool to see whether the device works outside this program";
  }
}

void throw_hd_error(const hd::HDErrorInfo& error, std::string_view context) {
  const std::string message = "OpenHaptics: " + std::string(context) + ": " + hd_error_name(error.errorCode) +
                              " (code " + std::to_string(error.errorCode) + ", internal " +
                              std::to_string(error.internalErrorCode) + ")";
  switch (classify_hd_error(error.errorCode)) {
    case HdErrorKind::communication:
      throw CommunicationError(message);
    case HdErrorKind::safety:
      throw SafetyFault(message + "; forces turned off");
    default:
      throw DeviceError(message);
  }
}

DeviceFault hd_servo_fault(hd::HDerror code) noexcept {
  switch (classify_hd_error(code)) {
    case HdErrorKind::none:
      return DeviceFault::none;
    case HdErrorKind::safety:
      return DeviceFault::safety_limit;
    default:
      return DeviceFault::driver_error;
  }
}

}  // namespace calligraphy::openhaptics
