#include "calligraphy/render/force_law.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/safety_chain.hpp"

using namespace calligraphy;

TEST_CASE("Eq. (9): the paper pushes a penetrating tip out with K_en times the depth", "[force]") {
  const Vec3 f = paper_force(-0.002, 0.0, 800.0);  // 2 mm below the paper
  CHECK(f.x() == 0.0);
  CHECK(f.y() == 0.0);
  CHECK(f.z() == Approx(1.6));                     // 800 N/m * 2 mm, out of the paper (+z)
  CHECK(paper_force(0.001, 0.0, 800.0).isZero());  // above the paper: nothing
  CHECK(paper_force(0.0105, 0.01, 1000.0).isZero());
  CHECK(paper_force(0.0095, 0.01, 1000.0).z() == Approx(0.5));  // z0 = 10 mm
}

TEST_CASE("Eq. (8): the attraction pulls the tip towards X_S, scaled by the attraction factor", "[force]") {
  const Vec2 tip(0.010, 0.003);
  const Vec2 foot(0.010, 0.0);
  const Vec2 f = attraction_force(tip, foot, 400.0, 1.5);
  CHECK(f.x() == Approx(0.0).margin(1e-15));
  CHECK(f.y() == Approx(-1.8));  // 400 N/m * 1.5 * 3 mm, towards the stroke
  CHECK(attraction_force(foot, foot, 400.0, 1.0).isZero());
}

TEST_CASE("Resistance opposes only backward motion along the element (Fig. 4)", "[force]") {
  const Vec2 t(1.0, 0.0);
  CHECK(resistance_force(Vec2(0.02, 0.01), t, 15.0).isZero());  // forward: free
  const Vec2 back = resistance_force(Vec2(-0.02, 0.01), t, 15.0);
  CHECK(back.x() == Approx(0.3));  // 15 N s/m * 20 mm/s, pushing forward
  CHECK(back.y() == 0.0);
}

TEST_CASE("Clamping keeps the direction and removes non-finite forces", "[force]") {
  const Vec3 f = clamp_force(Vec3(6.0, 8.0, 0.0), 5.0);
  CHECK(f.norm() == Approx(5.0));
  CHECK(f.x() / f.y() == Approx(0.75));
  CHECK(clamp_force(Vec3(1.0, 0.0, 0.0), 5.0) == Vec3(1.0, 0.0, 0.0));
  CHECK(clamp_force(Vec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0), 5.0).isZero());
  CHECK(clamp_force(Vec3(std::numeric_limits<double>::infinity(), 0.0, 0.0), 5.0).isZero());
}

TEST_CASE("Force-law parameters are validated", "[force]") {
  ForceLawParameters p;
  CHECK_NOTHROW(p.validate());
  p.constraint_radius_m = 0.0;
  CHECK_THROWS_AS(p.validate(), InvalidArgument);
  p = {};
  p.guidance_stiffness_n_per_m = -1.0;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("guidance_stiffness_n_per_m"));
}

TEST_CASE("An error names a number in its shortest form, not in six fixed decimals", "[force]") {
  // Printed as %f, a taper of 1e300 m was a 301-digit number and a radius of 1e-9 m read "0.000000".
  ForceLawParameters p;
  p.constraint_taper_m = 1e300;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("constraint_taper_m = 1e+300 m must be in"));
  p = {};
  p.constraint_radius_m = 1e-9;
  p.constraint_taper_m = 2e-9;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("= 2e-09 must not exceed constraint_radius_m = 1e-09"));
}

