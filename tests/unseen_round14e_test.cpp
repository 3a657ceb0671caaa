// A haptic application's round against the library's public headers under threads, lifetimes and re-entry:
// the cases were written from the documented contracts (include/calligraphy/**'s doc comments,
// docs/servo-loop.md, docs/architecture.md, docs/devices.md) before the implementation was read. The same
// const library, character, scene and options are used from four threads at once (each thread must get what
// one thread gets); renderers, active strokes and libraries are copied, moved and self-assigned mid-stroke;
// a servo loop's callback and after-write hook call back into the loop, throw late, and the loop is stopped
// from several threads at once and destroyed from another thread; a display thread reads snapshots while the
// loop ticks; the library's log is taken, swapped and re-levelled from many threads while a loop runs; and
// the loop thread is counted for allocations while its ticks run late and are logged.
#include <algorithm>
#include <array>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <future>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "allocation_count.hpp"
#include "application_stylus.hpp"
#include "calligraphy/collision/active_stroke.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/logging.hpp"
#include "calligraphy/devices/device_registry.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/trial/display.hpp"
#include "calligraphy/trial/runner.hpp"
#include "calligraphy/trial/session.hpp"
#include "embedded_scenes.hpp"

using calligraphy::testing::cross_scene;

namespace {

using namespace calligraphy;
using Catch::Matchers::Contains;

constexpr int kThreads = 4;

// Runs `work(i)` on kThreads threads started together (they wait for each other before working).
template <typename Work>
void on_threads(Work work) {
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      ready.fetch_add(1);
      while (ready.load() < kThreads) std::this_thread::yield();
      work(i);
    });
  }
  for (std::thread& thread : threads) thread.join();
}

// The states of a pen that comes down onto the first stroke's start, writes along its centre line and lifts
// at its end, one per 1 ms tick: the renderer goes through SS, AS, CS and WS and completes the stroke.
std::vector<DeviceState> writing_states(const Scene& scene) {
  const auto& points = scene.characters.front().strokes.front().centre_line.points_m;
  const double z0 = scene.layout.paper_z_m;
  std::vector<DeviceState> states;
  auto add = [&](const Vec2& p, double z) {
    DeviceState state;
    state.position_m = Vec3(p.x(), p.y(), z);
    state.time_s = 0.001 * static_cast<double>(states.size());
    states.push_back(state);
  };
  for (int i = 0; i < 40; ++i) add(points.front(), z0 + 0.01 - 0.0003 * i);  // down to 2 mm into the paper
  const int along = 400;
  for (int i = 0; i <= along; ++i) {
    const double s = static_cast<double>(i) / along * static_cast<double>(points.size() - 1);
    const auto k = std::min(points.size() - 2, static_cast<std::size_t>(s));
    const double f = s - static_cast<double>(k);
    add(points[k] + f * (points[k + 1] - points[k]), z0 - 0.002);
  }
  for (int i = 0; i < 40; ++i) add(points.back(), z0 + 0.0003 * i);  // lifted
  return states;
}

bool same_output(const RenderOutput& a, const RenderOutput& b) {
  return a.force_n == b.force_n && a.state == b.state && a.state_changed == b.state_changed &&
         a.character == b.character && a.stroke == b.stroke && a.element == b.element &&
         a.finished == b.finished && a.in_constraint_space == b.in_constraint_space && a.foot_m == b.foot_m &&
         a.stroke_completed == b.stroke_completed && a.stroke_abandoned == b.stroke_abandoned &&
         a.misses == b.misses && a.limits == b.limits &&
         a.passivity_damping_n_s_per_m == b.passivity_damping_n_s_per_m;
}

std::vector<RenderOutput> render_all(Renderer& renderer, const std::vector<DeviceState>& states,
                                     std::size_t from = 0, std::size_t to = SIZE_MAX) {
  std::vector<RenderOutput> outputs;
  for (std::size_t i = from; i < std::min(to, states.size()); ++i)
    outputs.push_back(renderer.tick(states[i]));
  return outputs;
}

bool same_outputs(const std::vector<RenderOutput>& a, const std::vector<RenderOutput>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!same_output(a[i], b[i])) return false;
  }
  return true;
}

bool same_character(const Character& a, const Character& b) {
  if (a.code_point != b.code_point || a.source != b.source || a.strokes.size() != b.strokes.size())
    return false;
  for (std::size_t s = 0; s < a.strokes.size(); ++s) {
    const Stroke& x = a.strokes[s];
    const Stroke& y = b.strokes[s];
    if (x.typical_id != y.typical_id || x.median != y.median ||
        x.attraction_factors != y.attraction_factors || x.elements.size() != y.elements.size()) {
      return false;
    }
    for (std::size_t e = 0; e < x.elements.size(); ++e) {
      if (x.elements[e].start() != y.elements[e].start() || x.elements[e].end() != y.elements[e].end()) {
        return false;
      }
    }
  }
  return true;
}

bool same_scene(const Scene& a, const Scene& b) {
  if (a.characters.size() != b.characters.size()) return false;
  for (std::size_t c = 0; c < a.characters.size(); ++c) {
    const PlacedCharacter& x = a.characters[c];
    const PlacedCharacter& y = b.characters[c];
    if (x.strokes.size() != y.strokes.size() || x.bounding_box.min() != y.bounding_box.min() ||
        x.bounding_box.max() != y.bounding_box.max()) {
      return false;
    }
    for (std::size_t s = 0; s < x.strokes.size(); ++s) {
      if (x.strokes[s].median_m != y.strokes[s].median_m ||
          x.strokes[s].centre_line.points_m != y.strokes[s].centre_line.points_m ||
          x.strokes[s].centre_line.element_end_arc_m != y.strokes[s].centre_line.element_end_arc_m) {
        return false;
      }
    }
  }
  return true;
}

