/*
 * hd_stand_in_hdapi.h - the part of the OpenHaptics HDAPI (HD/hd.h,
 * HD/hdDefines.h, HD/hdScheduler.h) that the stand-in libHD.so implements.
 *
 * Written for the stand-in from public facts only (names, numeric values and
 * signatures as documented in the OpenHaptics API reference and as
 * redeclared by public wrappers such as kirurobo/ManagedPhantom). It is not
 * the vendor header. Plain C; a test may include it to get the constants
 * without an OpenHaptics installation.
 */
#ifndef HD_STAND_IN_HDAPI_H
#define HD_STAND_IN_HDAPI_H

#ifdef __cplusplus
extern "C" {
#endif

/* ---- types (hdDefines.h / hdScheduler.h) ---- */
typedef unsigned int HHD;
typedef unsigned int HDenum;
typedef unsigned int HDerror;
typedef int HDint;
typedef unsigned int HDuint;
typedef long HDlong;
typedef unsigned long HDulong;
typedef unsigned short HDushort;
typedef float HDfloat;
typedef double HDdouble;
typedef unsigned char HDboolean;
typedef const char* HDstring;
typedef unsigned int HDCallbackCode;
typedef unsigned long HDSchedulerHandle;
typedef unsigned int HDWaitCode;
typedef HDCallbackCode (*HDSchedulerCallback)(void* pUserData);

typedef struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
} HDErrorInfo;

/* ---- handles, booleans, callbacks ---- */
#define HD_DEFAULT_DEVICE ((HDstring)0)
#define HD_INVALID_HANDLE 0xFFFFFFFFu
#define HD_TRUE 1
#define HD_FALSE 0
#define HD_CALLBACK_DONE 0
#define HD_CALLBACK_CONTINUE 1
#define HD_WAIT_CHECK_STATUS 0
#define HD_WAIT_INFINITE 1
#define HD_MAX_SCHEDULER_PRIORITY ((HDushort)0xFFFF)
#define HD_MIN_SCHEDULER_PRIORITY ((HDushort)0)
#define HD_DEFAULT_SCHEDULER_PRIORITY ((HDushort)0x7FFF)

/* ---- error codes ---- */
#define HD_SUCCESS 0x0000
#define HD_INVALID_ENUM 0x0100
#define HD_INVALID_VALUE 0x0101
#define HD_INVALID_OPERATION 0x0102
#define HD_INVALID_INPUT_TYPE 0x0103
#define HD_BAD_HANDLE 0x0104
#define HD_WARM_MOTORS 0x0200
#define HD_EXCEEDED_MAX_FORCE 0x0201
#define HD_EXCEEDED_MAX_FORCE_IMPULSE 0x0202
#define HD_EXCEEDED_MAX_VELOCITY 0x0203
#define HD_FORCE_ERROR 0x0204
#define HD_DEVICE_FAULT 0x0300
#define HD_DEVICE_ALREADY_INITIATED 0x0301
#define HD_COMM_ERROR 0x0302
#define HD_COMM_CONFIG_ERROR 0x0303
#define HD_TIMER_ERROR 0x0304
#define HD_ILLEGAL_BEGIN 0x0400
#define HD_ILLEGAL_END 0x0401
#define HD_FRAME_ERROR 0x0402
#define HD_INVALID_PRIORITY 0x0500
#define HD_SCHEDULER_FULL 0x0501
#define HD_INVALID_LICENSE 0x0600

/* ---- parameters: frame state ---- */
#define HD_CURRENT_BUTTONS 0x2000
#define HD_CURRENT_SAFETY_SWITCH 0x2001
#define HD_CURRENT_INKWELL_SWITCH 0x2002
#define HD_CURRENT_POSITION 0x2050
#define HD_CURRENT_VELOCITY 0x2051
#define HD_CURRENT_TRANSFORM 0x2052
#define HD_LAST_BUTTONS 0x2200
#define HD_LAST_INKWELL_SWITCH 0x2202
#define HD_LAST_POSITION 0x2250
#define HD_LAST_VELOCITY 0x2251
#define HD_LAST_TRANSFORM 0x2252
#define HD_CURRENT_FORCE 0x2700

