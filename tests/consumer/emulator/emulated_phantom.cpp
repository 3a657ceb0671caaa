// Opens the emulated Phantom (the mock that speaks the real packet protocol) from the installed package and
// reads one state: an application's test of its own device code would start here.
#include "calligraphy/testing/emulated_phantom.hpp"

#include <cstdio>

#include "calligraphy/devices/device_registry.hpp"

int main() {
  calligraphy::DeviceRegistry registry;
  calligraphy::testing::register_emulated_phantom(registry);
  const auto device = registry.create("emulated-phantom");
  device->open();
  calligraphy::DeviceState state;
  const calligraphy::DeviceFault fault = device->read_state(state);
  device->close();
  std::printf("emulated-phantom: %s, read %s\n", device->info().model.c_str(), to_string(fault));
  return fault == calligraphy::DeviceFault::none ? 0 : 1;
}
