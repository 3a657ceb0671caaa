// An application's own haptic device on the library's `ServoLoop`, linking `calligraphy::haptics` only.
//
// Implement `HapticDevice` (SI units; x right, y away from the writer, z up out of the paper); its
// `read_state` and `write_force` are the servo path: noexcept, no allocation, faults as `DeviceFault` codes.
// The `ServoLoop` calls the callback once per tick on its own thread, paced by the wall clock; its defaults
// ask for nothing (no SCHED_FIFO, no memory locking): this example asks for the thread's priority only.
// The callback is the `TrialSession`'s own (`servo_callback`), the one way to tick a trial from any loop; it
// carries the session's rate, which the loop checks at start.
//
// The device is a stand-in for hardware: a stylus resting 1 mm below the paper at the first stroke's start,
// its clock the machine's monotonic clock. A person would move it; here nobody does, so the run lasts
// 300 ms and shows the paper pushing back (eq. 9) and the loop's statistics.
#include <calligraphy/core/errors.hpp>
#include <calligraphy/devices/servo_loop.hpp>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/trial/session.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace {

using calligraphy::Vec3;

class RestingStylus final : public calligraphy::HapticDevice {
 public:
  explicit RestingStylus(const Vec3& position_m) : position_(position_m) {
    info_.model = "resting stylus (example)";
    info_.manufacturer = "an application";
    info_.max_force_n = 3.0;
    info_.max_continuous_force_n = 1.0;
    info_.max_stiffness_n_per_m = 1000.0;
    info_.max_damping_n_s_per_m = 5.0;
    info_.workspace_radius_m = 0.08;
    info_.workspace_size_m = Vec3(0.16, 0.12, 0.12);
  }

  const calligraphy::DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }
  void close() noexcept override {
    forces_ = false;
    open_ = false;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { forces_ = enabled; }
  bool forces_enabled() const override { return forces_; }

  calligraphy::DeviceFault read_state(calligraphy::DeviceState& state) noexcept override {
    if (!open_) return calligraphy::DeviceFault::not_open;
    state.position_m = position_;
    state.velocity_m_s = Vec3::Zero();
    // DeviceState::time_s: the device's own monotonic clock in seconds, any origin (here the machine's).
    state.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    return calligraphy::DeviceFault::none;
  }
  calligraphy::DeviceFault write_force(const Vec3& force_n) noexcept override {
    if (!open_) return calligraphy::DeviceFault::not_open;
    if (!force_n.allFinite()) {
      forces_ = false;
      return calligraphy::DeviceFault::non_finite_force;
    }
    last_force_ = forces_ ? force_n : Vec3::Zero();
    return calligraphy::DeviceFault::none;
  }

 private:
  calligraphy::DeviceInfo info_;
  Vec3 position_;
  Vec3 last_force_ = Vec3::Zero();
  bool open_ = false;
  bool forces_ = false;
};

}  // namespace

int main() {
  using namespace calligraphy;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  const auto& start = scene.characters.front().strokes.front().centre_line.points_m.front();
  RestingStylus device(Vec3(start.x(), start.y(), scene.layout.paper_z_m - 0.001));
  device.open();

  TrialOptions options;  // rate_hz 1000: the session and the loop tick at the same rate
  TrialSession session(scene, device.info(), options);
  session.reserve_trace();  // no allocation on the servo path after this

  ServoLoopOptions loop_options;  // the defaults change nothing process-wide: no mlockall
  loop_options.rate_hz = options.rate_hz;
  // The loop thread's own priority, when the system allows it (RealtimeMode::ignore runs on without it): a
  // thread of normal priority on a busy machine stalls for tens of ms.
  loop_options.priority = kDedicatedServoPriority;
  // This stand-in has no motors, so a stall holds no force against a hand: no stall bound (a real arm keeps
  // the default 50 ms, which ends the run with zero force).
  loop_options.stall_timeout_s = 0.0;
  // The session's own callback steps it and tells the loop its rate: start() refuses a loop at another rate
  // (a renderer built for 500 Hz and ticked by a 1 kHz loop would run its fades and filters twice as fast).
  ServoLoop loop(device, session.servo_callback(), loop_options);
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const LoopFault fault = loop.stop();
  const TrialResult result = session.finish(fault ? TrialEnd::device_fault : TrialEnd::time_limit, fault.message);
  double peak_paper_force_n = 0.0;
  for (const TrialSample& sample : result.trace) peak_paper_force_n = std::max(peak_paper_force_n, sample.force_n.z());

  const ServoLoopStats stats = loop.stats();
  std::printf("十 on a custom device: %llu ticks at %.0f Hz by its clock, %llu late; paper force up to %.2f N; "
              "SCHED_FIFO %s, memory locked %s\n",
              static_cast<unsigned long long>(stats.ticks), result.device_tick_rate_hz,
              static_cast<unsigned long long>(stats.late_ticks), peak_paper_force_n,
              stats.realtime.fifo_scheduling ? "yes" : "no", stats.realtime.memory_locked ? "yes" : "no");
  device.close();
  // A stylus 1 mm into the paper is pushed out (+z: K_en x 1 mm as the paper fades in), and the library asked
  // for nothing process-wide.
  return !fault && stats.ticks > 100 && peak_paper_force_n > 0.1 && !stats.realtime.memory_locked ? 0 : 1;
}
