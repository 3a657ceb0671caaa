#pragma once
/// \file emulated_phantom.hpp
/// The Phantom emulator for applications' own tests (target `calligraphy::testing`, not part of
/// `calligraphy::calligraphy`): a `PhantomDevice` talking the Phantom packet protocol to an emulated arm
/// over an in-memory link, in the spirit of libfranka's mock server. The whole device code path runs
/// (packet codec, arm kinematics, watchdog); the arm is moved by a simulated hand (`HandPort`).
#include <memory>

#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/haptic_device.hpp"

namespace calligraphy::testing {

/// A Phantom Omni emulator as the registry offers it: powers on docked, so `open()` homes the encoders;
/// the stylus leaves the inkwell after 50 ms of emulated time. The device also implements `HandPort`
/// (calligraphy/devices/hand_port.hpp), so a simulated writer can move it.
[[nodiscard]] std::unique_ptr<HapticDevice> make_emulated_phantom();

/// Registers that device as "emulated-phantom" in `registry`; nothing when a backend of that name is
/// already there.
void register_emulated_phantom(DeviceRegistry& registry);

}  // namespace calligraphy::testing
