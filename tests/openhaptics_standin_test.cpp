// The OpenHaptics backend end to end against a stand-in libHD written from the public HDAPI reference
// (tests/hd_stand_in: a scheduler thread, frame rules, an error stack, calibration states, nominal limits,
// a hand that plays back a pen path, fault injection). Open, calibrate, a whole trial, faults and close.
// The stand-in's frame log says, per servo tick, which position it reported and which force it was given
// in that tick's frame: that is what shows the force answering the position of the same frame.
#include <dlfcn.h>
#include <stdlib.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/trial/runner.hpp"
#include "devices/standard_backends.hpp"
#include "devices/openhaptics/openhaptics_device.hpp"
#include "hd_stand_in_control.h"

using namespace calligraphy;
using calligraphy::openhaptics::OpenHapticsDevice;

namespace {

constexpr unsigned kCommConfigError = 0x0303;    // HD_COMM_CONFIG_ERROR (hdDefines.h)
constexpr unsigned kCalibrationManual = 0x5002;  // HD_CALIBRATION_NEEDS_MANUAL_INPUT
constexpr unsigned kCalibrationNeedsUpdate = 0x5001;
constexpr int kStyleAuto = 2, kStyleInkwell = 4;

// The stand-in's control API, from the same libHD.so the backend loads (CALLIGRAPHY_LIBHD).
struct StandIn {
  void* handle = nullptr;
  template <typename F>
  F get(const char* name) {
    void* symbol = dlsym(handle, name);
    if (symbol == nullptr) FAIL("the stand-in lacks " << name);
    return reinterpret_cast<F>(symbol);
  }
  StandIn() {
    ::setenv("CALLIGRAPHY_LIBHD", CALLIGRAPHY_HD_STAND_IN, 1);
    handle = dlopen(CALLIGRAPHY_HD_STAND_IN, RTLD_NOW | RTLD_LOCAL);
    REQUIRE(handle != nullptr);
    reset = get<decltype(reset)>("hd_stand_in_reset");
    configure_log = get<decltype(configure_log)>("hd_stand_in_configure_log");
    set_path = get<decltype(set_path)>("hd_stand_in_set_path");
    set_square_wave = get<decltype(set_square_wave)>("hd_stand_in_set_square_wave");
    set_calibration = get<decltype(set_calibration)>("hd_stand_in_set_calibration");
    set_docked = get<decltype(set_docked)>("hd_stand_in_set_docked");
    inject = get<decltype(inject)>("hd_stand_in_inject");
    fail_init = get<decltype(fail_init)>("hd_stand_in_fail_init");
    frame_count = get<decltype(frame_count)>("hd_stand_in_frame_count");
    frame = get<decltype(frame)>("hd_stand_in_frame");
    violations = get<decltype(violations)>("hd_stand_in_violations");
    ticks = get<decltype(ticks)>("hd_stand_in_ticks");
    wait_ticks = get<decltype(wait_ticks)>("hd_stand_in_wait_ticks");
    reset();
    configure_log(1 << 17);
  }
  ~StandIn() {
    reset();
    dlclose(handle);
  }
  [[nodiscard]] std::vector<hd_stand_in_frame_record> log() const {
    std::vector<hd_stand_in_frame_record> records(frame_count());
    for (std::size_t i = 0; i < records.size(); ++i) frame(i, &records[i]);
    return records;
  }

