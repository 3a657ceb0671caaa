#pragma once
// The few HDAPI (OpenHaptics) types, enum values and function signatures this backend uses, declared
// here so that the library builds without OpenHaptics; libHD.so is loaded with dlopen at run time.
// Values as in OpenHaptics' HD/hdDefines.h (public knowledge), cross-checked against the MIT-licensed
// ManagedPhantom wrapper (kirurobo). Not checked against a real libHD here: none is installed.

namespace calligraphy::openhaptics::hd {

using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDint = int;
using HDdouble = double;
using HDushort = unsigned short;
using HDCallbackCode = unsigned int;
using HDSchedulerHandle = unsigned long;

struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};

using SchedulerCallback = HDCallbackCode (*)(void* user_data);

inline constexpr HHD HD_INVALID_HANDLE = 0xFFFFFFFF;
inline constexpr HDCallbackCode HD_CALLBACK_DONE = 0;
inline constexpr HDCallbackCode HD_CALLBACK_CONTINUE = 1;
inline constexpr HDushort HD_DEFAULT_SCHEDULER_PRIORITY = 0x7FFF;  // (max 0xFFFF + min 0) / 2

// Parameters (hdGet*/hdSet*).
inline constexpr HDenum HD_CURRENT_BUTTONS = 0x2000;
inline constexpr HDenum HD_CURRENT_INKWELL_SWITCH = 0x2002;
inline constexpr HDenum HD_CURRENT_POSITION = 0x2050;  // mm
inline constexpr HDenum HD_CURRENT_VELOCITY = 0x2051;  // mm/s
inline constexpr HDenum HD_DEVICE_MODEL_TYPE = 0x2501;
inline constexpr HDenum HD_DEVICE_VENDOR = 0x2503;
inline constexpr HDenum HD_USABLE_WORKSPACE_DIMENSIONS = 0x2551;  // mm: min x y z, max x y z
inline constexpr HDenum HD_CALIBRATION_STYLE = 0x2555;
inline constexpr HDenum HD_NOMINAL_MAX_STIFFNESS = 0x2602;         // N/mm
inline constexpr HDenum HD_NOMINAL_MAX_FORCE = 0x2603;             // N
inline constexpr HDenum HD_NOMINAL_MAX_CONTINUOUS_FORCE = 0x2604;  // N
inline constexpr HDenum HD_NOMINAL_MAX_DAMPING = 0x2609;           // N s/mm
inline constexpr HDenum HD_CURRENT_FORCE = 0x2700;                 // N

// Capabilities (hdEnable/hdDisable).
inline constexpr HDenum HD_FORCE_OUTPUT = 0x4000;

// Calibration.
inline constexpr HDenum HD_CALIBRATION_OK = 0x5000;
inline constexpr HDenum HD_CALIBRATION_NEEDS_UPDATE = 0x5001;
inline constexpr HDenum HD_CALIBRATION_NEEDS_MANUAL_INPUT = 0x5002;
inline constexpr HDint HD_CALIBRATION_ENCODER_RESET = 1 << 0;
inline constexpr HDint HD_CALIBRATION_AUTO = 1 << 1;
inline constexpr HDint HD_CALIBRATION_INKWELL = 1 << 2;

// Errors (HDErrorInfo::errorCode).
inline constexpr HDerror HD_SUCCESS = 0x0000;
inline constexpr HDerror HD_INVALID_ENUM = 0x0100;
inline constexpr HDerror HD_INVALID_VALUE = 0x0101;
inline constexpr HDerror HD_INVALID_OPERATION = 0x0102;
inline constexpr HDerror HD_INVALID_INPUT_TYPE = 0x0103;
inline constexpr HDerror HD_BAD_HANDLE = 0x0104;
inline constexpr HDerror HD_WARM_MOTORS = 0x0200;
inline constexpr HDerror HD_EXCEEDED_MAX_FORCE = 0x0201;
inline constexpr HDerror HD_EXCEEDED_MAX_FORCE_IMPULSE = 0x0202;
inline constexpr HDerror HD_EXCEEDED_MAX_VELOCITY = 0x0203;
inline constexpr HDerror HD_FORCE_ERROR = 0x0204;
inline constexpr HDerror HD_DEVICE_FAULT = 0x0300;
inline constexpr HDerror HD_DEVICE_ALREADY_INITIATED = 0x0301;
inline constexpr HDerror HD_COMM_ERROR = 0x0302;
inline constexpr HDerror HD_COMM_CONFIG_ERROR = 0x0303;
inline constexpr HDerror HD_TIMER_ERROR = 0x0304;
inline constexpr HDerror HD_ILLEGAL_BEGIN = 0x0400;
inline constexpr HDerror HD_ILLEGAL_END = 0x0401;
inline constexpr HDerror HD_FRAME_ERROR = 0x0402;
inline constexpr HDerror HD_INVALID_PRIORITY = 0x0500;
inline constexpr HDerror HD_SCHEDULER_FULL = 0x0501;
inline constexpr HDerror HD_INVALID_LICENSE = 0x0600;

// Function signatures (C linkage in libHD).
using InitDeviceFn = HHD (*)(const char* config_name);  // nullptr = HD_DEFAULT_DEVICE
using DisableDeviceFn = void (*)(HHD);
using MakeCurrentDeviceFn = void (*)(HHD);
using BeginFrameFn = void (*)(HHD);
using EndFrameFn = void (*)(HHD);
using GetDoublevFn = void (*)(HDenum, HDdouble*);
using GetIntegervFn = void (*)(HDenum, HDint*);
using SetDoublevFn = void (*)(HDenum, const HDdouble*);
using GetStringFn = const char* (*)(HDenum);
using EnableFn = void (*)(HDenum);
using GetErrorFn = HDErrorInfo (*)();
using ScheduleAsynchronousFn = HDSchedulerHandle (*)(SchedulerCallback, void*, HDushort);
using ScheduleSynchronousFn = void (*)(SchedulerCallback, void*, HDushort);
using UnscheduleFn = void (*)(HDSchedulerHandle);
using StartSchedulerFn = void (*)();
using StopSchedulerFn = void (*)();
using CheckCalibrationFn = HDenum (*)();
using UpdateCalibrationFn = void (*)(HDint style);
using SetSchedulerRateFn = void (*)(unsigned long rate_hz);

}  // namespace calligraphy::openhaptics::hd
