#pragma once
/// \file errors.hpp
/// The library's exception hierarchy. Every error message names the thing at fault
/// (file, character, stroke, position). Bad input throws `DataError` or `InvalidArgument`;
/// device faults off the servo path throw `DeviceError` subclasses. On the servo path nothing throws: a
/// device returns a `DeviceFault` code (device_fault.hpp), and `throw_device_fault` is the one mapping
/// from such a code to `CommunicationError` or `SafetyFault`, used off the servo path.

#include <stdexcept>
#include <string>

namespace calligraphy {

/// Base of every exception thrown by the library.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A caller passed a value outside a documented precondition (NaN, negative stiffness, ...).
class InvalidArgument : public Error {
 public:
  using Error::Error;
};

/// Character data could not be read: missing folder or file, malformed JSON, impossible geometry.
/// The message names the path, the character and the position (line:column or JSON pointer).
class DataError : public Error {
 public:
  using Error::Error;
};

/// A character is not in the library that was asked for it. The message names the character
/// (glyph and U+ code point) and where the library looked.
class CharacterNotFound : public DataError {
 public:
  using DataError::DataError;
};

/// The content of a file a command was given as its input (a study protocol, a trial record given with
/// `trial --spec`) refused by its reader: malformed JSON, a missing or unknown key, a value of another type
/// or out of its range. One line "FILE: /json/pointer: what is wrong". The command line treats it as wrong
/// usage (exit 2), as it treats an option's value out of its range; a file that cannot be read at all stays
/// a DataError (exit 1).
class InputError : public DataError {
 public:
  using DataError::DataError;
};

/// Base of haptic-device faults.
class DeviceError : public Error {
 public:
  using Error::Error;
};

/// No device of the requested name or id is attached.
class DeviceNotFound : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// A backend knows the device that was asked for but cannot use it now: its driver loaded but found no
/// arm, the USB device refused access, a library on the way is damaged. The message names the backend's
/// reason and what to try. Unlike a name that no backend knows (DeviceNotFound), this is not a typing
/// error.
class DeviceUnavailable : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// The transport to the device failed: timeout, unplug, malformed packet stream.
class CommunicationError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// A safety limit tripped (force, velocity, watchdog, NaN command); forces were turned off.
class SafetyFault : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// The device must be calibrated (for a Phantom: put the stylus in the inkwell) before use.
class CalibrationNeeded : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// The realtime settings were required (`RealtimeMode::enforce`) and could not be applied; the message
/// names the setting and the system's reason (e.g. "SCHED_FIFO priority 80: Operation not permitted
/// (EPERM)"). Thrown by `ServoLoop::start`.
class RealtimeError : public DeviceError {
 public:
  using DeviceError::DeviceError;
};

/// A call in the wrong state, e.g. starting a servo loop that is already running.
class StateError : public Error {
 public:
  using Error::Error;
};

}  // namespace calligraphy
