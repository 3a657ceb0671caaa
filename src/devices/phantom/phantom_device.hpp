#pragma once
/// \file phantom.hpp
/// `PhantomDevice`: a Phantom arm behind `HapticDevice`, composed of a `ByteTransport` (hidapi,
/// libusb or in-memory), the packet codec (phantom_codec.hpp) and the arm model (phantom_arm.hpp).
///
/// What is verified and what is not (also logged at open() and written in docs/devices.md): the codec
/// follows the published field list of the FireWire Omni protocol, with field order and byte order
/// chosen by this library where the publication is silent; the kinematics follow Cavusoglu et al.'s
/// published Phantom 1.5 model; the USB Touch's framing is not public; the USB ids 0x2988 /
/// 0x0301, 0x0302 are unconfirmed; nothing was run on hardware. Tests run against `PhantomEmulator`.
///
/// Threading: `read_state` and `write_force` belong to one servo thread. `enable_forces(false)`,
/// `forces_enabled`, `is_calibrated`, `info`, `packet_errors` and `safety_events` may be called from any
/// thread. `open`, `close`, `calibrate`, `enable_forces(true)` and `last_fault` must not run while the
/// servo loop runs.
///
/// The servo path (`read_state`, `write_force`, and the codec and transport calls under them) neither
/// throws, allocates nor builds a string: a fault is a `DeviceFault` code, its detail a plain
/// `PhantomFaultRecord` and counters, formatted off the servo thread (`describe`, the log at `close()`).

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "calligraphy/devices/haptic_device.hpp"
#include "devices/byte_transport.hpp"
#include "devices/phantom/command_watchdog.hpp"
#include "devices/phantom/phantom_arm.hpp"
#include "devices/phantom/phantom_codec.hpp"
#include "devices/phantom/velocity_filter.hpp"

namespace calligraphy::phantom {

/// Everything a PhantomDevice needs to know about its arm and its link.
struct PhantomDeviceConfig {
  DeviceInfo info;                                         ///< reported by info(); max_force_n clamps
  ArmGeometry geometry = ArmGeometry::omni();              ///< link lengths [m]
  JointAngles workspace_centre_rad = JointAngles::Zero();  ///< joint angles of the device origin [rad]
  /// Joint angles with the stylus in the inkwell [rad]. PLACEHOLDER, not measured on a device.
  JointAngles inkwell_rad = JointAngles(0.0, -0.2, -0.3);
  int encoder_counts_per_revolution = kEncoderCountsPerRevolution;
  std::array<int, 3> encoder_direction = {1, 1, 1};  ///< sign of counts per positive angle
  MotorModel motors;                                 ///< torque -> DAC scaling (placeholders)
  double watchdog_timeout_s = 0.05;                  ///< no write_force for this long [s] turns forces off
  double velocity_cutoff_hz = 50.0;                  ///< velocity filter cut-off [Hz] (velocity_filter.hpp)
  std::chrono::microseconds packet_timeout{2000};    ///< per read or write
  /// This many reads in a row without a valid status packet (timeouts, rejected packets) is a broken
  /// link: `DeviceFault::no_valid_status`. 50 is 50 ms at 1 kHz.
  int max_consecutive_bad_packets = 50;
  /// Monotonic time [s] used for time stamps, velocity and the watchdog. Empty: std::chrono::steady_clock.
  /// Must not allocate, lock or throw (it is called on the servo path).
  std::function<double()> clock;
};

/// Omni geometry and CHAI3D's Omni DeviceInfo.
[[nodiscard]] PhantomDeviceConfig phantom_omni_config();
/// Touch: Omni geometry (assumed, not published) and CHAI3D's Touch DeviceInfo.
[[nodiscard]] PhantomDeviceConfig touch_config();

/// Safety events since open(), for reports.
struct SafetyEventCounts {
  std::uint64_t non_finite_commands = 0;  ///< NaN/inf forces: zero force sent, `non_finite_force`
  std::uint64_t clamped_commands = 0;     ///< forces above info().max_force_n, scaled down
  std::uint64_t watchdog_trips = 0;       ///< forces turned off because write_force stopped
};

/// The last servo-path fault and its detail, as plain data: written on the servo thread without
/// allocating, formatted off it (`describe`).
struct PhantomFaultRecord {
  DeviceFault fault = DeviceFault::none;
  double time_s = 0.0;  ///< the device clock at the fault [s]
  /// Reads in a row without a valid status packet when the fault came (for `no_valid_status`).
  int bad_reads = 0;
  /// The problem of the last read without a valid status packet: a rejected packet's error, or none
  /// for a timeout (nothing arrived).
  PacketError last_packet_error = PacketError::none;
  bool last_read_timed_out = false;
};

/// The record in words, e.g. "at 1.234 s; 50 reads in a row without a valid status packet, the last a
/// timeout". Allocates: off the servo path. Empty for no fault.
[[nodiscard]] std::string describe(const PhantomFaultRecord& record);

class PhantomDevice final : public HapticDevice {
 public:
  /// Takes ownership of `transport` (not yet open). Throws InvalidArgument when it is null or the config
  /// is impossible (non-positive timeouts, links or counts).
  PhantomDevice(std::unique_ptr<devices::ByteTransport> transport, PhantomDeviceConfig config);
  ~PhantomDevice() override;

  [[nodiscard]] const DeviceInfo& info() const override { return config_.info; }

  /// Opens the transport, logs what is and is not verified, sends a forces-off packet and waits for a
  /// valid status packet; homes the encoders when that packet says the stylus is docked. Throws
  /// DeviceNotFound (transport cannot open) or CommunicationError (link lost, no valid status packet:
  /// `throw_device_fault` with the record's detail).
  void open() override;
  /// Sends a forces-off packet (best effort), closes the transport, logs the packet and safety
  /// counters and the last servo-path fault with its detail. Never throws.
  void close() noexcept override;
  [[nodiscard]] bool is_open() const override { return open_; }