// An application's stylus on the machine's clock or on a clock the test gives, whose reading of tick k (the
// k-th read, 1-based) the test may give too. The loop is its only user while a run lasts (the loop's
// contract); what the test reads meanwhile is atomic.
class Stylus final : public HapticDevice {
 public:
  Stylus() : info_(testing::application_stylus_info("round 14E stylus")) {}
  const DeviceInfo& info() const override { return info_; }
  void open() override { open_ = true; }
  void close() noexcept override {
    forces_.store(false);
    open_ = false;
  }
  bool is_open() const override { return open_; }
  void enable_forces(bool enabled) override { forces_.store(enabled); }
  bool forces_enabled() const override { return forces_.load(); }
  DeviceFault read_state(DeviceState& state) noexcept override {
    if (!open_) return DeviceFault::not_open;
    const std::uint64_t k = reads.fetch_add(1, std::memory_order_relaxed) + 1;
    state.position_m = Vec3(0.0, 0.0, 0.02);
    state.velocity_m_s = Vec3::Zero();
    state.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (reading) reading(k, state);
    return DeviceFault::none;
  }
  DeviceFault write_force(const Vec3& force_n) noexcept override {
    if (!open_) return DeviceFault::not_open;
    writes.fetch_add(1, std::memory_order_relaxed);
    const Vec3 held = forces_.load() ? force_n : Vec3::Zero();
    last_force_x.store(held.x());
    last_force_norm.store(held.norm());
    return DeviceFault::none;
  }

  std::function<void(std::uint64_t, DeviceState&)> reading;  // set before the run: may change the state
  std::atomic<std::uint64_t> reads{0};
  std::atomic<std::uint64_t> writes{0};
  std::atomic<double> last_force_x{0.0};
  std::atomic<double> last_force_norm{0.0};

 private:
  DeviceInfo info_;
  bool open_ = false;
  std::atomic<bool> forces_{false};
};

// Loop options for a test on a shared, loaded machine: no stall bound (a descheduled test thread is not the
// fault under test) and forces never withheld for age (the 1 s maximum), unless the case says otherwise.
ServoLoopOptions relaxed_loop(double rate_hz = 1000.0) {
  ServoLoopOptions options;
  options.rate_hz = rate_hz;
  options.stall_timeout_s = 0.0;
  options.max_force_age_s = 1.0;
  return options;
}

// Waits until `done()` or `seconds` pass.
template <typename Done>
bool eventually(Done done, double seconds = 10.0) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// A log handler's calls: how many, and whether two ever overlapped (the header serialises them).
struct HandlerCalls {
  std::atomic<int> inside{0};
  std::atomic<int> overlaps{0};
  std::atomic<int> calls{0};
  std::atomic<int> warnings{0};
  LogHandler handler() {
    return [this](LogLevel level, std::string_view message) {
      if (inside.fetch_add(1) != 0) overlaps.fetch_add(1);
      calls.fetch_add(1);
      if (level == LogLevel::warning && message.find("stiffness") != std::string_view::npos) {
        warnings.fetch_add(1);
      }
      std::this_thread::yield();  // widen the window in which an unserialised call would overlap
      inside.fetch_sub(1);
    };
  }
};

// A force law whose paper stiffness is above the device's stable maximum: each Renderer built with it logs
// one warning (renderer.hpp), from the thread that builds it.
ForceLawParameters too_stiff() {
  ForceLawParameters parameters;
  parameters.paper_stiffness_n_per_m = 1.5 * simulated_phantom_desktop_info().max_stiffness_n_per_m;
  return parameters;
}

// Gives the library's log back to spdlog at the level the test program's main sets (errors only).
struct LogRestorer {
  ~LogRestorer() {
    set_log_handler({});
    set_log_level(LogLevel::error);
  }
};

}  // namespace

// ---- The same const object from four threads at once.

TEST_CASE("unseen14e: one const CharacterLibrary loads from four threads what it loads on one",
          "[unseen14e]") {
  const CharacterLibrary embedded = CharacterLibrary::embedded();
  const CharacterLibrary standard = CharacterLibrary::standard();
  const std::array<char32_t, 4> wanted{U'人', U'十', U'乙', U'口'};
  std::vector<Character> alone;
  for (char32_t c : wanted) alone.push_back(embedded.load(c));
  const Character store_alone = standard.load(U'丁');
  std::array<std::vector<Character>, kThreads> loaded;
  std::array<Character, kThreads> from_store;
  std::array<std::size_t, kThreads> listed{};
  on_threads([&](int t) {
    for (int round = 0; round < 3; ++round) {
      loaded[t].clear();
      for (std::size_t i = 0; i < wanted.size(); ++i) {
        loaded[t].push_back(embedded.load(wanted[(i + static_cast<std::size_t>(t)) % wanted.size()]));
      }
    }
    from_store[t] = standard.load(U'丁');
    listed[t] = embedded.characters().size();
  });
  for (int t = 0; t < kThreads; ++t) {
    INFO("thread " << t);
    for (std::size_t i = 0; i < wanted.size(); ++i) {
      CHECK(same_character(loaded[t][i], alone[(i + static_cast<std::size_t>(t)) % wanted.size()]));
    }
    CHECK(same_character(from_store[t], store_alone));
    CHECK(listed[t] == embedded.characters().size());
  }
}

TEST_CASE("unseen14e: copies, moves and a self-assignment of a CharacterLibrary load the same characters",
          "[unseen14e]") {
  CharacterLibrary library = CharacterLibrary::embedded();
  const Character reference = library.load(U'十');
  CharacterLibrary copy = library;
  CharacterLibrary moved = std::move(copy);
  CharacterLibrary& alias = library;
  library = alias;  // self-assignment
  copy = moved;     // a moved-from library assigned anew
  CHECK(same_character(library.load(U'十'), reference));
  CHECK(same_character(moved.load(U'十'), reference));
  CHECK(same_character(copy.load(U'十'), reference));
  CHECK(copy.description() == library.description());
  CHECK_THROWS_AS(copy.load(U'\U0010FFFD'), CharacterNotFound);
}