/* ---- parameters: device facts and settings ---- */
#define HD_VERSION 0x2500
#define HD_DEVICE_MODEL_TYPE 0x2501
#define HD_DEVICE_DRIVER_VERSION 0x2502
#define HD_DEVICE_VENDOR 0x2503
#define HD_DEVICE_SERIAL_NUMBER 0x2504
#define HD_MAX_WORKSPACE_DIMENSIONS 0x2550
#define HD_USABLE_WORKSPACE_DIMENSIONS 0x2551
#define HD_INPUT_DOF 0x2553
#define HD_OUTPUT_DOF 0x2554
#define HD_CALIBRATION_STYLE 0x2555
#define HD_UPDATE_RATE 0x2600
#define HD_INSTANTANEOUS_UPDATE_RATE 0x2601
#define HD_NOMINAL_MAX_STIFFNESS 0x2602
#define HD_NOMINAL_MAX_FORCE 0x2603
#define HD_NOMINAL_MAX_CONTINUOUS_FORCE 0x2604
#define HD_SOFTWARE_VELOCITY_LIMIT 0x2606
#define HD_SOFTWARE_FORCE_IMPULSE_LIMIT 0x2607
#define HD_FORCE_RAMPING_RATE 0x2608
#define HD_NOMINAL_MAX_DAMPING 0x2609
#define HD_USER_STATUS_LIGHT 0x2900

/* ---- capabilities (hdEnable / hdDisable / hdIsEnabled) ---- */
#define HD_FORCE_OUTPUT 0x4000
#define HD_MAX_FORCE_CLAMPING 0x4001
#define HD_FORCE_RAMPING 0x4002
#define HD_SOFTWARE_FORCE_LIMIT 0x4003
#define HD_ONE_FRAME_LIMIT 0x4004

/* ---- calibration ---- */
#define HD_CALIBRATION_OK 0x5000
#define HD_CALIBRATION_NEEDS_UPDATE 0x5001
#define HD_CALIBRATION_NEEDS_MANUAL_INPUT 0x5002
#define HD_CALIBRATION_ENCODER_RESET (1 << 0)
#define HD_CALIBRATION_AUTO (1 << 1)
#define HD_CALIBRATION_INKWELL (1 << 2)

/* ---- buttons ---- */
#define HD_DEVICE_BUTTON_1 (1 << 0)
#define HD_DEVICE_BUTTON_2 (1 << 1)
#define HD_DEVICE_BUTTON_3 (1 << 2)
#define HD_DEVICE_BUTTON_4 (1 << 3)

/* ---- device routines ---- */
HHD hdInitDevice(HDstring pConfigName);
void hdDisableDevice(HHD hHD);
void hdMakeCurrentDevice(HHD hHD);
HHD hdGetCurrentDevice(void);
void hdBeginFrame(HHD hHD);
void hdEndFrame(HHD hHD);
void hdEnable(HDenum cap);
void hdDisable(HDenum cap);
HDboolean hdIsEnabled(HDenum cap);
HDErrorInfo hdGetError(void);
HDstring hdGetErrorString(HDerror errorCode);
HDstring hdGetString(HDenum pname);

void hdGetBooleanv(HDenum pname, HDboolean* params);
void hdGetIntegerv(HDenum pname, HDint* params);
void hdGetFloatv(HDenum pname, HDfloat* params);
void hdGetDoublev(HDenum pname, HDdouble* params);
void hdGetLongv(HDenum pname, HDlong* params);
void hdSetBooleanv(HDenum pname, const HDboolean* params);
void hdSetIntegerv(HDenum pname, const HDint* params);
void hdSetFloatv(HDenum pname, const HDfloat* params);
void hdSetDoublev(HDenum pname, const HDdouble* params);
void hdSetLongv(HDenum pname, const HDlong* params);

/* ---- calibration routines ---- */
HDenum hdCheckCalibration(void);
void hdUpdateCalibration(HDenum style);

/* ---- scheduler routines ---- */
void hdStartScheduler(void);
void hdStopScheduler(void);
void hdSetSchedulerRate(HDulong nRate);
HDdouble hdGetSchedulerTimeStamp(void);
HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority);
void hdScheduleSynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort nPriority);
void hdUnschedule(HDSchedulerHandle hHandle);
HDboolean hdWaitForCompletion(HDSchedulerHandle hHandle, HDWaitCode param);

#ifdef __cplusplus
}
#endif

#endif /* HD_STAND_IN_HDAPI_H */