  int (*reset)() = nullptr;
  int (*configure_log)(size_t) = nullptr;
  int (*set_path)(const double*, const double*, size_t) = nullptr;
  void (*set_square_wave)(int, double, int) = nullptr;
  void (*set_calibration)(unsigned, int) = nullptr;
  void (*set_docked)(int) = nullptr;
  int (*inject)(int, long, double) = nullptr;
  void (*fail_init)(unsigned) = nullptr;
  size_t (*frame_count)() = nullptr;
  int (*frame)(size_t, hd_stand_in_frame_record*) = nullptr;
  long (*violations)() = nullptr;
  long (*ticks)() = nullptr;
  int (*wait_ticks)(long, double) = nullptr;
};

// HDAPI's frame (x right, y up, z towards the user, mm) from the library's (x right, y away, z up, m),
// written here from the two definitions rather than taken from the backend.
Vec3 hd_mm(const Vec3& device_m) { return Vec3(device_m.x(), device_m.z(), -device_m.y()) * 1000.0; }
Vec3 device_m(const double* hd) { return Vec3(hd[0], -hd[2], hd[1]) / 1000.0; }

// A pen that writes every stroke of `scene` along the data's medians at 40 mm/s, 1 mm into the paper,
// lifting 5 mm between strokes, after resting 0.3 s above the first stroke's start.
struct PenPath {
  std::vector<double> t_s;
  std::vector<double> xyz_mm;
  void add(double t, const Vec3& device_position_m) {
    t_s.push_back(t);
    const Vec3 p = hd_mm(device_position_m);
    xyz_mm.insert(xyz_mm.end(), {p.x(), p.y(), p.z()});
  }
};

PenPath writing_path(const Scene& scene) {
  constexpr double kSpeed = 0.04, kDown = -0.001, kUp = 0.005, kMove = 0.15;
  PenPath path;
  double t = 0.0;
  bool first = true;
  for (const auto& character : scene.characters) {
    for (const auto& stroke : character.strokes) {
      const auto& median = stroke.median_m;
      const Vec2 start = median.front();
      if (first) {
        path.add(t, Vec3(start.x(), start.y(), kUp));
        t += 0.3;
        first = false;
      } else {
        t += kMove;
      }
      path.add(t, Vec3(start.x(), start.y(), kUp));
      t += 0.05;
      path.add(t, Vec3(start.x(), start.y(), kDown));
      for (std::size_t i = 1; i < median.size(); ++i) {
        t += (median[i] - median[i - 1]).norm() / kSpeed;
        path.add(t, Vec3(median[i].x(), median[i].y(), kDown));
      }
      t += 0.05;
      path.add(t, Vec3(median.back().x(), median.back().y(), kUp));
    }
  }
  return path;
}

TrialOptions stand_in_trial_options() {
  TrialOptions options;
  options.pacing = TrialPacing::real_time;
  options.max_duration_s = 40.0;
  options.loop.lock_memory = false;
  options.loop.max_force_age_s = 0.01;  // a sanitized build is slower; the bound still applies
  return options;
}

}  // namespace

TEST_CASE("OpenHaptics on the stand-in: open reads the nominal limits, calibrates, closes",
          "[servo][openhaptics]") {
  StandIn stand_in;
  SECTION("calibrated at open") {
    OpenHapticsDevice device;
    device.open();
    CHECK(device.is_open());
    CHECK(device.is_calibrated());
    CHECK(device.info().max_force_n == Approx(3.3));
    CHECK(device.info().max_stiffness_n_per_m == Approx(1020.0));
    CHECK(device.servo_clock() != nullptr);
    CHECK(device.servo_rate_hz() == 1000.0);
    device.close();
    CHECK_FALSE(device.is_open());
  }
  SECTION("an update is made with the automatic style") {
    stand_in.set_calibration(kCalibrationNeedsUpdate, kStyleAuto | kStyleInkwell);
    OpenHapticsDevice device;
    device.open();
    CHECK_FALSE(device.is_calibrated());
    device.calibrate();
    CHECK(device.is_calibrated());
  }
  SECTION("the inkwell is named when the device needs it") {
    stand_in.set_calibration(kCalibrationManual, kStyleInkwell);
    OpenHapticsDevice device;
    device.open();
    CHECK_THROWS_AS(device.calibrate(), CalibrationNeeded);
    CHECK_THROWS_WITH(device.calibrate(), Catch::Contains("inkwell"));
    CHECK_THROWS_AS(device.enable_forces(true), CalibrationNeeded);
  }
  CHECK(stand_in.violations() == 0);
}