TEST_CASE("unseen14e: one const set of characters laid out by four threads at once gives one scene",
          "[unseen14e]") {
  const std::vector<Character> characters{CharacterLibrary::embedded().load(U'十'),
                                          CharacterLibrary::embedded().load(U'口')};
  const Scene alone = Scene::lay_out(characters);
  std::array<Scene, kThreads> scenes;
  on_threads([&](int t) {
    for (int round = 0; round < 5; ++round) scenes[t] = Scene::lay_out(characters);
  });
  for (int t = 0; t < kThreads; ++t) CHECK(same_scene(scenes[t], alone));
}

TEST_CASE("unseen14e: one const scene and options ticked by four renderers on four threads answer as one",
          "[unseen14e]") {
  const Scene& scene = cross_scene();
  const std::vector<DeviceState> states = writing_states(scene);
  const ForceLawParameters parameters;
  const RendererOptions options;
  const DeviceInfo device = simulated_phantom_desktop_info();
  Renderer single(scene, parameters, device, options);
  const std::vector<RenderOutput> alone = render_all(single, states);
  REQUIRE(std::any_of(alone.begin(), alone.end(), [](const RenderOutput& o) { return o.stroke_completed; }));
  std::array<std::vector<RenderOutput>, kThreads> outputs;
  on_threads([&](int t) {
    options.validate();  // the shared options read while the others build from them
    Renderer renderer(scene, parameters, device, options);
    outputs[t] = render_all(renderer, states);
  });
  for (int t = 0; t < kThreads; ++t) {
    INFO("thread " << t);
    CHECK(same_outputs(outputs[t], alone));
  }
}

TEST_CASE("unseen14e: two trial sessions on two simulated devices run by two servo loops at once match",
          "[unseen14e]") {
  const Scene& scene = cross_scene();
  // A hand pressing the stylus onto the first stroke's start and along it (both devices the same).
  struct PressingHand final : HandModel {
    Vec3 target;
    Vec3 hand_force(double t, const Vec3& x, const Vec3& v) override {
      const Vec3 goal = target + Vec3(0.03 * std::min(t, 0.3), 0.0, 0.0);
      return 200.0 * (goal - x) - 3.0 * v;
    }
  };
  const Vec2& start = scene.characters.front().strokes.front().centre_line.points_m.front();
  struct Run {
    SimulatedDevice device;
    PressingHand hand;
    std::unique_ptr<TrialSession> session;
    std::unique_ptr<ServoLoop> loop;
    TrialResult result;
  };
  TrialOptions options;
  options.max_duration_s = 0.25;
  std::array<Run, 2> runs;
  for (Run& run : runs) {
    run.hand.target = Vec3(start.x(), start.y(), scene.layout.paper_z_m - 0.004);
    run.device.attach_hand(&run.hand);
    run.device.open();
    run.session = std::make_unique<TrialSession>(scene, run.device.info(), options);
    run.session->reserve_trace();
    SimulatedDevice* device = &run.device;
    run.loop = std::make_unique<ServoLoop>(run.device, run.session->servo_callback(), relaxed_loop(),
                                           [device] { device->advance(0.001); });
  }
  std::thread first([&] {
    runs[0].loop->start();
    runs[0].loop->wait();
  });
  std::thread second([&] {
    runs[1].loop->start();
    runs[1].loop->wait();
  });
  first.join();
  second.join();
  for (Run& run : runs) run.result = run.session->finish(TrialEnd::time_limit);
  REQUIRE(runs[0].result.trace.size() == 250);
  REQUIRE(runs[1].result.trace.size() == runs[0].result.trace.size());
  bool touched = false;
  for (std::size_t i = 0; i < runs[0].result.trace.size(); ++i) {
    const TrialSample& a = runs[0].result.trace[i];
    const TrialSample& b = runs[1].result.trace[i];
    INFO("tick " << i);
    REQUIRE(a.position_m == b.position_m);
    REQUIRE(a.force_n == b.force_n);
    REQUIRE(a.state == b.state);
    touched = touched || a.state != InteractionState::separation;
  }
  CHECK(touched);
  for (Run& run : runs) CHECK_FALSE(run.device.forces_enabled());
}

TEST_CASE("unseen14e: a device registry filled from four threads at once holds each backend once",
          "[unseen14e]") {
  DeviceRegistry registry;
  std::array<int, kThreads> added{};
  on_threads([&](int t) {
    register_simulated_device(registry);
    register_standard_device_backends(registry);
    added[t] =
        registry.register_device_if_absent(
            "round14e", simulated_phantom_desktop_info(), [] { return std::make_unique<SimulatedDevice>(); },
            DeviceCapabilities{.moved_by_simulated_hand = true})
            ? 1
            : 0;
  });
  const std::vector<std::string> names = registry.backend_names();
  CHECK(std::count(names.begin(), names.end(), "simulated") == 1);
  CHECK(std::count(names.begin(), names.end(), "round14e") == 1);
  CHECK(added[0] + added[1] + added[2] + added[3] == 1);
  CHECK(registry.create("round14e") != nullptr);
}

// ---- The library's log from many threads.

TEST_CASE(
    "unseen14e: warnings logged from four threads while a servo loop runs reach the handler one at a time",
    "[unseen14e]") {
  LogRestorer restore;
  HandlerCalls calls;
  set_log_level(LogLevel::info);
  set_log_handler(calls.handler());
  Stylus stylus;
  stylus.open();
  ServoLoop loop(
      stylus, [](const DeviceState&, double) { return ServoCommand{}; }, relaxed_loop());
  loop.start();
  constexpr int kEach = 10;
  on_threads([&](int) {
    for (int i = 0; i < kEach; ++i) {
      Renderer renderer(cross_scene(), too_stiff(), simulated_phantom_desktop_info());
      (void)renderer;
    }
  });
  const LoopFault fault = loop.stop();
  CHECK_FALSE(fault);
  CHECK(calls.warnings.load() == kThreads * kEach);
  CHECK(calls.overlaps.load() == 0);
}