namespace {

// What validates `object`: the force-law parameters holding it when it is a guidance law (a replay with a
// teacher, so that only the table is at stake), else the object itself.
template <typename S>
auto holding(const S& object) {
  if constexpr (!std::is_constructible_v<GuidanceLaw, S>) {
    return object;
  } else {
    ForceLawParameters p;
    S law = object;
    if constexpr (std::is_same_v<S, ReplayGuidance>)
      law.teacher_trajectory = {TeacherSample{}, TeacherSample{}};
    p.guidance_law = law;
    return p;
  }
}

// Every entry of S's table: its default lies in its range, and the struct's validation refuses a value
// just outside each bound (and infinities and NaN), naming "Struct.field".
template <typename S>
void check_table() {
  const std::string struct_name(ParameterTable<S>::name);
  CHECK_NOTHROW(holding(S{}).validate());
  for (const ParameterField<S>& field : ParameterTable<S>::fields()) {
    const std::string qualified = struct_name + "." + std::string(field.name);
    INFO(qualified);
    CHECK(!field.doc.empty());
    CHECK(field.doc.find(':') == std::string_view::npos);  // Python's stubs would read "words:" as a type
    CHECK(field.range.contains(field.default_value()));
    CHECK(&parameter_field(field.member) == &field);
    const ParameterRange& range = field.range;
    std::vector<double> outside{std::numeric_limits<double>::quiet_NaN(),
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
    outside.push_back(range.low_open ? range.low : std::nextafter(range.low, -INFINITY));
    if (std::isfinite(range.high))
      outside.push_back(range.high_open ? range.high : std::nextafter(range.high, INFINITY));
    for (const double value : outside) {
      INFO(value);
      S object{};
      object.*field.member = value;
      CHECK_FALSE(range.contains(value));
      CHECK_THROWS_WITH(holding(object).validate(), Catch::Contains(qualified + " = "));
    }
    // Just inside each bound the table agrees (the struct's cross-field rules aside).
    CHECK(range.contains(range.low_open ? std::nextafter(range.low, INFINITY) : range.low));
    if (std::isfinite(range.high))
      CHECK(range.contains(range.high_open ? std::nextafter(range.high, -INFINITY) : range.high));
  }
}

}  // namespace

TEST_CASE("Each parameter table holds its defaults, and validation refuses just outside each bound",
          "[force]") {
  check_table<ForceLawParameters>();
  check_table<FadingGuidance>();
  check_table<ReplayGuidance>();
  check_table<AssistAsNeededGuidance>();
  check_table<ErrorAmplificationGuidance>();
  check_table<TimingGuidance>();
  CHECK(ParameterTable<FixedGuidance>::fields().empty());
  check_table<FadingRule>();
  check_table<AssistBandRule>();
  check_table<SkillAdaptiveRule>();
  check_table<StrokeAcceptance>();
}

TEST_CASE("A parameter's error names the field, its value with the unit and the range", "[force]") {
  ForceLawParameters p;
  p.constraint_radius_m = 0.0;
  CHECK_THROWS_WITH(p.validate(), "ForceLawParameters.constraint_radius_m = 0 m must be in (0, 0.1] m");
  p = {};
  p.guidance_law = FadingGuidance{.gain = 1.5};
  CHECK_THROWS_WITH(p.validate(), "FadingGuidance.gain = 1.5 must be in [0, 1]");
  p.guidance_law = TimingGuidance{.max_lead_m = 0.01};
  CHECK_THROWS_WITH(p.validate(),
                    Catch::Contains("TimingGuidance.max_lead_m") && Catch::Contains("0.006] m"));
  CHECK(parameter_field(&ForceLawParameters::friction_stick_speed_m_s).description() ==
        "stick band of the friction, viscous below it [m/s], > 0 m/s");
}

TEST_CASE("The force law's lengths, fade times and nearest-point tolerance have finite bounds", "[force]") {
  for (const auto& [field, name, bound] :
       {std::tuple{&ForceLawParameters::constraint_radius_m, "constraint_radius_m", 0.1},
        std::tuple{&ForceLawParameters::contact_hysteresis_m, "contact_hysteresis_m", 0.1},
        std::tuple{&ForceLawParameters::off_stroke_travel_m, "off_stroke_travel_m", 0.1},
        std::tuple{&ForceLawParameters::constraint_taper_m, "constraint_taper_m", 0.1},
        std::tuple{&ForceLawParameters::crossfade_s, "crossfade_s", 10.0},
        std::tuple{&ForceLawParameters::paper_fade_s, "paper_fade_s", 10.0}}) {
    INFO(name);
    ForceLawParameters p;
    p.constraint_radius_m = 0.1;  // the taper may reach it
    p.*field = bound;
    CHECK_NOTHROW(p.validate());
    p.*field = 1e308;
    CHECK_THROWS_WITH(p.validate(), Catch::Contains(name));
  }
  ForceLawParameters p;
  p.nearest.tolerance = 1e-3;
  CHECK_NOTHROW(p.validate());
  p.nearest.tolerance = 1e308;
  CHECK_THROWS_WITH(p.validate(), Catch::Contains("nearest.tolerance") && Catch::Contains("(0, 0.001]"));
  SafetyChainParameters safety;
  safety.continuous_time_constant_s = 86400.0;
  CHECK_NOTHROW(safety.validate());
  safety.continuous_time_constant_s = 1e308;
  CHECK_THROWS_WITH(safety.validate(), Catch::Contains("continuous_time_constant_s"));
}
