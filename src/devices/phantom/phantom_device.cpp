#include "devices/phantom/phantom_device.hpp"

#include <spdlog/spdlog.h>

#include <string>
#include <utility>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/force_limits.hpp"
#include "calligraphy/devices/phantom_models.hpp"

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
  spdlog::info("Phantom: opening {} on {}", config_.info.model, transport_->description());
  spdlog::info(
      "Phantom: verified (by tests, against published sources): the packet codec against the FireWire Omni "
      "field list of raw_omni / phantom-drivers (field order and byte order are this library's choice, see "
      "docs/devices.md); the kinematics against Cavusoglu et al.'s Phantom 1.5 model (here l1 = {} m, "
      "l2 = {} m)",
      config_.geometry.first_link_m, config_.geometry.second_link_m);
  spdlog::warn(
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
  try {
    send_command(CommandPacket{});  // forces off before anything else
    // receive_status throws CommunicationError after max_consecutive_bad_packets bad reads.
    while (!receive_status(now_s())) {
    }
  } catch (...) {
    open_ = false;
    transport_->close();
    throw;
  }
  if (is_calibrated()) {
    spdlog::info("Phantom: homed from the inkwell (docked bit set)");
  } else {
    spdlog::warn("Phantom: not calibrated: put the stylus in the inkwell and call calibrate()");
  }
}

void PhantomDevice::close() noexcept {
  if (open_) {
    turn_forces_off_locally();
    try {
      send_command(CommandPacket{});
    } catch (...) {
      // The link is already gone; the device's own watchdog drops the forces.
    }
    open_ = false;
    const auto errors = packet_errors();
    const auto safety = safety_events();
    try {
      spdlog::info(
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
  while (!receive_status(now_s())) {
  }
  if (!last_status_.docked) {
    throw CalibrationNeeded("Phantom " + config_.info.model +
                            ": the stylus is not in the inkwell; dock it and call calibrate() again");
  }
  home_at_inkwell(last_status_);
  apply_status(last_status_, state_.time_s);
  spdlog::info("Phantom: homed from the inkwell");
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
    send_command(CommandPacket{});
    enable_bit_zero_sent_ = true;
  }
  forces_requested_.store(enabled, std::memory_order_release);
}

DeviceState PhantomDevice::read_state() {
  if (!open_) throw CommunicationError("Phantom: read_state() on a device that is not open");
  const double now = now_s();
  if (watchdog_.expired(now)) {
    turn_forces_off_locally();
    counters_.watchdog_trips.fetch_add(1, std::memory_order_relaxed);
    send_command(CommandPacket{});  // CommunicationError here means the link is gone as well
    // A fixed message: the servo path builds no strings, also when it fails.
    throw SafetyFault("Phantom: watchdog: no force command within its timeout; forces turned off");
  }
  receive_status(now);
  return state_;
}

void PhantomDevice::write_force(const Vec3& force_n) {
  if (!open_) throw CommunicationError("Phantom: write_force() on a device that is not open");
  const double now = now_s();
  if (!force_n.allFinite()) {
    counters_.non_finite_commands.fetch_add(1, std::memory_order_relaxed);
    turn_forces_off_locally();
    send_command(CommandPacket{});
    throw SafetyFault(
        "Phantom: non-finite force command (NaN or infinity); zero force sent, forces turned off");
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
  send_command(command);
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

bool PhantomDevice::receive_status(double now) {
  std::size_t received = 0;
  try {
    received = transport_->read(receive_buffer_, config_.packet_timeout);
  } catch (const CommunicationError&) {
    lose_link();
    throw;
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
    last_packet_error_ = error;
    if (++consecutive_bad_reads_ >= config_.max_consecutive_bad_packets) {
      lose_link();
      throw CommunicationError(
          "Phantom: no valid status packet in " + std::to_string(consecutive_bad_reads_) +
          " reads (last problem: " + (received == 0 ? std::string("timeout") : packet_error_name(error)) +
          "); forces turned off, device closed");
    }
    return false;
  }
  consecutive_bad_reads_ = 0;
  if (have_status_) {
    // Counter gaps are lost packets; a counter that goes backwards (gap >= 2^15) is a repeat, not a loss.
    const auto gap = static_cast<std::uint16_t>(status.packet_counter - last_status_.packet_counter - 1);
    if (gap != 0 && gap < 0x8000) counters_.lost_packets.fetch_add(gap, std::memory_order_relaxed);
  }
  if (status.docked && !is_calibrated()) home_at_inkwell(status);
  apply_status(status, now);
  return true;
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

void PhantomDevice::send_command(const CommandPacket& command) {
  encode_command(command, send_buffer_);
  try {
    transport_->write(send_buffer_, config_.packet_timeout);
  } catch (const CommunicationError&) {
    lose_link();
    throw;
  }
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
  try {
    transport_->write(send_buffer_, config_.packet_timeout);
  } catch (...) {
    // Unplugged: nothing more to do on this side; the device's watchdog drops its forces.
  }
  transport_->close();
}

}  // namespace calligraphy::phantom