TEST_CASE("unseen14e: once set_log_handler returns on one thread the old handler is never called again",
          "[unseen14e]") {
  LogRestorer restore;
  set_log_level(LogLevel::info);
  std::atomic<bool> replaced{false};
  std::atomic<int> late_calls{0};
  std::atomic<int> old_calls{0};
  std::atomic<int> new_calls{0};
  set_log_handler([&](LogLevel, std::string_view) {
    old_calls.fetch_add(1);
    if (replaced.load()) late_calls.fetch_add(1);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    if (replaced.load()) late_calls.fetch_add(1);  // still running after the swap returned
  });
  std::atomic<bool> logging{true};
  std::vector<std::thread> loggers;
  for (int t = 0; t < 3; ++t) {
    loggers.emplace_back([&] {
      while (logging.load()) Renderer(cross_scene(), too_stiff(), simulated_phantom_desktop_info());
    });
  }
  REQUIRE(eventually([&] { return old_calls.load() >= 10; }));
  set_log_handler([&](LogLevel, std::string_view) { new_calls.fetch_add(1); });
  replaced.store(true);
  REQUIRE(eventually([&] { return new_calls.load() >= 10; }));
  logging.store(false);
  for (std::thread& thread : loggers) thread.join();
  CHECK(late_calls.load() == 0);
}

TEST_CASE("unseen14e: a handler that throws or changes the level is contained and the log goes on",
          "[unseen14e]") {
  LogRestorer restore;
  set_log_level(LogLevel::info);
  std::atomic<int> calls{0};
  // The header forbids only set_log_handler inside the handler; set_log_level is not forbidden.
  set_log_handler([&](LogLevel, std::string_view) {
    const int n = calls.fetch_add(1);
    if (n % 2 == 0) set_log_level(LogLevel::info);
    throw std::runtime_error("the application's handler failed");
  });
  auto done = std::async(std::launch::async, [] {
    on_threads([](int) {
      for (int i = 0; i < 3; ++i) Renderer(cross_scene(), too_stiff(), simulated_phantom_desktop_info());
    });
  });
  const bool finished = done.wait_for(std::chrono::seconds(20)) == std::future_status::ready;
  REQUIRE(finished);  // a deadlock would hang here (and in the future's destructor)
  CHECK_NOTHROW(done.get());
  CHECK(calls.load() == kThreads * 3);
}

TEST_CASE("unseen14e: handlers and levels changed from many threads while a loop logs late ticks never hang",
          "[unseen14e]") {
  LogRestorer restore;
  Stylus stylus;
  stylus.open();
  std::atomic<std::uint64_t> ticks{0};
  ServoLoopOptions options = relaxed_loop();
  options.max_force_age_s = 0.0005;  // every slow tick withholds its force, and the loop logs it
  ServoLoop loop(
      stylus,
      [&](const DeviceState&, double) {
        if (ticks.fetch_add(1) % 20 == 0) {
          const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(1500);
          while (std::chrono::steady_clock::now() < until) {
          }
        }
        return ServoCommand{Vec3(0.1, 0.0, 0.0), false};
      },
      options);
  loop.start();
  std::array<HandlerCalls, kThreads> calls;
  on_threads([&](int t) {
    for (int i = 0; i < 30; ++i) {
      set_log_handler(calls[t].handler());
      set_log_level(i % 3 == 0 ? LogLevel::debug : LogLevel::info);
      Renderer(cross_scene(), too_stiff(), simulated_phantom_desktop_info());
      if (i % 5 == 0) set_log_handler({});
      set_log_level(LogLevel::off);
    }
  });
  REQUIRE(eventually([&] { return ticks.load() >= 100; }));
  CHECK_FALSE(loop.stop());
  CHECK(loop.stats().forces_withheld >= 1);
  for (const HandlerCalls& each : calls) CHECK(each.overlaps.load() == 0);
  CHECK(stylus.last_force_norm.load() == 0.0);
  CHECK_FALSE(stylus.forces_enabled());
}

// ---- Value types copied and moved mid-use.