TEST_CASE("OpenHaptics on the stand-in: a device that cannot initialise is named with its reason",
          "[servo][openhaptics]") {
  StandIn stand_in;
  stand_in.fail_init(kCommConfigError);
  OpenHapticsDevice device;
  CHECK_THROWS_AS(device.open(), DeviceUnavailable);
  CHECK_THROWS_WITH(device.open(), Catch::Contains("HD_COMM_CONFIG_ERROR") && Catch::Contains("plugged in"));
  DeviceRegistry registry;
  openhaptics::register_backend(registry);
  CHECK_THROWS_AS(registry.find("openhaptics"), DeviceUnavailable);
  CHECK_THROWS_WITH(registry.find("openhaptics"), Catch::Contains("HD_COMM_CONFIG_ERROR"));
  stand_in.fail_init(0);
  const DeviceListing listing = registry.find("openhaptics");
  CHECK(listing.capabilities.hardware);
  CHECK(listing.capabilities.needs_calibration);
  CHECK_FALSE(listing.capabilities.moved_by_simulated_hand);
  CHECK_FALSE(listing.limits_known);
}

TEST_CASE("OpenHaptics on the stand-in: each tick runs in the HD frame that read its position",
          "[servo][openhaptics]") {
  StandIn stand_in;
  stand_in.set_square_wave(0, 1.0, 7);  // 1 mm steps in x every 7 frames
  OpenHapticsDevice device;
  device.open();
  constexpr double kStiffness = 500.0;  // N/m, towards the workspace centre
  ServoLoopOptions options;
  options.lock_memory = false;
  options.max_force_age_s = 0.01;
  ServoLoop loop(
      device,
      [](const DeviceState& state, double) {
        return ServoCommand{-kStiffness * state.position_m, false};
      },
      options);
  loop.start();
  REQUIRE(stand_in.wait_ticks(stand_in.ticks() + 400, 10.0) == 1);
  CHECK_FALSE(loop.stop());
  device.close();
  // Each frame that sent a force: whether it was -k times the position that frame reported.
  std::vector<bool> matched;
  std::vector<bool> zero;
  long steps = 0;
  const auto log = stand_in.log();
  for (std::size_t i = 1; i < log.size(); ++i) {
    const auto& f = log[i];
    if (!f.force_set || !f.force_output) continue;
    const Vec3 expected = hd_mm(-kStiffness * device_m(f.position_mm)) / 1000.0;  // N, HD axes
    const Vec3 sent(f.force_output_n[0], f.force_output_n[1], f.force_output_n[2]);
    matched.push_back((sent - expected).norm() < 1e-9);
    zero.push_back(sent.norm() == 0.0);
    if (f.position_mm[0] != log[i - 1].position_mm[0]) ++steps;
  }
  // A frame may send zero (the stop at the end; a force withheld as too old when the machine is loaded,
  // max_force_age_s), but every force it sends is the one computed from that frame's own position.
  long sent_forces = 0, same_frame = 0, zeros = 0;
  for (std::size_t k = 0; k < matched.size(); ++k) {
    if (zero[k] && !matched[k]) {
      ++zeros;
      continue;
    }
    ++sent_forces;
    same_frame += matched[k] ? 1 : 0;
  }
  INFO("frames " << matched.size() << ", forces sent " << sent_forces << ", of their own frame " << same_frame
                 << ", zero " << zeros << ", steps " << steps);
  CHECK(same_frame > 300);
  CHECK(steps > 30);
  CHECK(same_frame == sent_forces);
  CHECK(stand_in.violations() == 0);
}

