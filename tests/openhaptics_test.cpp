// The OpenHaptics backend without libHD (none is installed here): error mapping, conversions and the
// "not found" path. The scheduler code itself is untested.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <optional>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "devices/openhaptics/hd_conversions.hpp"
#include "devices/openhaptics/hd_errors.hpp"
#include "devices/openhaptics/hd_library.hpp"
#include "devices/openhaptics/openhaptics_device.hpp"

using namespace calligraphy::openhaptics;
using calligraphy::Vec3;

namespace {

// Sets CALLIGRAPHY_LIBHD for one scope.
class ScopedLibhdPath {
 public:
  explicit ScopedLibhdPath(const char* value) {
    if (const char* old = std::getenv("CALLIGRAPHY_LIBHD")) previous_ = old;
    ::setenv("CALLIGRAPHY_LIBHD", value, 1);
  }
  ~ScopedLibhdPath() {
    if (previous_) {
      ::setenv("CALLIGRAPHY_LIBHD", previous_->c_str(), 1);
    } else {
      ::unsetenv("CALLIGRAPHY_LIBHD");
    }
  }

 private:
  std::optional<std::string> previous_;
};

std::string not_found_message() {
  try {
    (void)HdLibrary::load();
  } catch (const calligraphy::DeviceNotFound& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST_CASE("HD error codes map onto the exception hierarchy", "[openhaptics]") {
  using namespace calligraphy::openhaptics::hd;
  CHECK(classify_hd_error(HD_SUCCESS) == HdErrorKind::none);
  CHECK(classify_hd_error(HD_COMM_ERROR) == HdErrorKind::communication);
  CHECK(classify_hd_error(HD_COMM_CONFIG_ERROR) == HdErrorKind::communication);
  CHECK(classify_hd_error(HD_TIMER_ERROR) == HdErrorKind::communication);
  for (const HDerror code : {HD_WARM_MOTORS, HD_EXCEEDED_MAX_FORCE, HD_EXCEEDED_MAX_FORCE_IMPULSE,
                             HD_EXCEEDED_MAX_VELOCITY, HD_FORCE_ERROR}) {
    CHECK(classify_hd_error(code) == HdErrorKind::safety);
    CHECK_THROWS_AS(throw_hd_error({code, 0, 0}, "test"), calligraphy::SafetyFault);
    // The servo path gets a code; off it, the one mapping gives the same exception type.
    CHECK(hd_servo_fault(code) == calligraphy::DeviceFault::safety_limit);
    CHECK_THROWS_AS(calligraphy::throw_device_fault(hd_servo_fault(code), "test"), calligraphy::SafetyFault);
  }
  for (const HDerror code :
       {HD_COMM_ERROR, HD_TIMER_ERROR, HD_DEVICE_FAULT, HD_ILLEGAL_END, HDerror{0x7777}}) {
    CHECK(hd_servo_fault(code) == calligraphy::DeviceFault::driver_error);
    CHECK_THROWS_AS(calligraphy::throw_device_fault(hd_servo_fault(code), "test"),
                    calligraphy::CommunicationError);
  }
  CHECK(hd_servo_fault(HD_SUCCESS) == calligraphy::DeviceFault::none);
  CHECK(classify_hd_error(HD_ILLEGAL_END) == HdErrorKind::usage);
  CHECK(classify_hd_error(HD_INVALID_LICENSE) == HdErrorKind::setup);
  CHECK(classify_hd_error(0x7777) == HdErrorKind::setup);
  CHECK(std::string(hd_error_name(HD_EXCEEDED_MAX_FORCE_IMPULSE)) == "HD_EXCEEDED_MAX_FORCE_IMPULSE");
  CHECK(std::string(hd_error_name(0x7777)) == "HD_UNKNOWN_ERROR");

  CHECK_THROWS_AS(throw_hd_error({HD_COMM_ERROR, 5, 0}, "reading"), calligraphy::CommunicationError);
  CHECK_THROWS_WITH(throw_hd_error({HD_COMM_ERROR, 5, 0}, "reading"), Catch::Contains("reading") &&
                                                                          Catch::Contains("HD_COMM_ERROR") &&
                                                                          Catch::Contains("internal 5"));
  CHECK_THROWS_AS(throw_hd_error({HD_INVALID_LICENSE, 0, 0}, "init"), calligraphy::DeviceError);
  // The servo path gets only driver_error or safety_limit: CommunicationError or SafetyFault off it.
  CHECK(hd_servo_fault(HD_ILLEGAL_BEGIN) == calligraphy::DeviceFault::driver_error);
  CHECK(hd_servo_fault(HD_INVALID_LICENSE) == calligraphy::DeviceFault::driver_error);
}

TEST_CASE("HD millimetres and axes convert to device metres, forces map back power-consistently",
          "[openhaptics]") {
  CHECK((hd_mm_to_device_m({10.0, 20.0, 30.0}) - Vec3(0.010, -0.030, 0.020)).norm() < 1e-15);
  // Power is frame-independent: F.v in device axes equals F.v in HD axes.
  const Vec3 force(0.3, -1.2, 2.0);
  const std::array<double, 3> velocity_hd{15.0, -7.0, 4.0};  // mm/s
  const Vec3 velocity = hd_mm_to_device_m(velocity_hd);      // m/s
  const auto force_hd = device_force_to_hd(force);
  const double power_hd =
      1e-3 * (force_hd[0] * velocity_hd[0] + force_hd[1] * velocity_hd[1] + force_hd[2] * velocity_hd[2]);
  CHECK(force.dot(velocity) == Approx(power_hd));
  // Up in the library (z) is up in HD (y).
  CHECK(device_force_to_hd(Vec3::UnitZ())[1] == 1.0);

  const auto info = info_from_hd_nominals("Touch", "3D Systems", 3.3, 0.88, 0.4, 0.004,
                                          {-80.0, -60.0, -35.0, 80.0, 60.0, 35.0});
  CHECK(info.max_stiffness_n_per_m == Approx(400.0));
  CHECK(info.max_damping_n_s_per_m == Approx(4.0));
  CHECK((info.workspace_size_m - Vec3(0.16, 0.07, 0.12)).norm() < 1e-12);
  CHECK(info.workspace_radius_m == Approx(0.035));
  CHECK(info_from_hd_nominals(nullptr, "", 1, 1, 1, 1, {}).model == "OpenHaptics device");
}

TEST_CASE("Without libHD: DeviceNotFound 'OpenHaptics not found' listing the paths tried", "[openhaptics]") {
  {
    const ScopedLibhdPath path("/nonexistent/libHD.so");
    const std::string message = not_found_message();
    CHECK(message.find("OpenHaptics not found") != std::string::npos);
    CHECK(message.find("/nonexistent/libHD.so") != std::string::npos);
    CHECK(message.find("libHD.so.3.4") != std::string::npos);
    CHECK(message.find("/usr/lib/libHD.so") != std::string::npos);
    OpenHapticsDevice device;
    CHECK_THROWS_AS(device.open(), calligraphy::DeviceNotFound);
    CHECK_FALSE(device.is_open());
    calligraphy::DeviceState state;
    CHECK(device.read_state(state) == calligraphy::DeviceFault::not_open);
    CHECK(device.write_force(Vec3::Zero()) == calligraphy::DeviceFault::not_open);
  }
  {
    // A library that loads but is not libHD is rejected by its missing symbols, not crashed on.
    const ScopedLibhdPath path("libm.so.6");
    CHECK(not_found_message().find("libm.so.6: loaded, but lacks hdInitDevice") != std::string::npos);
  }
  const auto survey = calligraphy::device_registry().survey();
  bool noted = false;
  for (const auto& note : survey.notes)
    noted = noted || note.rfind("openhaptics: OpenHaptics not found", 0) == 0;
  CHECK(noted);
}
