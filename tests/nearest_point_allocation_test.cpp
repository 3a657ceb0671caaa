// The nearest-point queries and the tracker's update run on the servo thread: they must not
// allocate. Counts calls of the global operator new (replaced for this test binary; it only counts).
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <new>

#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/model/nearest_point_tracker.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/trial/trial.hpp"

// AddressSanitizer owns operator new/delete; replacing them there mixes its allocator with ours
// (alloc-dealloc-mismatch at exit). The Release build runs this test; the ASan build leaves it out.
#if !defined(CALLIGRAPHY_TEST_SANITIZED)
namespace {
std::atomic<long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
  throw std::bad_alloc();
}
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }

TEST_CASE("Nearest-point queries and tracker updates do not allocate", "[nearest_point][tracker]") {
  using calligraphy::Vec2;
  const Vec2 points[5] = {Vec2(0, 0), Vec2(0.03, 0.03), Vec2(0, 0.03), Vec2(0.03, 0), Vec2(0.05, 0.02)};
  const calligraphy::StrokeElement elements[4] = {
      calligraphy::StrokeElement::line(points[0], points[1]), calligraphy::StrokeElement::bezier(points, 3),
      calligraphy::StrokeElement::bezier(points, 4), calligraphy::StrokeElement::bezier(points, 5)};
  calligraphy::NearestPointTracker tracker;
  calligraphy::NearestPointOptions options;
  const long before = allocations.load();
  double sum = 0.0;
  for (const auto& element : elements) {
    for (const auto method : {calligraphy::NearestPointMethod::exact, calligraphy::NearestPointMethod::newton,
                              calligraphy::NearestPointMethod::subdivision}) {
      options.method = method;
      for (int i = 0; i < 50; ++i)
        sum += calligraphy::nearest_point(element, Vec2(0.001 * i, 0.01), options).distance;
    }
    tracker.reset();
    for (int i = 0; i < 50; ++i) sum += tracker.update(element, Vec2(0.001 * i, 0.01)).distance;
  }
  sum += calligraphy::nearest_point_on_segment(points[0], points[1], points[2]).distance;
  CHECK(allocations.load() == before);
  CHECK(sum > 0.0);
}
TEST_CASE("Renderer ticks (smoothing, passivity controller, safety chain) do not allocate", "[safety]") {
  using namespace calligraphy;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'永')});
  TrialOptions trial;
  SimulationOptions simulation;
  simulation.seed = 1;
  const TrialResult recorded = run_simulated_trial(scene, trial, simulation);  // positions of a real trial
  REQUIRE(recorded.trace.size() > 1000);
  RendererOptions options;
  options.passivity.enabled = true;
  options.safety.low_pass_cutoff_hz = 100.0;
  Renderer renderer(scene, ForceLawParameters{}, simulated_phantom_desktop_info(), options);
  const long before = allocations.load();
  double sum = 0.0;
  for (std::size_t k = 1; k < recorded.trace.size(); ++k) {
    DeviceState state;
    state.position_m = recorded.trace[k].position_m;
    state.velocity_m_s = (recorded.trace[k].position_m - recorded.trace[k - 1].position_m) * 1000.0;
    sum += renderer.tick(state).force_n.norm();
  }
  CHECK(allocations.load() == before);
  CHECK(sum > 0.0);
}
#endif  // !defined(CALLIGRAPHY_TEST_SANITIZED)
