// The emulated Phantom in the device registry.
#include <memory>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/devices/phantom_models.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "testing/phantom_emulator.hpp"

namespace calligraphy::testing {
namespace {

DeviceInfo emulated_info() {
  DeviceInfo info = phantom_omni_info();
  info.model = "Phantom Omni (emulated)";
  info.manufacturer = "calligraphy";
  return info;
}

}  // namespace

std::unique_ptr<HapticDevice> make_emulated_phantom() {
  auto config = phantom::phantom_omni_config();
  config.info = emulated_info();
  auto parameters = phantom::emulator_matching(config);
  // Powers on docked, so open() homes the encoders; 50 ms later the writer lifts the stylus out.
  parameters.undock_after_s = 0.05;
  return std::make_unique<phantom::EmulatedPhantomDevice>(std::move(config), parameters);
}

void register_emulated_phantom(DeviceRegistry& registry) {
  registry.register_device_if_absent(
      "emulated-phantom", emulated_info(), make_emulated_phantom,
      DeviceCapabilities{.moved_by_simulated_hand = true, .needs_calibration = true},
      "PhantomEmulator over an in-memory link, through the real PhantomDevice "
      "code path; starts docked, leaves the inkwell after 50 ms of emulated time");
}

}  // namespace calligraphy::testing
