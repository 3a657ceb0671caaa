// Must not compile: a servo callback that returns a bare force instead of a ServoCommand. The build stops at
// ServoLoop's own static_assert, with a message saying what to return, and nothing after it
// (tests/compile_fail/check_refused.cmake checks both).
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"

int main() {
  calligraphy::SimulatedDevice device;
  calligraphy::ServoLoop loop(device, [](const calligraphy::DeviceState&, double) { return calligraphy::Vec3::Zero().eval(); });
  return 0;
}