TEST_CASE(
    "OpenHaptics on the stand-in: a whole trial on the HD clock, times from 0, forces of their own frame",
    "[servo][openhaptics]") {
  StandIn stand_in;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'永')});
  const PenPath path = writing_path(scene);
  OpenHapticsDevice device;
  device.open();  // the path starts with the scheduler's next tick: the pen rests before the strokes
  REQUIRE(stand_in.set_path(path.t_s.data(), path.xyz_mm.data(), path.t_s.size()) == 0);
  const TrialResult result = run_trial(device, scene, stand_in_trial_options());
  INFO("end " << to_string(result.end) << ": " << result.abort_reason);
  CHECK(result.end == TrialEnd::completed);
  CHECK(result.metrics.strokes_completed == 5);
  REQUIRE_FALSE(result.trace.empty());
  CHECK(result.trace.front().time_s == 0.0);
  // The trial's clock, not the stand-in's (1600 s and more); longer than the path on a loaded machine,
  // whose hand keeps its own ticks' time.
  CHECK(result.metrics.time_s < 2.0 * path.t_s.back() + 5.0);
  CHECK(result.device_time_at_start_s > 100.0);  // the stand-in's clock is not the trial's
  REQUIRE(result.loop);
  CHECK(result.loop->realtime.device_clock);

  // The recorded ticks are a run of the stand-in's frames: find where the trial's first tick sits in its
  // log (the pen moves, so the positions place it), then compare forces. Had the force been computed a
  // frame before it was sent, a frame's force would be the previous tick's.
  const auto log = stand_in.log();
  const auto position_of = [&](std::size_t frame) { return device_m(log[frame].position_mm); };
  const std::size_t n = result.trace.size();
  std::size_t offset = log.size();
  for (std::size_t k = 0; k + n <= log.size() && offset == log.size(); ++k) {
    std::size_t i = 0;
    while (i < n && (position_of(k + i) - result.trace[i].position_m).norm() < 1e-12) ++i;
    if (i == n) offset = k;
  }
  REQUIRE(offset < log.size());
  long with_force = 0, same_frame = 0, previous_frame = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const Vec3 commanded = hd_mm(result.trace[i].force_n) / 1000.0;
    const Vec3 before = hd_mm(result.trace[i - 1].force_n) / 1000.0;
    if (commanded.norm() == 0.0 || (commanded - before).norm() < 1e-6) continue;  // tells nothing apart
    ++with_force;
    const double* set = log[offset + i].force_set_n;
    const Vec3 sent(set[0], set[1], set[2]);
    if ((sent - commanded).norm() < 1e-9) ++same_frame;
    if ((sent - before).norm() < 1e-9) ++previous_frame;
  }
  INFO("ticks with a changing force " << with_force << ": sent in their frame " << same_frame
                                      << ", a frame late " << previous_frame);
  CHECK(with_force > 500);
  CHECK(same_frame >= with_force - 1);  // the last tick's force is zeroed when the run ends
  CHECK(previous_frame == 0);
  CHECK(stand_in.violations() == 0);
}

TEST_CASE("OpenHaptics on the stand-in: a link lost mid-trial ends it with zero force and the trace kept",
          "[servo][openhaptics]") {
  StandIn stand_in;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'永')});
  const PenPath path = writing_path(scene);
  OpenHapticsDevice device;
  device.open();
  REQUIRE(stand_in.set_path(path.t_s.data(), path.xyz_mm.data(), path.t_s.size()) == 0);
  const long fault_tick = stand_in.ticks() + 1500;
  REQUIRE(stand_in.inject(HD_STAND_IN_FAULT_LINK_LOST, fault_tick, 0.0) == 0);
  const TrialResult result = run_trial(device, scene, stand_in_trial_options());
  CHECK(result.end == TrialEnd::device_fault);
  CHECK(result.aborted);
  CHECK(result.device_fault == DeviceFault::driver_error);
  CHECK(result.abort_reason.find("driver") != std::string::npos);
  CHECK(result.trace.size() > 1000);  // every tick before the fault kept
  CHECK(result.trace.size() < 1600);
  long commanded_after_fault = 0;  // what the backend itself set, whatever the stand-in then sent
  for (const auto& f : stand_in.log()) {
    if (f.tick >= fault_tick && std::hypot(f.force_set_n[0], f.force_set_n[1], f.force_set_n[2]) > 0.0)
      ++commanded_after_fault;
  }
  CHECK(commanded_after_fault == 0);
  CHECK(stand_in.violations() == 0);
}

TEST_CASE("OpenHaptics on the stand-in: a slow HD frame ends the trial on the stall bound",
          "[servo][openhaptics]") {
  StandIn stand_in;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  OpenHapticsDevice device;
  device.open();
  REQUIRE(stand_in.inject(HD_STAND_IN_FAULT_SLOW_FRAME, stand_in.ticks() + 300, 120.0) == 0);
  TrialOptions options = stand_in_trial_options();
  options.loop.stall_timeout_s = 0.05;
  const TrialResult result = run_trial(device, scene, options);
  CHECK(result.end == TrialEnd::watchdog);
  CHECK(result.trace.size() > 200);
  CHECK_FALSE(device.is_open());
}
