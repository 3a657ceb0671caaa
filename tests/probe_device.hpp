#pragma once
// A simulated device that the servo-loop and trial tests watch and disturb: it counts reads, force writes
// and writes of a marker force, can fail one read with a fault code (link_lost by default), and can sleep
// in one hand-port step (a stall on the loop thread). Its hand port lets a real-time trial step the
// physics after each write.
#include <chrono>
#include <thread>

#include "calligraphy/core/device_fault.hpp"
#include "calligraphy/devices/haptic_device.hpp"
#include "calligraphy/devices/hand_port.hpp"
#include "calligraphy/devices/simulated_device.hpp"

namespace calligraphy::test {

class ProbeDevice final : public HandDrivenDevice {
 public:
  static constexpr double kMarker = 1.25;  ///< x of the marker force [N]

  /// Opened. `fail_on_read`: the 0-based read that returns `fault`; -1: none.
  explicit ProbeDevice(long fail_on_read = -1, DeviceFault fault = DeviceFault::link_lost)
      : fail_on_read_(fail_on_read), fault_(fault) {
    inner_.open();
  }

  const DeviceInfo& info() const override { return inner_.info(); }
  void open() override { inner_.open(); }
  void close() noexcept override { inner_.close(); }
  bool is_open() const override { return inner_.is_open(); }
  void enable_forces(bool enabled) override { inner_.enable_forces(enabled); }
  bool forces_enabled() const override { return inner_.forces_enabled(); }
  DeviceFault read_state(DeviceState& state) noexcept override {
    if (reads_++ == fail_on_read_) {
      inner_.enable_forces(false);  // what a device does on a fault: forces off
      return fault_;
    }
    return inner_.read_state(state);
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    ++writes_;
    if (force_n.x() == kMarker) ++marker_writes_;
    last_force_ = force_n;
    return inner_.write_force(force_n);
  }
  void attach_hand(HandModel* hand) noexcept override { inner_.attach_hand(hand); }
  void advance(double dt_s) override {
    if (++advances_ == stall_after_advances_)
      std::this_thread::sleep_for(std::chrono::milliseconds(stall_ms_));
    inner_.advance(dt_s);
  }

  /// Sleep `ms` in the `advances`-th hand-port step (1-based).
  void stall_at(long advances, int ms) {
    stall_after_advances_ = advances;
    stall_ms_ = ms;
  }

  SimulatedDevice inner_;
  long reads_ = 0;
  long writes_ = 0;
  int marker_writes_ = 0;
  long advances_ = 0;
  Vec3 last_force_ = Vec3::Constant(1.0);  ///< the last force commanded [N]

 private:
  long fail_on_read_;
  DeviceFault fault_;
  long stall_after_advances_ = -1;
  int stall_ms_ = 0;
};

}  // namespace calligraphy::test
