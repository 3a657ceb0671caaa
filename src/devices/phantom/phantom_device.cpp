#include "devices/phantom/phantom_device.hpp"

#include <string>
#include <utility>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "calligraphy/devices/phantom_models.hpp"
#include "core/library_log.hpp"

namespace calligraphy::phantom {
namespace {

std::function<double()> steady_clock_since_now() {
  const auto start = std::chrono::steady_clock::now();
  return [start] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
}

PhantomDeviceConfig validated(PhantomDeviceConfig config) {
  if (config.geometry.first_link_m <= 0.0 || config.geometry.second_link_m <= 0.0) {
    throw InvalidArgument("PhantomDevice: link lengths must be > 0 m");
  }
  if (!(config.watchdog_timeout_s > 0.0))
    throw InvalidArgument("PhantomDevice: watchdog timeout must be > 0 s");
  if (!(config.velocity_cutoff_hz > 0.0))
    throw InvalidArgument("PhantomDevice: velocity cut-off must be > 0 Hz");
  if (config.max_consecutive_bad_packets < 1) {
    throw InvalidArgument("PhantomDevice: max_consecutive_bad_packets must be >= 1");
  }
  if (!(config.info.max_force_n > 0.0))
    throw InvalidArgument("PhantomDevice: info.max_force_n must be > 0 N");
  if (!config.clock) config.clock = steady_clock_since_now();
  return config;
}

}  // namespace

std::string describe(const PhantomFaultRecord& record) {
  if (record.fault == DeviceFault::none) return {};
  std::string text = "at " + shortest_decimal(record.time_s) + " s";
  if (record.bad_reads > 0) {
    text +=
        "; " + std::to_string(record.bad_reads) + " reads in a row without a valid status packet, the last ";
    text += record.last_read_timed_out
                ? std::string("a timeout")
                : std::string("rejected: ") + packet_error_name(record.last_packet_error);
  }
  return text;
}

PhantomDeviceConfig phantom_omni_config() {
  PhantomDeviceConfig config;
  config.info = phantom_omni_info();
  return config;
}

PhantomDeviceConfig touch_config() {
  PhantomDeviceConfig config;
  config.info = touch_info();
  return config;
}

PhantomDevice::PhantomDevice(std::unique_ptr<devices::ByteTransport> transport, PhantomDeviceConfig config)
    : transport_(std::move(transport)),
      config_(validated(std::move(config))),
      arm_(config_.geometry, config_.workspace_centre_rad),
      encoders_(config_.encoder_counts_per_revolution, config_.encoder_direction),
      velocity_filter_(config_.velocity_cutoff_hz),
      watchdog_(config_.watchdog_timeout_s) {
  if (!transport_) throw InvalidArgument("PhantomDevice: the transport must not be null");
}

PhantomDevice::~PhantomDevice() { close(); }

void PhantomDevice::log_start_up() const {
  calligraphy::detail::library_log().info("Phantom: opening {} on {}", config_.info.model,
                                          transport_->description());
  calligraphy::detail::library_log().info(
      "Phantom: verified (by tests, against published sources): the packet codec against the FireWire Omni "
      "field list of raw_omni / phantom-drivers (field order and byte order are this library's choice, see "
      "docs/devices.md); the kinematics against Cavusoglu et al.'s Phantom 1.5 model (here l1 = {} m, "
      "l2 = {} m)",
      config_.geometry.first_link_m, config_.geometry.second_link_m);
  calligraphy::detail::library_log().warn(
      "Phantom: NOT verified: nothing was run on hardware; the USB Touch's packet framing is not public; "
      "the USB ids 0x2988 / 0x0301, 0x0302 are unconfirmed; motor constants and the inkwell pose are "
      "placeholders");
}

void PhantomDevice::open() {
  if (open_) return;
  log_start_up();
  transport_->open();
  open_ = true;
  consecutive_bad_reads_ = 0;
  have_status_ = false;
  enable_bit_zero_sent_ = false;
  velocity_filter_.reset();
  watchdog_.disarm();
  fault_record_ = PhantomFaultRecord{};
  DeviceFault fault = send_command(CommandPacket{});  // forces off before anything else
  // receive_status gives up after max_consecutive_bad_packets bad reads.
  for (bool valid = false; fault == DeviceFault::none && !valid;) fault = receive_status(valid);
  if (fault != DeviceFault::none) {
    record(fault);
    open_ = false;
    transport_->close();
    throw_fault(fault);
  }
  if (is_calibrated()) {
    calligraphy::detail::library_log().info("Phantom: homed from the inkwell (docked bit set)");
  } else {
    calligraphy::detail::library_log().warn(
        "Phantom: not calibrated: put the stylus in the inkwell and call calibrate()");
  }
}

void PhantomDevice::close() noexcept {
  if (fault_record_.fault != DeviceFault::none) {
    try {  // the servo path kept the fault as plain data; it is worded here, off the servo thread
      calligraphy::detail::library_log().warn("Phantom: last fault: {} ({}): {}",
                                              device_fault_name(fault_record_.fault), describe(fault_record_),
                                              to_string(fault_record_.fault));
    } catch (...) {
      // Logging must not turn close() into a throwing call.
    }
    fault_record_ = PhantomFaultRecord{};
  }
  if (open_) {
    turn_forces_off_locally();
    // Best effort: when the link is already gone, the device's own watchdog drops the forces.
    static_cast<void>(send_command(CommandPacket{}));
    open_ = false;
    const auto errors = packet_errors();
    const auto safety = safety_events();
    try {
      calligraphy::detail::library_log().info(
          "Phantom: closed; rejected packets {} (short {}, long {}, malformed {}), timeouts {}, lost {}; "
          "NaN commands {}, clamped {}, watchdog trips {}",
          errors.rejected(), errors.too_short, errors.too_long, errors.malformed, errors.timeouts,
          errors.lost_packets, safety.non_finite_commands, safety.clamped_commands, safety.watchdog_trips);
    } catch (...) {
      // Logging must not turn close() into a throwing call.
    }
  }
  if (transport_) transport_->close();
}

void PhantomDevice::calibrate() {
  if (!open_) throw DeviceError("Phantom: calibrate() on a device that is not open");
  for (bool valid = false; !valid;) {
    if (const DeviceFault fault = receive_status(valid); fault != DeviceFault::none)
      throw_fault(record(fault));
  }
  if (!last_status_.docked) {
    throw CalibrationNeeded("Phantom " + config_.info.model +
                            ": the stylus is not in the inkwell; dock it and call calibrate() again");
  }
  home_at_inkwell(last_status_);
  apply_status(last_status_, state_.time_s);
  calligraphy::detail::library_log().info("Phantom: homed from the inkwell");
}

void PhantomDevice::enable_forces(bool enabled) {
  if (enabled) {
    if (!open_) throw DeviceError("Phantom: enable_forces(true) on a device that is not open");
    if (!is_calibrated()) {
      throw CalibrationNeeded("Phantom " + config_.info.model +
                              ": forces need a calibrated arm; put the stylus in the inkwell and call "
                              "calibrate()");
    }
  }
  if (enabled && !forces_requested_.load(std::memory_order_acquire)) {
    // First half of the Omni's 0 -> 1 force-enable toggle, sent now so that the first write_force
    // already carries its force. The watchdog is armed by that first write_force.
    if (const DeviceFault fault = send_command(CommandPacket{}); fault != DeviceFault::none)
      throw_fault(record(fault));
    enable_bit_zero_sent_ = true;
  }
  forces_requested_.store(enabled, std::memory_order_release);
}

// Servo path from here to the end of write_force: codes and counters, no exception, allocation or string.
DeviceFault PhantomDevice::read_state(DeviceState& state) noexcept {
  if (!open_) return record(DeviceFault::not_open);
  const double now = now_s();
  if (watchdog_.expired(now)) {
    turn_forces_off_locally();
    counters_.watchdog_trips.fetch_add(1, std::memory_order_relaxed);
    // A link fault here means the link is gone as well: that is the fault to report.
    if (const DeviceFault fault = send_command(CommandPacket{}); fault != DeviceFault::none)
      return record(fault);
    return record(DeviceFault::watchdog);
  }
  bool valid = false;
  if (const DeviceFault fault = receive_status(valid); fault != DeviceFault::none) return record(fault);
  state = state_;  // a fresh state, or the previous one after a rejected or missing packet
  return DeviceFault::none;
}

DeviceFault PhantomDevice::write_force(const Vec3& force_n) noexcept {
  if (!open_) return record(DeviceFault::not_open);
  const double now = now_s();
  if (!force_n.allFinite()) {
    counters_.non_finite_commands.fetch_add(1, std::memory_order_relaxed);
    turn_forces_off_locally();
    if (const DeviceFault fault = send_command(CommandPacket{}); fault != DeviceFault::none)
      return record(fault);
    return record(DeviceFault::non_finite_force);
  }
  CommandPacket command;
  if (!forces_requested_.load(std::memory_order_acquire)) {
    enable_bit_zero_sent_ = false;
    watchdog_.disarm();
  } else if (!enable_bit_zero_sent_) {
    // Forces were turned off and on again without a bit-0 packet in between (enable_forces(false)
    // from another thread): first half of the toggle now, with zero force; the next packet sets it to 1.
    enable_bit_zero_sent_ = true;
    watchdog_.kick(now);
  } else {
    const Vec3 limited = clamp_force_magnitude(force_n, config_.info.max_force_n);
    if (limited != force_n) counters_.clamped_commands.fetch_add(1, std::memory_order_relaxed);
    command.dac_counts = torques_to_dac(config_.motors, arm_.joint_torques(joint_angles_, limited));
    command.force_enable = true;
    watchdog_.kick(now);
  }
  if (const DeviceFault fault = send_command(command); fault != DeviceFault::none) return record(fault);
  return DeviceFault::none;
}

DeviceFault PhantomDevice::record(DeviceFault fault) noexcept {
  fault_record_.fault = fault;
  fault_record_.time_s = state_.time_s;
  fault_record_.bad_reads = fault == DeviceFault::no_valid_status ? consecutive_bad_reads_ : 0;
  fault_record_.last_packet_error = last_packet_error_;
  fault_record_.last_read_timed_out = last_read_timed_out_;
  return fault;
}

void PhantomDevice::throw_fault(DeviceFault fault) const {
  throw_device_fault(fault, config_.info.model, describe(fault_record_));
}

PacketErrorCounts PhantomDevice::packet_errors() const noexcept {
  PacketErrorCounts counts;
  counts.too_short = counters_.too_short.load(std::memory_order_relaxed);
  counts.too_long = counters_.too_long.load(std::memory_order_relaxed);
  counts.malformed = counters_.malformed.load(std::memory_order_relaxed);
  counts.timeouts = counters_.timeouts.load(std::memory_order_relaxed);
  counts.lost_packets = counters_.lost_packets.load(std::memory_order_relaxed);
  return counts;
}

SafetyEventCounts PhantomDevice::safety_events() const noexcept {
  SafetyEventCounts counts;
  counts.non_finite_commands = counters_.non_finite_commands.load(std::memory_order_relaxed);
  counts.clamped_commands = counters_.clamped_commands.load(std::memory_order_relaxed);
  counts.watchdog_trips = counters_.watchdog_trips.load(std::memory_order_relaxed);
  return counts;
}

DeviceFault PhantomDevice::receive_status(bool& valid) noexcept {
  valid = false;
  std::size_t received = 0;
  if (const DeviceFault fault = transport_->read(receive_buffer_, config_.packet_timeout, received);
      fault != DeviceFault::none) {
    lose_link();
    return fault;
  }
  StatusPacket status;
  PacketError error = PacketError::none;
  if (received == 0) {
    counters_.timeouts.fetch_add(1, std::memory_order_relaxed);
  } else {
    error = decode_status(std::span<const std::uint8_t>(receive_buffer_.data(), received), status);
    if (error != PacketError::none) count_rejected(error);
  }
  if (received == 0 || error != PacketError::none) {
    // The detail stays plain data; describe() words it off the servo path.
    last_packet_error_ = error;
    last_read_timed_out_ = received == 0;
    if (++consecutive_bad_reads_ >= config_.max_consecutive_bad_packets) {
      lose_link();
      return DeviceFault::no_valid_status;
    }
    return DeviceFault::none;
  }
  consecutive_bad_reads_ = 0;
  if (have_status_) {
    // Counter gaps are lost packets; a counter that goes backwards (gap >= 2^15) is a repeat, not a loss.
    const auto gap = static_cast<std::uint16_t>(status.packet_counter - last_status_.packet_counter - 1);
    if (gap != 0 && gap < 0x8000) counters_.lost_packets.fetch_add(gap, std::memory_order_relaxed);
  }
  if (status.docked && !is_calibrated()) home_at_inkwell(status);
  // Stamped when it arrived: the state it carries is the device's after the read (the emulator integrates
  // one tick per status packet), so its time and the velocity's differences are those of that state.
  apply_status(status, now_s());
  valid = true;
  return DeviceFault::none;
}

void PhantomDevice::count_rejected(PacketError error) noexcept {
  switch (error) {
    case PacketError::too_short:
      counters_.too_short.fetch_add(1, std::memory_order_relaxed);
      break;
    case PacketError::too_long:
      counters_.too_long.fetch_add(1, std::memory_order_relaxed);
      break;
    default:
      counters_.malformed.fetch_add(1, std::memory_order_relaxed);
      break;
  }
}

void PhantomDevice::apply_status(const StatusPacket& status, double now) noexcept {
  last_status_ = status;
  have_status_ = true;
  joint_angles_ = encoders_.angles(status.encoder_counts);
  state_.position_m = arm_.tip_position(joint_angles_);
  state_.velocity_m_s = velocity_filter_.update(state_.position_m, now);
  state_.buttons = status.buttons_pressed;
  state_.time_s = now;
}

void PhantomDevice::home_at_inkwell(const StatusPacket& status) noexcept {
  encoders_.home(status.encoder_counts, config_.inkwell_rad);
  velocity_filter_.reset();  // the position jumps at homing; that jump is not a velocity
  calibrated_.store(true, std::memory_order_release);
}

DeviceFault PhantomDevice::send_command(const CommandPacket& command) noexcept {
  encode_command(command, send_buffer_);
  const DeviceFault fault = transport_->write(send_buffer_, config_.packet_timeout);
  if (fault != DeviceFault::none) lose_link();
  return fault;
}

void PhantomDevice::turn_forces_off_locally() noexcept {
  forces_requested_.store(false, std::memory_order_release);
  enable_bit_zero_sent_ = false;
  watchdog_.disarm();
}

void PhantomDevice::lose_link() noexcept {
  turn_forces_off_locally();
  if (!open_) return;
  open_ = false;  // before the best-effort write, so that a failing write does not recurse here
  encode_command(CommandPacket{}, send_buffer_);
  // Unplugged: nothing more to do on this side; the device's watchdog drops its forces.
  static_cast<void>(transport_->write(send_buffer_, config_.packet_timeout));
  transport_->close();
}

}  // namespace calligraphy::phantom
