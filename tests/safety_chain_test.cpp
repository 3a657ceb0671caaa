// The safety chain: each stage on its own, and the renderer's use of it.
#include "calligraphy/render/safety_chain.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/render/renderer.hpp"
#include "calligraphy/devices/simulated_device.hpp"

using namespace calligraphy;

namespace {

// Only the peak clamp: the other stages off.
SafetyChainParameters clamp_only(double max_force_n) {
  SafetyChainParameters p;
  p.max_force_n = max_force_n;
  p.start_ramp_n_per_s = 0.0;
  p.max_force_change_n_per_tick = 0.0;
  return p;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST_CASE("Safety chain: a non-finite force gives zero force, the flag and a count", "[safety]") {
  SafetyChain chain(clamp_only(5.0), 1000.0);
  CHECK(chain.apply(Vec3(1.0, 0.0, 0.0)).force_n.x() == 1.0);
  for (const Vec3& bad : {Vec3(kNaN, 0.0, 0.0), Vec3(0.0, std::numeric_limits<double>::infinity(), 0.0),
                          Vec3(0.0, 0.0, -std::numeric_limits<double>::infinity())}) {
    const SafetyResult r = chain.apply(bad);
    CHECK(r.force_n.isZero());
    CHECK((r.limits & safety_non_finite) != 0);
  }
  CHECK(chain.non_finite_count() == 3);
  const SafetyResult after = chain.apply(Vec3(0.0, 0.5, 0.0));  // recovers; no NaN left in the state
  CHECK(after.force_n.allFinite());
  CHECK(after.limits == safety_none);
}

TEST_CASE("Safety chain: the peak clamp keeps the direction", "[safety]") {
  SafetyChain chain(clamp_only(2.0), 1000.0);
  const SafetyResult r = chain.apply(Vec3(3.0, 4.0, 0.0));
  CHECK(r.force_n.norm() == Approx(2.0));
  CHECK(r.force_n.normalized().isApprox(Vec3(0.6, 0.8, 0.0)));
  CHECK((r.limits & safety_peak) != 0);
}

TEST_CASE("Safety chain: the start ramp limits |F| to rate times time", "[safety]") {
  SafetyChainParameters p = clamp_only(5.0);
  p.start_ramp_n_per_s = 10.0;
  SafetyChain chain(p, 1000.0);
  for (int k = 1; k <= 600; ++k) {
    const SafetyResult r = chain.apply(Vec3(0.0, 0.0, 4.0));
    REQUIRE(r.force_n.norm() <= 10.0 * k * 1e-3 + 1e-12);
    if (k == 100) CHECK(r.force_n.z() == Approx(1.0));
  }
  CHECK(chain.last_output().z() == Approx(4.0));  // reached after 0.4 s
  chain.reset();
  CHECK(chain.apply(Vec3(0.0, 0.0, 4.0)).force_n.z() == Approx(0.01));
}

TEST_CASE("Safety chain: the per-tick change limit shortens the change along its direction", "[safety]") {
  SafetyChainParameters p = clamp_only(7.9);
  p.max_force_change_n_per_tick = 0.1;
  SafetyChain chain(p, 1000.0);
  const SafetyResult first = chain.apply(Vec3(3.0, 0.0, 4.0));  // a 5 N step
  CHECK(first.force_n.isApprox(Vec3(0.06, 0.0, 0.08)));
  CHECK((first.limits & safety_rate) != 0);
  Vec3 previous = first.force_n;
  for (int k = 0; k < 100; ++k) {
    const Vec3 target = k % 2 ? Vec3(-2.0, 1.0, 0.0) : Vec3(0.0, 3.0, 1.0);  // chatter
    const Vec3 now = chain.apply(target).force_n;
    REQUIRE((now - previous).norm() <= 0.1 + 1e-12);
    previous = now;
  }
}

TEST_CASE("Safety chain: a sustained demand settles at the continuous force", "[safety]") {
  SafetyChainParameters p = clamp_only(7.9);
  p.max_continuous_force_n = 1.75;
  p.continuous_time_constant_s = 1.0;
  SafetyChain chain(p, 1000.0);
  // A short peak passes: the RMS estimate is still low.
  CHECK(chain.apply(Vec3(0.0, 0.0, 5.0)).force_n.z() == Approx(5.0));
  bool limited = false;
  double out = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const SafetyResult r = chain.apply(Vec3(0.0, 0.0, 5.0));
    limited = limited || (r.limits & safety_continuous) != 0;
    out = r.force_n.z();
  }
  CHECK(limited);
  CHECK(out == Approx(1.75).epsilon(1e-3));
  CHECK(chain.rms_force_n() == Approx(1.75).epsilon(1e-2));
}

TEST_CASE("Safety chain: the low-pass is first order at its cutoff", "[safety]") {
  SafetyChainParameters p = clamp_only(7.9);
  p.low_pass_cutoff_hz = 10.0;
  SafetyChain chain(p, 1000.0);
  // Step response of a first-order filter: 1 - exp(-t / tau), tau = 1 / (2 pi f_c) = 15.9 ms.
  double y = 0.0;
  for (int k = 0; k < 16; ++k) y = chain.apply(Vec3(1.0, 0.0, 0.0)).force_n.x();
  CHECK(y == Approx(1.0 - std::exp(-16e-3 * 2.0 * std::numbers::pi * 10.0)).epsilon(1e-9));
}

TEST_CASE("Safety chain: parameters are validated", "[safety]") {
  CHECK_THROWS_AS(SafetyChain(SafetyChainParameters{}, 1000.0), InvalidArgument);  // no peak force
  SafetyChainParameters p = clamp_only(5.0);
  CHECK_THROWS_AS(SafetyChain(p, 0.0), InvalidArgument);
  p.max_continuous_force_n = 6.0;
  CHECK_THROWS_AS(SafetyChain(p, 1000.0), InvalidArgument);
  p = clamp_only(5.0);
  p.max_force_change_n_per_tick = -1.0;
  CHECK_THROWS_AS(SafetyChain(p, 1000.0), InvalidArgument);
  p = clamp_only(5.0);
  p.low_pass_cutoff_hz = kNaN;
  CHECK_THROWS_AS(SafetyChain(p, 1000.0), InvalidArgument);
}

TEST_CASE("Renderer: NaN input gives zero force and the safety flag, the chain's limits hold", "[safety]") {
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'口')});
  Renderer r(scene, ForceLawParameters{}, simulated_phantom_desktop_info());
  const Vec2 centre = scene.characters[0].bounding_box.center();
  DeviceState s;
  s.position_m = Vec3(centre.x(), centre.y(), scene.layout.paper_z_m - 0.004);
  Vec3 previous = Vec3::Zero();
  for (int k = 0; k < 500; ++k) {  // 3.2 N asked at once: ramped in at <= 0.25 N per tick
    const RenderOutput out = r.tick(s);
    REQUIRE((out.force_n - previous).norm() <=
            r.safety_chain().parameters().max_force_change_n_per_tick + 1e-12);
    previous = out.force_n;
  }
  CHECK(previous.z() == Approx(0.8 * 0.004 * 1000.0));
  s.position_m.y() = kNaN;
  const RenderOutput bad = r.tick(s);
  CHECK(bad.input_rejected);
  CHECK(bad.force_n.isZero());
  CHECK((bad.limits & safety_non_finite) != 0);
  CHECK(r.safety_chain().non_finite_count() == 1);
}
