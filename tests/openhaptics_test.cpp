// The OpenHaptics backend without libHD: error mapping, conversions, the "not found" path, and damaged
// libraries named by CALLIGRAPHY_LIBHD (the scheduler code runs against the stand-in libHD in
// openhaptics_standin_test.cpp).
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "devices/openhaptics/hd_conversions.hpp"
#include "devices/openhaptics/hd_errors.hpp"
#include "devices/openhaptics/hd_library.hpp"
#include "devices/openhaptics/openhaptics_device.hpp"
#include "devices/shared_library_check.hpp"

using namespace calligraphy::openhaptics;
using calligraphy::Vec3;

namespace {

// Sets CALLIGRAPHY_LIBHD for one scope.
class ScopedLibhdPath {
 public:
  /// nullptr unsets it.
  explicit ScopedLibhdPath(const char* value) {
    if (const char* old = std::getenv("CALLIGRAPHY_LIBHD")) previous_ = old;
    if (value == nullptr) {
      ::unsetenv("CALLIGRAPHY_LIBHD");
    } else {
      ::setenv("CALLIGRAPHY_LIBHD", value, 1);
    }
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

// The message of the `Failure` that loading libHD throws; empty when it throws nothing.
template <typename Failure>
std::string load_failure() {
  try {
    (void)HdLibrary::load();
  } catch (const Failure& e) {
    return e.what();
  }
  return {};
}

std::string not_found_message() { return load_failure<calligraphy::DeviceNotFound>(); }
// What loading says of a CALLIGRAPHY_LIBHD that is not a loadable libHD.
std::string unavailable_message() { return load_failure<calligraphy::DeviceUnavailable>(); }

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
    const ScopedLibhdPath path(nullptr);
    const std::string message = not_found_message();
    CHECK(message.find("OpenHaptics not found") != std::string::npos);
    CHECK(message.find("libHD.so.3.4") != std::string::npos);
    CHECK(message.find("/usr/lib/libHD.so") != std::string::npos);
    OpenHapticsDevice device;
    CHECK_THROWS_AS(device.open(), calligraphy::DeviceNotFound);
    CHECK_FALSE(device.is_open());
    calligraphy::DeviceState state;
    CHECK(device.read_state(state) == calligraphy::DeviceFault::not_open);
    CHECK(device.write_force(Vec3::Zero()) == calligraphy::DeviceFault::not_open);
    const auto survey = calligraphy::standard_device_registry().survey();
    bool noted = false;
    for (const auto& note : survey.notes)
      noted = noted || note.rfind("openhaptics: OpenHaptics not found", 0) == 0;
    CHECK(noted);
  }
  {
    // A path the user named is that path or nothing: its problem is the error, named.
    const ScopedLibhdPath path("/nonexistent/libHD.so");
    const std::string message = unavailable_message();
    CHECK(message.find("CALLIGRAPHY_LIBHD=/nonexistent/libHD.so") != std::string::npos);
    CHECK(message.find("No such file") != std::string::npos);
  }
  {
    // A library that loads but is not libHD is rejected by its missing symbols, not crashed on.
    const ScopedLibhdPath path("libm.so.6");
    CHECK(unavailable_message().find("libm.so.6 cannot be used: loaded, but lacks hdInitDevice") !=
          std::string::npos);
  }
}

TEST_CASE("A damaged CALLIGRAPHY_LIBHD is an error naming the path and why, never a crash or a hang",
          "[openhaptics]") {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("calligraphy-libhd-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  const auto write = [&](const char* name, const std::string& bytes) {
    const auto file = folder / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return file.string();
  };
  // The first bytes of a real shared object (this machine's libm), cut short: its segments point past
  // the end of the file, which is what makes dlopen fault with SIGBUS.
  std::string library_head;
  {
    std::ifstream libm("/lib/x86_64-linux-gnu/libm.so.6", std::ios::binary);
    library_head.assign(std::istreambuf_iterator<char>(libm), {});
    library_head.resize(std::min<std::size_t>(library_head.size(), 8192));
  }
  const std::string fifo = (folder / "fifo.so").string();
  ::mkfifo(fifo.c_str(), 0600);
  struct Case {
    std::string path;
    const char* why;
  };
  std::vector<Case> cases = {{folder.string(), "a directory"},
                             {write("empty.so", ""), "empty"},
                             {write("short.so", "not a library\n"), "too short"},
                             {write("text.so", std::string(200, 'x')), "not an ELF file"},
                             {fifo, "a FIFO"},
                             {"/dev/zero", "a character device"}};
  if (library_head.size() == 8192) cases.push_back({write("truncated.so", library_head), "truncated"});
  for (const Case& c : cases) {
    INFO(c.path);
    const ScopedLibhdPath path(c.path.c_str());
    const std::string message = unavailable_message();
    CHECK(message.find(c.path) != std::string::npos);
    CHECK(message.find(c.why) != std::string::npos);
    OpenHapticsDevice device;
    CHECK_THROWS_AS(device.open(), calligraphy::DeviceUnavailable);
  }
  std::filesystem::remove_all(folder);
}

TEST_CASE("The probe loads a library in a child process and reports a crash there", "[openhaptics]") {
  using calligraphy::devices::probe_shared_library;
  CHECK(probe_shared_library("libm.so.6", "cos").empty());
  CHECK(probe_shared_library("libm.so.6", "hdInitDevice") == "loaded, but lacks hdInitDevice");
  CHECK(probe_shared_library("/nonexistent/libHD.so", "hdInitDevice").find("No such file") !=
        std::string::npos);
  // A truncated shared object, past the checks that would refuse it: loading it is the child's problem.
  std::string library_head;
  {
    std::ifstream libm("/lib/x86_64-linux-gnu/libm.so.6", std::ios::binary);
    library_head.assign(std::istreambuf_iterator<char>(libm), {});
  }
  if (library_head.size() > 8192) {
    library_head.resize(8192);
    const auto file = std::filesystem::temp_directory_path() /
                      ("calligraphy-truncated-" + std::to_string(::getpid()) + ".so");
    std::ofstream(file, std::ios::binary) << library_head;
    const std::string outcome = probe_shared_library(file.string(), "cos");
    INFO(outcome);
    CHECK_FALSE(outcome.empty());
    std::filesystem::remove(file);
  }
}