TEST_CASE("unseen14e: a renderer copied mid-stroke and its original continue identically", "[unseen14e]") {
  const Scene& scene = cross_scene();
  const std::vector<DeviceState> states = writing_states(scene);
  Renderer original(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  const std::size_t half = 40 + 200;  // down, and half way along the stroke
  render_all(original, states, 0, half);
  REQUIRE(original.state() == InteractionState::writing);
  Renderer copy = original;
  CHECK(&copy.scene() == &scene);
  const std::vector<RenderOutput> a = render_all(original, states, half);
  const std::vector<RenderOutput> b = render_all(copy, states, half);
  CHECK(same_outputs(a, b));
  CHECK(copy.active().strokes_written() == original.active().strokes_written());
  CHECK(original.active().strokes_written() == 1);
}

TEST_CASE(
    "unseen14e: a renderer moved mid-stroke continues as its original would, and its moved-from "
    "source takes a new value",
    "[unseen14e]") {
  const Scene& scene = cross_scene();
  const std::vector<DeviceState> states = writing_states(scene);
  const std::size_t half = 40 + 200;
  Renderer reference(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  Renderer source(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  render_all(reference, states, 0, half);
  render_all(source, states, 0, half);
  Renderer moved = std::move(source);
  CHECK(same_outputs(render_all(moved, states, half), render_all(reference, states, half)));
  // The moved-from renderer is given a fresh value and renders the whole stroke as a new one does.
  source = Renderer(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  Renderer fresh(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  CHECK(same_outputs(render_all(source, states), render_all(fresh, states)));
}

TEST_CASE("unseen14e: a renderer assigned to itself mid-stroke continues as if nothing happened",
          "[unseen14e]") {
  const Scene& scene = cross_scene();
  const std::vector<DeviceState> states = writing_states(scene);
  const std::size_t half = 40 + 150;
  Renderer reference(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  Renderer renderer(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  render_all(reference, states, 0, half);
  render_all(renderer, states, 0, half);
  Renderer& alias = renderer;
  renderer = alias;
  CHECK(same_outputs(render_all(renderer, states, half), render_all(reference, states, half)));
}

TEST_CASE("unseen14e: reset() mid-stroke answers the same pen as a renderer built afresh", "[unseen14e]") {
  const Scene& scene = cross_scene();
  const std::vector<DeviceState> states = writing_states(scene);
  Renderer used(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  render_all(used, states, 0, 40 + 200);
  used.reset();
  CHECK(used.state() == InteractionState::separation);
  CHECK(used.active().stroke_index() == 0);
  CHECK(used.active().strokes_written() == 0);
  // The same pen again, from the top, on its own time stamps after the reset.
  std::vector<DeviceState> again = states;
  for (DeviceState& state : again) state.time_s += 10.0;
  Renderer fresh(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  const std::vector<RenderOutput> a = render_all(used, again);
  const std::vector<RenderOutput> b = render_all(fresh, again);
  std::size_t first_difference = a.size();
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!same_output(a[i], b[i])) {
      first_difference = i;
      break;
    }
  }
  INFO("first tick that differs: " << first_difference);
  CHECK(first_difference == a.size());
}

TEST_CASE(
    "unseen14e: an active stroke copied mid-stroke finishes it as the original, and resetting one "
    "leaves the other",
    "[unseen14e]") {
  const Scene& scene = cross_scene();
  // The pen along the first stroke in 1 ms steps (the states in the paper of `writing_states`).
  std::vector<Vec2> points;
  for (const DeviceState& state : writing_states(scene)) {
    if (state.position_m.z() < scene.layout.paper_z_m) points.emplace_back(state.position_m.head<2>());
  }
  ActiveStroke original(scene);
  original.begin(points.front());
  for (std::size_t i = 0; i < points.size() / 2; ++i) original.advance(points[i]);
  REQUIRE(original.strokes_written() == 0);
  ActiveStroke copy = original;
  StrokeProgress a;
  StrokeProgress b;
  for (std::size_t i = points.size() / 2; i < points.size(); ++i) {
    a = original.advance(points[i]);
    b = copy.advance(points[i]);
    REQUIRE(a.elements_passed == b.elements_passed);
    REQUIRE(a.stroke_completed == b.stroke_completed);
  }
  const StrokeProgress la = original.stroke_index() == 0 ? original.lift() : StrokeProgress{};
  const StrokeProgress lb = copy.stroke_index() == 0 ? copy.lift() : StrokeProgress{};
  CHECK(la.stroke_completed == lb.stroke_completed);
  CHECK(la.refusal == lb.refusal);
  INFO("refusal " << to_string(la.refusal));
  CHECK(original.strokes_written() == 1);
  CHECK(copy.strokes_written() == 1);
  CHECK(copy.stroke_index() == original.stroke_index());
  original.reset();
  CHECK(original.strokes_written() == 0);
  CHECK(copy.strokes_written() == 1);
  CHECK(copy.stroke_index() == 1);
  ActiveStroke& alias = copy;
  copy = alias;
  CHECK(copy.strokes_written() == 1);
  CHECK(copy.stroke() == &scene.characters.front().strokes[1]);
}

TEST_CASE("unseen14e: ticking() reads only the rate, so the renderer may go before the loop starts",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<int> ticks{0};
  auto renderer = std::make_unique<Renderer>(cross_scene(), ForceLawParameters{}, stylus.info());
  ServoLoop loop(stylus,
                 ticking(*renderer,
                         [&](const DeviceState&, double) {
                           return ServoCommand{Vec3::Zero(), ticks.fetch_add(1) >= 20};
                         }),
                 relaxed_loop());
  renderer.reset();  // destroyed: the loop holds its rate, not the renderer
  loop.start();
  CHECK_NOTHROW(loop.wait());
  CHECK(ticks.load() == 21);
  // The same at another rate is refused by start(), naming both rates, after the renderer is gone.
  RendererOptions fast;
  fast.rate_hz = 2000.0;
  auto other = std::make_unique<Renderer>(cross_scene(), ForceLawParameters{}, stylus.info(), fast);
  ServoLoop refused(stylus, ticking(*other, [](const DeviceState&, double) { return ServoCommand{}; }),
                    relaxed_loop());
  other.reset();
  CHECK_THROWS_WITH(refused.start(), Contains("RendererOptions::rate_hz") && Contains("2000"));
  CHECK_FALSE(refused.running());
}

// ---- Callbacks that call back into the loop, throw late, or outlive their loop's thread.

TEST_CASE("unseen14e: running() and options() asked from inside the callback answer the running loop",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<ServoLoop*> self{nullptr};
  std::atomic<int> not_running{0};
  std::atomic<int> wrong_rate{0};
  std::atomic<int> ticks{0};
  ServoLoop loop(
      stylus,
      [&](const DeviceState&, double) {
        ServoLoop* me = self.load();
        if (me != nullptr) {
          if (!me->running()) not_running.fetch_add(1);
          if (me->options().rate_hz != 2000.0) wrong_rate.fetch_add(1);
        }
        return ServoCommand{Vec3::Zero(), ticks.fetch_add(1) >= 50};
      },
      relaxed_loop(2000.0));
  self.store(&loop);
  loop.start();
  CHECK_NOTHROW(loop.wait());
  CHECK(not_running.load() == 0);
  CHECK(wrong_rate.load() == 0);
  CHECK_FALSE(loop.running());
}

TEST_CASE("unseen14e: stop() called from the after-write hook requests the stop and returns at once",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<ServoLoop*> self{nullptr};
  std::atomic<int> hooks{0};
  std::atomic<int> faults_seen{0};
  ServoLoop loop(
      stylus,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.2, 0.0, 0.0), false};
      },
      relaxed_loop(),
      [&] {
        if (hooks.fetch_add(1) == 10) {
          ServoLoop* me = self.load();
          if (me != nullptr && me->stop()) faults_seen.fetch_add(1);
        }
      });
  self.store(&loop);
  loop.start();
  auto waited = std::async(std::launch::async, [&] { loop.wait(); });
  REQUIRE(waited.wait_for(std::chrono::seconds(10)) == std::future_status::ready);
  CHECK_NOTHROW(waited.get());
  CHECK(hooks.load() >= 11);
  CHECK(hooks.load() < 1000);  // it did stop
  CHECK(faults_seen.load() == 0);
  CHECK_FALSE(loop.stats().fault);
  CHECK(stylus.last_force_norm.load() == 0.0);
  CHECK_FALSE(stylus.forces_enabled());
}

TEST_CASE("unseen14e: a callback that throws at its 1000th tick ends the run there, force zero, forces off",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<int> calls{0};
  ServoLoop loop(
      stylus,
      [&](const DeviceState&, double) {
        if (calls.fetch_add(1) + 1 == 1000) throw std::length_error("tick 1000 ran out of road");
        return ServoCommand{Vec3(0.5, 0.0, 0.0), false};
      },
      relaxed_loop(10000.0));
  loop.start();
  CHECK_THROWS_AS(loop.wait(), std::length_error);
  const ServoLoopStats stats = loop.stats();
  CHECK(stats.fault.kind == LoopFaultKind::callback);
  CHECK(stats.fault.message == "tick 1000 ran out of road");
  CHECK(calls.load() == 1000);
  CHECK(stylus.reads.load() == 1000);
  CHECK(stylus.last_force_norm.load() == 0.0);
  CHECK_FALSE(stylus.forces_enabled());
}

TEST_CASE("unseen14e: an after-write hook that throws at its fifth call ends the run as a callback fault",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<int> hooks{0};
  ServoLoop loop(
      stylus,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3(0.5, 0.0, 0.0), false};
      },
      relaxed_loop(),
      [&] {
        if (hooks.fetch_add(1) + 1 == 5) throw DataError("the simulated world could not step");
      });
  loop.start();
  CHECK_THROWS_AS(loop.wait(), DataError);
  CHECK(loop.stats().fault.kind == LoopFaultKind::callback);
  CHECK_THAT(loop.stats().fault.message, Contains("could not step"));
  CHECK(hooks.load() == 5);
  CHECK(stylus.last_force_norm.load() == 0.0);
  CHECK_FALSE(stylus.forces_enabled());
  // The loop can run again after the fault, without the fault.
  hooks.store(100);
  loop.start();
  CHECK(eventually([&] { return hooks.load() > 110; }));
  CHECK_FALSE(loop.stop());
}

TEST_CASE("unseen14e: a running loop destroyed from another thread stops there, force zero, forces off",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<int> ticks{0};
  auto loop = std::make_unique<ServoLoop>(
      stylus,
      [&](const DeviceState&, double) {
        ticks.fetch_add(1);
        return ServoCommand{Vec3(0.0, 1.0, 0.0), false};
      },
      relaxed_loop());
  loop->start();
  REQUIRE(eventually([&] { return ticks.load() >= 20; }));
  std::thread destroyer([&] { loop.reset(); });
  destroyer.join();
  const std::uint64_t writes = stylus.writes.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  CHECK(stylus.writes.load() == writes);  // nothing ticks any more
  CHECK(stylus.last_force_norm.load() == 0.0);
  CHECK_FALSE(stylus.forces_enabled());
  // The device serves a new loop.
  ServoLoop next(
      stylus,
      [](const DeviceState&, double) {
        return ServoCommand{Vec3::Zero(), true};
      },
      relaxed_loop());
  next.start();
  CHECK_NOTHROW(next.wait());
}

TEST_CASE("unseen14e: stop() from three threads at once while a fourth waits: all return, no fault",
          "[unseen14e]") {
  for (int round = 0; round < 5; ++round) {
    Stylus stylus;
    stylus.open();
    std::atomic<int> ticks{0};
    ServoLoop loop(
        stylus,
        [&](const DeviceState&, double) {
          ticks.fetch_add(1);
          return ServoCommand{Vec3(0.3, 0.0, 0.0), false};
        },
        relaxed_loop());
    loop.start();
    REQUIRE(eventually([&] { return ticks.load() >= 5; }));
    auto waiter = std::async(std::launch::async, [&] { loop.wait(); });
    std::array<LoopFault, 3> faults;
    std::vector<std::thread> stoppers;
    for (int i = 0; i < 3; ++i) stoppers.emplace_back([&, i] { faults[i] = loop.stop(); });
    for (std::thread& thread : stoppers) thread.join();
    for (const LoopFault& fault : faults) CHECK_FALSE(fault);
    const bool returned = waiter.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
    INFO("round " << round);
    REQUIRE(returned);
    CHECK_NOTHROW(waiter.get());
    CHECK_FALSE(loop.running());
    CHECK(stylus.last_force_norm.load() == 0.0);
    CHECK_FALSE(stylus.forces_enabled());
  }
}

TEST_CASE("unseen14e: a loop started and stopped 30 times in a row leaves the force off each time",
          "[unseen14e]") {
  Stylus stylus;
  stylus.open();
  std::atomic<int> ticks{0};
  ServoLoop loop(
      stylus,
      [&](const DeviceState&, double) {
        ticks.fetch_add(1);
        return ServoCommand{Vec3(0.4, 0.0, 0.0), false};
      },
      relaxed_loop());
  for (int i = 0; i < 30; ++i) {
    loop.start();
    CHECK(loop.running());
    if (i % 2 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    CHECK_FALSE(loop.stop());
    CHECK_FALSE(loop.running());
    CHECK(stylus.last_force_norm.load() == 0.0);
    CHECK_FALSE(stylus.forces_enabled());
  }
  CHECK(ticks.load() >= 1);
}

TEST_CASE("unseen14e: a display thread never reads a torn snapshot while a servo loop steps the trial",
          "[unseen14e]") {
  const Scene& scene = cross_scene();
  Stylus stylus;
  // Read k: the pen at x = k um, on a clock that reads k ms (the trial's clock then reads k - 1 ms: it starts
  // at 0 with the first tick): a snapshot whose fields come from two ticks shows it.
  stylus.reading = [](std::uint64_t k, DeviceState& state) {
    state.position_m = Vec3(1e-6 * static_cast<double>(k), 0.0, 0.03);
    state.time_s = 1e-3 * static_cast<double>(k);
  };
  stylus.open();
  DisplayChannel channel;
  TrialOptions options;
  options.rate_hz = 1000.0;
  options.max_duration_s = 0.4;
  options.display = &channel;
  TrialSession session(scene, stylus.info(), options);
  session.reserve_trace();
  ServoLoop loop(stylus, session.servo_callback(), relaxed_loop());
  std::atomic<bool> reading{true};
  std::atomic<long> torn{0};
  std::atomic<long> read{0};
  std::atomic<long> backwards{0};
  std::array<std::atomic<double>, 3> first_torn{};  // tick, HIP x, time of the first torn snapshot
  std::vector<std::thread> readers;
  for (int r = 0; r < 2; ++r) {
    readers.emplace_back([&] {
      std::uint64_t last = 0;
      while (reading.load()) {
        DisplaySnapshot now;
        if (!channel.try_latest(now)) continue;
        if (now.tick == 0) continue;
        read.fetch_add(1);
        const double k = static_cast<double>(now.tick);
        if (std::abs(now.hip_m.x - 1e-6 * k) > 1e-12 || std::abs(now.time_s - 1e-3 * (k - 1.0)) > 1e-9) {
          if (torn.fetch_add(1) == 0) {
            first_torn[0] = k;
            first_torn[1] = now.hip_m.x;
            first_torn[2] = now.time_s;
          }
        }
        if (now.tick < last) backwards.fetch_add(1);
        last = now.tick;
      }
    });
  }
  loop.start();
  CHECK_NOTHROW(loop.wait());
  reading.store(false);
  for (std::thread& thread : readers) thread.join();
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.trace.size() == 400);
  CHECK(read.load() > 0);
  INFO("first torn snapshot: tick " << first_torn[0].load() << ", HIP x " << first_torn[1].load()
                                    << " m, time " << first_torn[2].load() << " s");
  CHECK(torn.load() == 0);
  CHECK(backwards.load() == 0);
  CHECK(channel.latest().tick == 400);
}

TEST_CASE(
    "unseen14e: a device whose clock stops mid-trial on a servo loop: ticks go on, the record stays "
    "finite and in order",
    "[unseen14e]") {
  const Scene& scene = cross_scene();
  Stylus stylus;
  stylus.reading = [](std::uint64_t k, DeviceState& state) {
    state.time_s = 100.0 + 1e-3 * static_cast<double>(std::min<std::uint64_t>(k, 50));  // stops at tick 50
  };
  stylus.open();
  TrialOptions options;
  options.max_duration_s = 0.2;
  TrialSession session(scene, stylus.info(), options);
  session.reserve_trace();
  ServoLoop loop(stylus, session.servo_callback(), relaxed_loop());
  loop.start();
  CHECK_NOTHROW(loop.wait());
  const TrialResult result = session.finish(TrialEnd::time_limit);
  REQUIRE(result.trace.size() == 200);
  for (std::size_t i = 1; i < result.trace.size(); ++i) {
    REQUIRE(std::isfinite(result.trace[i].time_s));
    REQUIRE(result.trace[i].time_s >= result.trace[i - 1].time_s);
  }
  CHECK(result.trace.back().time_s == Approx(0.049).margin(1e-9));
  CHECK(std::isfinite(result.metrics.time_s));
  CHECK(result.metrics.time_s >= 0.0);
  CHECK_FALSE(stylus.forces_enabled());
}

// ---- The servo path's promise: no allocation after the warm-up.

TEST_CASE("unseen14e: the loop thread never allocates while its ticks run late, are withheld and logged",
          "[unseen14e]") {
  using testing::count_this_thread;
  using testing::counted_allocations;
  if constexpr (testing::kCountsAllocations) {  // the counter sees a counted allocation (so the check can
                                                // fail)
    const long before = counted_allocations.load();
    count_this_thread = true;
    auto* probe = new std::vector<int>(100);
    count_this_thread = false;
    delete probe;
    REQUIRE(counted_allocations.load() > before);
  }
  LogRestorer restore;
  std::atomic<int> handled{0};
  set_log_level(LogLevel::debug);
  set_log_handler([&](LogLevel, std::string_view) { handled.fetch_add(1); });
  const Scene& scene = cross_scene();
  Stylus stylus;
  const auto& points = scene.characters.front().strokes.front().centre_line.points_m;
  const Vec2 start = points.front();
  stylus.reading = [start](std::uint64_t k, DeviceState& state) {
    // Down onto the first stroke and along it: the renderer goes through its states.
    const double s = std::min(1.0, static_cast<double>(k) / 300.0);
    state.position_m = Vec3(start.x() + 0.02 * s, start.y(), k < 30 ? 0.01 : -0.002);
  };
  stylus.open();
  DisplayChannel channel;
  TrialOptions trial;
  trial.max_duration_s = 0.4;
  trial.display = &channel;
  TrialSession session(scene, stylus.info(), trial);
  session.reserve_trace();
  ServoLoopOptions options = relaxed_loop();
  options.max_force_age_s = 0.001;  // a 1.5 ms tick withholds its force
  std::atomic<long> allocations{0};
  std::atomic<int> tick{0};
  ServoLoop loop(
      stylus,
      [&](const DeviceState& state, double) {
        const int k = tick.fetch_add(1) + 1;
        if (k == 10) {  // the documented warm-up is over: count everything this thread does from here
          count_this_thread = true;
          allocations.store(counted_allocations.load());
        }
        if (k % 50 == 0) {  // late: the loop withholds the force, counts and logs it
          const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(1500);
          while (std::chrono::steady_clock::now() < until) {
          }
        }
        return session.step(state);
      },
      options);
  loop.start();
  CHECK_NOTHROW(loop.wait());
  const long counted = counted_allocations.load() - allocations.load();
  const TrialResult result = session.finish(TrialEnd::time_limit);
  CHECK(result.trace.size() == 400);
  CHECK(loop.stats().forces_withheld >= 1);
  if constexpr (testing::kCountsAllocations) {
    CHECK(counted == 0);
  } else {
    SUCCEED("malloc belongs to the sanitizer here");
  }
}

TEST_CASE(
    "unseen14e: a display thread draining a tiny trace queue while the loop ticks loses no point unseen",
    "[unseen14e]") {
  const Scene& scene = cross_scene();
  Stylus stylus;
  stylus.open();
  DisplayChannelOptions queues;
  queues.trace_capacity = 4;  // far smaller than the ticks between two drains: most points are dropped
  queues.event_capacity = 4;
  DisplayChannel channel(queues);
  TrialOptions options;
  options.max_duration_s = 0.3;
  options.display = &channel;
  TrialSession session(scene, stylus.info(), options);
  session.reserve_trace();
  ServoLoop loop(stylus, session.servo_callback(), relaxed_loop());
  std::atomic<bool> draining{true};
  std::uint64_t received = 0;
  std::uint64_t out_of_order = 0;
  std::thread display([&] {
    std::uint64_t last = 0;
    auto drain = [&] {
      for (TracePoint point; channel.poll_trace(point);) {
        ++received;
        if (point.tick <= last) ++out_of_order;
        last = point.tick;
      }
    };
    while (draining.load()) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // a slow display frame
    }
    drain();
  });
  loop.start();
  CHECK_NOTHROW(loop.wait());
  draining.store(false);
  display.join();
  const TrialResult result = session.finish(TrialEnd::time_limit);
  REQUIRE(result.trace.size() == 300);
  CHECK(out_of_order == 0);
  CHECK(channel.dropped_trace_points() > 0);
  CHECK(received + channel.dropped_trace_points() == 300);  // every point either drawn or counted as dropped
}

TEST_CASE(
    "unseen14e: a device registry moved while in use keeps its backends in the new one, and the "
    "moved-from one takes a new value",
    "[unseen14e]") {
  DeviceRegistry registry;
  register_simulated_device(registry);
  const std::unique_ptr<HapticDevice> before = registry.create("simulated");
  DeviceRegistry moved = std::move(registry);
  CHECK(moved.backend_names() == std::vector<std::string>{"simulated"});
  const std::unique_ptr<HapticDevice> after = moved.create("simulated");
  REQUIRE(after != nullptr);
  CHECK(after->info().model == before->info().model);
  registry = DeviceRegistry{};  // the moved-from registry given a fresh value works as a new one
  CHECK(registry.backend_names().empty());
  CHECK_THROWS_AS(registry.create("simulated"), DeviceNotFound);
  register_simulated_device(registry);
  CHECK(registry.create("simulated") != nullptr);
  DeviceRegistry& alias = moved;
  moved = std::move(alias);  // self-move-assignment: the header promises nothing of the value, only no crash
  CHECK_NOTHROW(moved.backend_names());
}

TEST_CASE("unseen14e: two real-time trials at once, each interrupted from the main thread, keep every tick",
          "[unseen14e]") {
  const Scene& scene = cross_scene();
  std::array<Stylus, 2> styluses;
  std::array<std::atomic<bool>, 2> interrupt{};
  std::array<TrialResult, 2> results;
  std::vector<std::thread> trials;
  for (std::size_t i = 0; i < 2; ++i) {
    trials.emplace_back([&, i] {
      TrialOptions options;
      options.max_duration_s = 30.0;
      options.loop = relaxed_loop();
      options.should_stop = [&, i] { return interrupt[i].load(); };
      results[i] = run_trial(styluses[i], scene, options);
    });
  }
  REQUIRE(eventually([&] { return styluses[0].reads.load() >= 30 && styluses[1].reads.load() >= 30; }));
  interrupt[0].store(true);
  REQUIRE(eventually([&] { return styluses[1].reads.load() >= 60; }));
  interrupt[1].store(true);
  for (std::thread& trial : trials) trial.join();
  for (std::size_t i = 0; i < 2; ++i) {
    INFO("trial " << i);
    CHECK(results[i].end == TrialEnd::interrupted);
    CHECK(results[i].aborted);
    CHECK(results[i].trace.size() == styluses[i].reads.load());  // every tick read was recorded
    CHECK(results[i].trace.size() >= 30);
    CHECK(styluses[i].last_force_norm.load() == 0.0);
    CHECK_FALSE(styluses[i].forces_enabled());
    CHECK_FALSE(styluses[i].is_open());
  }
}
