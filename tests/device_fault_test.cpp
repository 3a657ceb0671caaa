// The one taxonomy of device faults: every code has a name and a fixed message, and exactly one mapping
// turns a code into the typed exception (link faults CommunicationError, safety faults SafetyFault).
#include "calligraphy/core/device_fault.hpp"

#include <catch2/catch.hpp>
#include <cstring>
#include <iterator>
#include <set>
#include <string>

#include "calligraphy/core/errors.hpp"

using namespace calligraphy;

namespace {

constexpr DeviceFault kFaults[] = {DeviceFault::not_open,        DeviceFault::link_lost,
                                   DeviceFault::no_valid_status, DeviceFault::driver_error,
                                   DeviceFault::watchdog,        DeviceFault::non_finite_force,
                                   DeviceFault::safety_limit,    DeviceFault::not_advanced};
static_assert(std::size(kFaults) + 1 == kDeviceFaultCount);

}  // namespace

TEST_CASE("Every device fault code has a distinct name and a fixed message", "[device][fault]") {
  std::set<std::string> names{device_fault_name(DeviceFault::none)};
  std::set<std::string> messages{to_string(DeviceFault::none)};
  for (const DeviceFault fault : kFaults) {
    names.insert(device_fault_name(fault));
    messages.insert(to_string(fault));
    CHECK(std::strlen(to_string(fault)) > 10);
    // Static storage: the servo path hands out the pointer, never a copy.
    CHECK(to_string(fault) == to_string(fault));
  }
  CHECK(names.size() == kDeviceFaultCount);
  CHECK(messages.size() == kDeviceFaultCount);
  CHECK(std::string(device_fault_name(DeviceFault::link_lost)) == "link_lost");
  CHECK(std::string(to_string(DeviceFault::link_lost)).find("unplugged") != std::string::npos);
}

TEST_CASE("One mapping from fault codes to typed exceptions", "[device][fault]") {
  for (const DeviceFault fault : kFaults) {
    INFO(device_fault_name(fault));
    const std::string expected = device_fault_message(fault, "Touch", "at 1.5 s");
    CHECK(expected == std::string("Touch: ") + to_string(fault) + " (at 1.5 s)");
    try {
      throw_device_fault(fault, "Touch", "at 1.5 s");
      FAIL("throw_device_fault returned");
    } catch (const CommunicationError& e) {
      CHECK(is_link_fault(fault));
      CHECK(e.what() == expected);
    } catch (const SafetyFault& e) {
      CHECK_FALSE(is_link_fault(fault));
      CHECK(e.what() == expected);
    }
  }
  CHECK(device_fault_message(DeviceFault::watchdog, "") == to_string(DeviceFault::watchdog));
  CHECK(device_fault_message(DeviceFault::watchdog, "Omni") ==
        std::string("Omni: ") + to_string(DeviceFault::watchdog));
  CHECK_THROWS_AS(throw_device_fault(DeviceFault::none, "Touch"), InvalidArgument);
  // Both are DeviceErrors, so a caller that only cares that the device failed catches one type.
  CHECK_THROWS_AS(throw_device_fault(DeviceFault::non_finite_force, "Touch"), DeviceError);
}

TEST_CASE("kDeviceFaultCount counts the codes, and each code's name is its enumerator's", "[device][fault]") {
  // Every value below the count is a code with a name and a message (none of the switches' fallbacks), and
  // the value at the count is not a code: an enumerator added without raising the count fails here.
  for (std::size_t value = 0; value < kDeviceFaultCount; ++value) {
    const auto fault = static_cast<DeviceFault>(value);
    INFO(value);
    CHECK(std::string(device_fault_name(fault)) != "unknown");
    CHECK(std::string(to_string(fault)) != "unknown device fault");
  }
  CHECK(std::string(device_fault_name(static_cast<DeviceFault>(kDeviceFaultCount))) == "unknown");
  CHECK(std::string(device_fault_name(DeviceFault::not_advanced)) == "not_advanced");
  CHECK(is_link_fault(DeviceFault::not_advanced));  // a usage fault, thrown as CommunicationError
}
