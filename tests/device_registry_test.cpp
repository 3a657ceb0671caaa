#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/phantom_usb/phantom_usb_backends.hpp"

#include <atomic>
#include <catch2/catch.hpp>
#include <memory>
#include <sstream>
#include <thread>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/testing/emulated_phantom.hpp"
#include "devices/phantom/phantom_device.hpp"

using calligraphy::DeviceBackend;
using calligraphy::DeviceInfo;
using calligraphy::DeviceListing;
using calligraphy::DeviceRegistry;
using calligraphy::DeviceSurvey;
using calligraphy::HapticDevice;
using calligraphy::Vec3;

namespace {

// A trivial device standing in for the lead's SimulatedDevice.
class FixedDevice final : public HapticDevice {
 public:
  explicit FixedDevice(DeviceInfo info) : info_(std::move(info)) {}
  const DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { enabled_ = enabled; }
  bool forces_enabled() const override { return enabled_; }
  calligraphy::DeviceFault read_state(calligraphy::DeviceState& state) noexcept override {
    state = {};
    return calligraphy::DeviceFault::none;
  }
  calligraphy::DeviceFault write_force(const Vec3&) noexcept override {
    return calligraphy::DeviceFault::none;
  }

 private:
  DeviceInfo info_;
  bool open_ = false;
  bool enabled_ = false;
};

DeviceInfo info_named(const char* model) {
  DeviceInfo info;
  info.model = model;
  info.max_force_n = 2.0;
  return info;
}

}  // namespace

TEST_CASE("Backends register factories, devices are listed and created by name", "[registry]") {
  DeviceRegistry registry;
  registry.register_device("simulated", info_named("Sim"),
                           [] { return std::make_unique<FixedDevice>(info_named("Sim")); });
  DeviceBackend pair;
  pair.name = "pair";
  pair.scan = [] {
    return DeviceSurvey{
        {{"pair:a", "", info_named("A"), {.hardware = true}, ""}, {"pair:b", "", info_named("B"), {.hardware = true}, ""}},
        {"pair: scanned two"}};
  };
  pair.create = [](const DeviceListing& listing) { return std::make_unique<FixedDevice>(listing.info); };
  registry.register_backend(pair);

  const auto survey = registry.survey();
  REQUIRE(survey.devices.size() == 3);
  CHECK(survey.devices[0].name == "simulated");
  CHECK(survey.devices[2].name == "pair:b");
  CHECK(survey.devices[2].backend == "pair");
  CHECK(survey.any_hardware());
  CHECK(survey.notes == std::vector<std::string>{"pair: scanned two"});

  auto device = registry.open("pair:b");
  CHECK(device->is_open());
  CHECK(device->info().model == "B");
  CHECK_FALSE(registry.create("simulated")->is_open());

  try {
    (void)registry.create("nope");
    FAIL("expected DeviceNotFound");
  } catch (const calligraphy::DeviceNotFound& e) {
    CHECK(std::string(e.what()).find("simulated, pair:a, pair:b") != std::string::npos);
  }
  CHECK_THROWS_AS(registry.register_backend(pair), calligraphy::InvalidArgument);  // duplicate name
  CHECK_THROWS_AS(registry.register_backend(DeviceBackend{"empty", {}, {}}), calligraphy::InvalidArgument);
  CHECK(registry.unregister_backend("pair"));
  CHECK_FALSE(registry.unregister_backend("pair"));
  CHECK(registry.backend_names() == std::vector<std::string>{"simulated"});
}

TEST_CASE("A listing that contradicts its device's hand port is refused when the device is created", "[registry]") {
  DeviceRegistry registry;
  // A simulated device (it has a hand port) registered as if a person moved it, and the other way round.
  registry.register_device("unmarked", info_named("U"), [] { return std::make_unique<calligraphy::SimulatedDevice>(); });
  registry.register_device("overclaimed", info_named("O"), [] { return std::make_unique<FixedDevice>(info_named("O")); },
                           calligraphy::DeviceCapabilities{.moved_by_simulated_hand = true});
  CHECK_THROWS_WITH(registry.create("unmarked"),
                    Catch::Contains("'unmarked': its listing says it is not moved by a simulated hand"));
  CHECK_THROWS_WITH(registry.create("overclaimed"),
                    Catch::Contains("'overclaimed': its listing says it is moved by a simulated hand, but the device "
                                    "has none"));
  // A registry moves whole: the backends go with it.
  DeviceRegistry moved = std::move(registry);
  CHECK(moved.backend_names() == std::vector<std::string>{"unmarked", "overclaimed"});
}

