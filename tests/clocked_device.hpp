#pragma once
// A device whose "driver" owns the servo thread, as OpenHaptics' scheduler does: each frame it sets the
// pen position (a square wave in x, so a test can tell frames apart), calls the attached frame function,
// then sends the force the frame set and logs both. The log shows in which frame a force answered a
// position. The driver can be paused (it stops calling: a dead scheduler) and can fail one frame's read.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "calligraphy/devices/device_servo_clock.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy::test {

class ClockedDevice final : public HapticDevice, public DeviceServoClock {
 public:
  struct Frame {
    double position_x_m = 0.0;
    double force_x_n = 0.0;
    bool force_set = false;
  };
  static constexpr double kStepM = 0.001;  ///< the square wave's amplitude [m]
  static constexpr int kHalfPeriod = 7;    ///< frames per half period of the square wave

  explicit ClockedDevice(double rate_hz = 1000.0, std::size_t max_frames = 20000) : rate_hz_(rate_hz) {
    log_.resize(max_frames);
    info_.model = "clocked test device";
    info_.max_force_n = 5.0;
    info_.max_continuous_force_n = 1.0;
    info_.max_stiffness_n_per_m = 1000.0;
  }
  ~ClockedDevice() override { close(); }

  const DeviceInfo& info() const override { return info_; }
  void open() override {
    if (open_) return;
    open_ = true;
    quit_.store(false);
    driver_ = std::thread([this] { drive(); });
  }
  void close() noexcept override {
    if (!open_) return;
    quit_.store(true);
    driver_.join();
    open_ = false;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { forces_.store(enabled); }
  bool forces_enabled() const override { return forces_.load(); }

  DeviceFault read_state(DeviceState& state) noexcept override {
    if (!in_frame_) return DeviceFault::not_open;  // this test device is only read inside its frames
    if (frames_.load() == fail_frame_) {
      forces_.store(false);
      return DeviceFault::link_lost;
    }
    state = frame_state_;
    return DeviceFault::none;
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    if (in_frame_) {
      frame_force_ = force_n;
      force_set_ = true;
    }
    return DeviceFault::none;
  }

  DeviceServoClock* servo_clock() noexcept override { return this; }
  double servo_rate_hz() const noexcept override { return rate_hz_; }
  void attach(FrameFunction frame, void* context) override {
    context_.store(context);
    frame_.store(frame);
  }
  void detach() noexcept override {
    frame_.store(nullptr);
    while (busy_.load()) std::this_thread::yield();
  }

  /// The driver's clock advances this much per frame [s] (default one period): more than a period is a
  /// loop whose ticks came late by the device's clock, whatever the wall clock did. Before open().
  void set_time_per_frame_s(double time_s) { time_per_frame_s_ = time_s; }
  /// Stops calling frame functions (a driver whose scheduler died) or resumes.
  void pause(bool paused) { paused_.store(paused); }
  /// The 0-based frame (counted since open) whose read fails with link_lost.
  void fail_at_frame(long frame) { fail_frame_ = frame; }
  /// Frames run so far; the log of the first `frames()` (at most max_frames) is complete after close().
  [[nodiscard]] long frames() const { return frames_.load(); }
  [[nodiscard]] const std::vector<Frame>& log() const { return log_; }

 private:
  void drive() {
    const auto period = std::chrono::nanoseconds(static_cast<long>(1e9 / rate_hz_));
    auto next = std::chrono::steady_clock::now();
    while (!quit_.load()) {
      next += period;
      std::this_thread::sleep_until(next);
      if (paused_.load()) continue;
      const long frame = frames_.load();
      frame_state_.position_m = Vec3(((frame / kHalfPeriod) % 2 == 0) ? 0.0 : kStepM, 0.0, 0.0);
      frame_state_.time_s = 5000.0 + static_cast<double>(frame) * time_per_frame_s_;  // the driver's own clock
      force_set_ = false;
      busy_.store(true);
      if (FrameFunction f = frame_.load(); f != nullptr) {
        in_frame_ = true;
        f(context_.load());
        in_frame_ = false;
      }
      busy_.store(false);
      if (static_cast<std::size_t>(frame) < log_.size()) {
        log_[static_cast<std::size_t>(frame)] = {frame_state_.position_m.x(),
                                                 forces_.load() ? frame_force_.x() : 0.0, force_set_};
      }
      frames_.store(frame + 1);
    }
  }

  double rate_hz_;
  double time_per_frame_s_ = 1.0 / rate_hz_;
  DeviceInfo info_;
  bool open_ = false;
  std::thread driver_;
  std::atomic<bool> quit_{false};
  std::atomic<bool> paused_{false};
  std::atomic<bool> forces_{false};
  std::atomic<FrameFunction> frame_{nullptr};
  std::atomic<void*> context_{nullptr};
  std::atomic<bool> busy_{false};
  std::atomic<long> frames_{0};
  long fail_frame_ = -1;
  // Touched by the driver thread only (and by read_state/write_force, which run inside its frames).
  bool in_frame_ = false;
  DeviceState frame_state_;
  Vec3 frame_force_ = Vec3::Zero();
  bool force_set_ = false;
  std::vector<Frame> log_;
};

}  // namespace calligraphy::test
