#include "calligraphy/core/device_fault.hpp"

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

const char* device_fault_name(DeviceFault fault) noexcept {
  switch (fault) {
    case DeviceFault::none:
      return "none";
    case DeviceFault::not_open:
      return "not_open";
    case DeviceFault::link_lost:
      return "link_lost";
    case DeviceFault::no_valid_status:
      return "no_valid_status";
    case DeviceFault::driver_error:
      return "driver_error";
    case DeviceFault::watchdog:
      return "watchdog";
    case DeviceFault::non_finite_force:
      return "non_finite_force";
    case DeviceFault::safety_limit:
      return "safety_limit";
    case DeviceFault::not_advanced:
      return "not_advanced";
  }
  return "unknown";
}

const char* to_string(DeviceFault fault) noexcept {
  switch (fault) {
    case DeviceFault::none:
      return "no fault";
    case DeviceFault::not_open:
      return "read or write on a device that is not open";
    case DeviceFault::link_lost:
      return "link lost: the device was unplugged or a transfer failed; forces off, device closed";
    case DeviceFault::no_valid_status:
      return "no valid status packet in too many reads in a row (timeouts or rejected packets); forces "
             "off, device closed";
    case DeviceFault::driver_error:
      return "the device driver reported an error in its servo loop; forces off";
    case DeviceFault::watchdog:
      return "watchdog: no force command within its timeout; forces turned off";
    case DeviceFault::non_finite_force:
      return "non-finite force command (NaN or infinity); zero force sent, forces turned off";
    case DeviceFault::safety_limit:
      return "the device tripped a safety limit (force, impulse, velocity or motor temperature); forces "
             "turned off";
    case DeviceFault::not_advanced:
      return "simulated device read again without advance(): its time passes only when the program calls "
             "advance(dt_s) once per tick, after write_force; forces turned off";
  }
  return "unknown device fault";
}

std::string device_fault_message(DeviceFault fault, std::string_view device_name, std::string_view detail) {
  std::string message;
  if (!device_name.empty()) {
    message.append(device_name);
    message.append(": ");
  }
  message.append(to_string(fault));
  if (!detail.empty()) {
    message.append(" (");
    message.append(detail);
    message.append(")");
  }
  return message;
}

void throw_device_fault(DeviceFault fault, std::string_view device_name, std::string_view detail) {
  if (fault == DeviceFault::none) {
    throw InvalidArgument("throw_device_fault: DeviceFault::none is not a fault");
  }
  if (is_link_fault(fault)) throw CommunicationError(device_fault_message(fault, device_name, detail));
  throw SafetyFault(device_fault_message(fault, device_name, detail));
}

}  // namespace calligraphy