TEST_CASE("Registering a device if absent keeps the first of a name, also from many threads", "[registry]") {
  DeviceRegistry registry;
  CHECK(registry.register_device_if_absent(
      "sim", info_named("First"), [] { return std::make_unique<FixedDevice>(info_named("First")); }));
  CHECK_FALSE(registry.register_device_if_absent(
      "sim", info_named("Second"), [] { return std::make_unique<FixedDevice>(info_named("Second")); }));
  CHECK(registry.create("sim")->info().model == "First");
  CHECK_THROWS_AS(registry.register_device_if_absent("other", info_named("X"), {}),
                  calligraphy::InvalidArgument);

  std::atomic<int> added{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&] {
      if (registry.register_device_if_absent("raced", info_named("R"),
                                             [] { return std::make_unique<FixedDevice>(info_named("R")); }))
        ++added;
    });
  }
  for (std::thread& thread : threads) thread.join();
  CHECK(added == 1);
  CHECK(registry.backend_names() == std::vector<std::string>{"sim", "raced"});
}

TEST_CASE("A backend that fails to scan becomes a note, not a failure", "[registry]") {
  DeviceRegistry registry;
  registry.register_backend({"broken",
                             []() -> DeviceSurvey { throw calligraphy::CommunicationError("bus on fire"); },
                             [](const DeviceListing&) -> std::unique_ptr<HapticDevice> { return nullptr; }});
  const auto survey = registry.survey();
  CHECK(survey.devices.empty());
  REQUIRE(survey.notes.size() == 1);
  CHECK(survey.notes[0] == "broken: bus on fire");
  std::ostringstream out;
  calligraphy::print_device_survey(out, survey);
  CHECK(out.str().find("No haptic hardware attached. No devices available at all.") != std::string::npos);
  CHECK(out.str().find("note: broken: bus on fire") != std::string::npos);
}

TEST_CASE("A registry offers the emulated Phantom and runs a servo loop through it", "[registry][phantom]") {
  calligraphy::DeviceRegistry registry = calligraphy::standard_device_registry();
  calligraphy::register_phantom_usb_backends(registry);
  calligraphy::testing::register_emulated_phantom(registry);
  const auto names = registry.backend_names();
  CHECK(std::find(names.begin(), names.end(), "emulated-phantom") != names.end());
  CHECK(std::find(names.begin(), names.end(), "phantom-hid") != names.end());
  CHECK(std::find(names.begin(), names.end(), "phantom-usb") != names.end());

  const auto survey = registry.survey();
  const auto emulated = std::find_if(survey.devices.begin(), survey.devices.end(),
                                     [](const DeviceListing& d) { return d.name == "emulated-phantom"; });
  REQUIRE(emulated != survey.devices.end());
  // What it is, from the listing alone: moved by a simulated hand, homed in the inkwell, not hardware.
  CHECK(emulated->capabilities == calligraphy::DeviceCapabilities{.hardware = false,
                                                                   .moved_by_simulated_hand = true,
                                                                   .needs_calibration = true});
  const auto simulated = std::find_if(survey.devices.begin(), survey.devices.end(),
                                      [](const DeviceListing& d) { return d.name == "simulated"; });
  REQUIRE(simulated != survey.devices.end());
  CHECK(simulated->capabilities.moved_by_simulated_hand);
  CHECK_FALSE(simulated->capabilities.needs_calibration);
  CHECK(registry.create("simulated")->hand_port() != nullptr);
  CHECK(registry.create("emulated-phantom")->hand_port() != nullptr);
  CHECK(emulated->info.max_force_n == 3.3);
  CHECK(emulated->info.max_continuous_force_n == 0.88);
  CHECK(emulated->info.max_stiffness_n_per_m == 700.0);
  std::ostringstream printed;
  calligraphy::print_device_survey(printed, survey);
  CHECK(printed.str().find("emulated-phantom  (not hardware)") != std::string::npos);
  CHECK(printed.str().find("max force:          3.3 N (continuous 0.88 N)") != std::string::npos);

  auto device = registry.open("emulated-phantom");
  REQUIRE(device->is_calibrated());  // powered on in the inkwell
  device->enable_forces(true);
  // 200 ticks of a spring towards a point 2 cm above the start, as a trial would do.
  calligraphy::DeviceState state;
  REQUIRE(device->read_state(state) == calligraphy::DeviceFault::none);
  const Vec3 start = state.position_m;
  const Vec3 target = start + Vec3(0, 0, 0.02);
  for (int tick = 0; tick < 200; ++tick) {
    REQUIRE(device->read_state(state) == calligraphy::DeviceFault::none);
    REQUIRE(device->write_force(200.0 * (target - state.position_m) - 2.0 * state.velocity_m_s) ==
            calligraphy::DeviceFault::none);
  }
  CHECK(state.position_m.z() > start.z() + 0.005);  // left the inkwell after 50 ms and rose
  CHECK(state.time_s == Approx(0.202).margin(0.0015));
  device->close();
  CHECK_FALSE(device->is_open());
}
