// hd_stand_in_state.h - internal state shared by the stand-in's source files.
//
// Threading model:
//  * `Servo` is touched only by the servo thread (and by start/stop/reset
//    after the thread has been joined), so it needs no lock.
//  * Everything a test or client thread may touch concurrently is either an
//    atomic or guarded by one of the mutexes below. No two of these mutexes
//    are ever held at the same time, so there is no lock order to respect.
//  * The servo thread takes each mutex only for a few copies per tick and
//    never allocates once running.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#pragma GCC visibility push(default)
#include "hd_stand_in_control.h"
#include "hd_stand_in_hdapi.h"
#pragma GCC visibility pop

namespace hdsi {

// ---- limits --------------------------------------------------------------
inline constexpr int kErrorStackCap = 32;
inline constexpr int kMaxCallbacks = 32;
inline constexpr int kMaxFaults = 64;
inline constexpr int kViolationKinds = 9;  // index 0 unused
inline constexpr std::size_t kDefaultLogCapacity = 32768;
inline constexpr HHD kDeviceHandle = 0;
inline constexpr HDSchedulerHandle kInvalidSchedulerHandle = HD_INVALID_HANDLE;
inline constexpr const char* kDefaultDeviceName = "Default Device";

// ---- nominal facts of a 3D Systems Touch (see README for the source) -----
inline constexpr double kMaxForceN = 3.3;
inline constexpr double kMaxContinuousForceN = 0.88;
inline constexpr double kMaxStiffnessNPerMm = 1.02;  // weakest axis (Z)
inline constexpr double kMaxDampingNsPerMm = 0.003;  // assumed, not a spec value
inline constexpr std::array<double, 6> kUsableWorkspaceMm{-80.0, -60.0, -35.0, 80.0, 60.0, 35.0};

using Vec3 = std::array<double, 3>;

// State a frame reports. The servo thread owns the live copy; a copy is
// published under log_mu at the end of every tick for off-thread readers.
struct FrameView {
  Vec3 pos{};
  Vec3 vel{};
  Vec3 last_pos{};
  Vec3 last_vel{};
  Vec3 force{};  // HD_CURRENT_FORCE as set so far in this tick
  int buttons = 0;
  int last_buttons = 0;
  int ink = 0;
  int last_ink = 0;
};

struct Servo {
  FrameView view{};
  bool have_prev = false;
  // hand playback
  unsigned long path_epoch_seen = 0;
  unsigned long wave_epoch_seen = 0;
  double path_time_s = 0.0;
  long wave_ticks = 0;
  // the tick being run
  long tick = 0;
  std::int64_t start_ns = 0;
  long late_us = 0;
  bool frame_open = false;
  int frames_done = 0;
  bool position_read = false;
  bool force_set = false;
  bool output = false;
  Vec3 out{};
  bool force_limit_pending = false;
  HDerror first_error = HD_SUCCESS;
  int error_count = 0;
};

struct Fault {
  bool used = false;
  int kind = 0;
  long tick = 0;
  double value = 0.0;
  int remaining = 0;
};

struct Callback {
  bool used = false;
  bool sync = false;
  HDSchedulerHandle handle = 0;
  HDSchedulerCallback fn = nullptr;
  void* data = nullptr;
  HDushort priority = 0;
  unsigned long seq = 0;
};

struct Lib {
  Lib();

  // -- error stack (err_mu) --
  std::mutex err_mu;
  std::array<HDErrorInfo, kErrorStackCap> errors{};
  int err_count = 0;  // entries [0, err_count), most recent last

  // -- device (atomics) --
  std::atomic<bool> initialized{false};
  std::atomic<HHD> current{HD_INVALID_HANDLE};
  std::atomic<bool> force_output{false};
  std::atomic<bool> clamping{false};
  std::atomic<bool> ramping{false};
  std::atomic<bool> software_force_limit{false};
  std::atomic<bool> one_frame_limit{false};
  std::atomic<bool> force_output_at_init{false};
  std::atomic<double> velocity_limit{0.0};
  std::atomic<double> impulse_limit{0.0};
  std::atomic<double> ramping_rate{0.0};
  std::atomic<int> status_light{0};
  std::atomic<HDenum> cal_state{HD_CALIBRATION_OK};
  std::atomic<int> cal_styles{HD_CALIBRATION_AUTO | HD_CALIBRATION_INKWELL};
  std::atomic<HDerror> fail_init{HD_SUCCESS};
  std::atomic<int> fail_init_fault{0};
  std::atomic<bool> link_lost{false};
  std::atomic<bool> strict_one_frame{false};

  // -- hand inputs read each tick --
  std::atomic<int> buttons{0};
  std::atomic<bool> docked{false};
  std::atomic<bool> docked_reads_one{false};
  std::atomic<double> clock_offset_s{1600.0};

  // -- configuration guarded by state_mu --
  std::mutex state_mu;
  std::string device_name{kDefaultDeviceName};
  std::vector<double> path_t;
  std::vector<double> path_xyz;
  unsigned long path_epoch = 1;
  int wave_axis = 0;
  double wave_amp_mm = 0.0;
  int wave_half = 0;
  unsigned long wave_epoch = 1;
  std::array<Fault, kMaxFaults> faults{};

  // -- scheduler --
  std::mutex life_mu;  // serialises start / stop / reset
  std::mutex sched_mu;
  std::condition_variable sched_cv;
  std::array<Callback, kMaxCallbacks> callbacks{};
  HDSchedulerHandle next_handle = 1;
  unsigned long next_seq = 0;
  HDSchedulerHandle running_cb = 0;
  int waiters = 0;
  std::thread thread;
  std::atomic<bool> running{false};
  std::atomic<bool> stop{false};
  std::atomic<unsigned long> rate_hz{1000};
  std::atomic<double> instantaneous_rate{0.0};
  std::atomic<std::int64_t> tick_start_ns{0};
  std::atomic<long> ticks{0};

  // -- frame log and published state (log_mu) --
  std::mutex log_mu;
  std::vector<hd_stand_in_frame_record> ring;
  FrameView published{};

  // -- violations --
  std::array<std::atomic<long>, kViolationKinds> violations{};

  // -- servo-thread-only --
  Servo servo{};
};

Lib& lib();

// Misbehaviours of a hostile driver, set from the environment when the library loads
// (hd_stand_in_environment.cpp), for tests of a caller that must survive them.
enum class InitMisbehaviour { none, crash, hang, exit };
struct EnvironmentFaults {
  InitMisbehaviour init = InitMisbehaviour::none;  // in hdInitDevice
  int exit_status = 0;                             // for InitMisbehaviour::exit
  bool scheduler_stalled = false;                  // hdStartScheduler succeeds, no tick ever runs
  bool stop_hangs = false;                         // hdStopScheduler never returns
};
const EnvironmentFaults& environment_faults();
extern thread_local bool tl_on_servo;

std::int64_t mono_ns();
double device_time_s(std::int64_t mono);

void push_error(HDerror code, int internal);
void violation(int kind, HDerror code);
bool require_device();  // pushes HD_BAD_HANDLE when no initialised current device

// Scheduler internals used by the control API.
void stop_scheduler_internal();
void clear_callbacks();
int scheduled_count();

}  // namespace hdsi