  /// Reads a fresh status packet and homes the encoders to `inkwell_rad`. Throws CalibrationNeeded when
  /// the stylus is not docked in the inkwell, DeviceError when not open, CommunicationError on link loss.
  void calibrate() override;
  /// True once the encoders were homed (by calibrate(), or by the first docked packet after open()).
  [[nodiscard]] bool is_calibrated() const override { return calibrated_.load(std::memory_order_acquire); }

  /// Enabling sends a packet with the force-enable bit 0 (zero force) at once; the next write_force sets
  /// the bit to 1 with its force: the 0 -> 1 toggle the Omni needs, and no commanded force is skipped.
  /// Throws CalibrationNeeded when enabling an uncalibrated arm (the Jacobian would push in wrong
  /// directions), DeviceError when not open, CommunicationError when that packet cannot be sent (link
  /// lost). Disabling never throws.
  void enable_forces(bool enabled) override;
  [[nodiscard]] bool forces_enabled() const override {
    return forces_requested_.load(std::memory_order_acquire);
  }

  /// Servo path: reads one status packet (position [m], filtered velocity [m/s], buttons, time [s]).
  /// A rejected or missing packet is counted and the previous state is returned. Until is_calibrated()
  /// the position is not meaningful. Faults: `not_open`; `link_lost` (unplugged) and `no_valid_status`
  /// (`max_consecutive_bad_packets` bad reads in a row): forces turned off, the device closes;
  /// `watchdog` (forces on and no write_force for `watchdog_timeout_s`): forces turned off, call
  /// enable_forces(true) to resume.
  [[nodiscard]] DeviceFault read_state(DeviceState& state) noexcept override;
  /// Servo path: clamps `force_n` [N] to info().max_force_n keeping its direction, maps it to joint
  /// torques (J^T F) and DAC counts, and sends one command packet. Faults: `non_finite_force` (a NaN or
  /// infinite component: zero force is sent and forces are turned off), `not_open`, `link_lost`
  /// (forces off, device closed).
  [[nodiscard]] DeviceFault write_force(const Vec3& force_n) noexcept override;

  /// Rejected packets and link counters since construction. Any thread.
  [[nodiscard]] PacketErrorCounts packet_errors() const noexcept;
  /// Safety events since construction. Any thread.
  [[nodiscard]] SafetyEventCounts safety_events() const noexcept;
  /// Joint angles [rad] of the last valid status packet. Servo thread only.
  [[nodiscard]] const JointAngles& joint_angles() const noexcept { return joint_angles_; }
  /// The last valid status packet (raw). Servo thread only.
  [[nodiscard]] const StatusPacket& last_status() const noexcept { return last_status_; }
  /// The last servo-path fault since open(), with its detail (`describe` words it). Servo thread, or any
  /// thread once the servo loop has stopped.
  [[nodiscard]] const PhantomFaultRecord& last_fault() const noexcept { return fault_record_; }

 private:
  struct AtomicCounters {
    std::atomic<std::uint64_t> too_short{0}, too_long{0}, malformed{0}, timeouts{0}, lost_packets{0};
    std::atomic<std::uint64_t> non_finite_commands{0}, clamped_commands{0}, watchdog_trips{0};
  };

  double now_s() const noexcept { return config_.clock(); }
  /// Reads once; on a valid packet updates the state, stamped with the clock when it arrived, and sets
  /// `valid`. Returns `link_lost` or `not_open` (transport) or `no_valid_status` (too many bad reads in a
  /// row): the link is then lost.
  [[nodiscard]] DeviceFault receive_status(bool& valid) noexcept;
  void count_rejected(PacketError error) noexcept;
  void apply_status(const StatusPacket& status, double now_s) noexcept;
  void home_at_inkwell(const StatusPacket& status) noexcept;
  /// Sends one command packet; on a transport fault loses the link and returns the fault.
  [[nodiscard]] DeviceFault send_command(const CommandPacket& command) noexcept;
  /// Forces off on both sides (best effort), device closed. Never throws.
  void lose_link() noexcept;
  void turn_forces_off_locally() noexcept;
  /// Keeps the fault and its detail in `fault_record_` and returns it. No allocation.
  DeviceFault record(DeviceFault fault) noexcept;
  /// Off the servo path: throws the typed exception of `fault` with the record's detail.
  [[noreturn]] void throw_fault(DeviceFault fault) const;
  void log_start_up() const;

  std::unique_ptr<devices::ByteTransport> transport_;
  PhantomDeviceConfig config_;
  PhantomArm arm_;
  JointEncoders encoders_;
  devices::VelocityFilter velocity_filter_;
  devices::CommandWatchdog watchdog_;

  // Buffers are members so that the servo path never allocates. The receive buffer is longer than a
  // status packet so that over-long packets are seen as such.
  std::array<std::uint8_t, 64> receive_buffer_{};
  std::array<std::uint8_t, kCommandPacketBytes> send_buffer_{};

  bool open_ = false;
  std::atomic<bool> forces_requested_{false};
  std::atomic<bool> calibrated_{false};
  bool enable_bit_zero_sent_ = false;  // first half of the 0 -> 1 force-enable toggle done
  bool have_status_ = false;
  int consecutive_bad_reads_ = 0;
  PacketError last_packet_error_ = PacketError::none;
  bool last_read_timed_out_ = false;
  PhantomFaultRecord fault_record_;
  StatusPacket last_status_;
  JointAngles joint_angles_ = JointAngles::Zero();
  DeviceState state_;
  AtomicCounters counters_;
};

}  // namespace calligraphy::phantom
