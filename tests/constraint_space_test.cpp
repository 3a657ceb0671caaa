#include "calligraphy/collision/constraint_space.hpp"

#include <catch2/catch.hpp>

using namespace calligraphy;

TEST_CASE("LSE constraint space rules (a)-(d) of section 4.3.1", "[collision]") {
  const Vec2 a(0.0, 0.0);
  const Vec2 b(0.02, 0.0);  // a 20 mm horizontal
  // (a) P1 . PEdge < 0: behind the start, outside.
  CHECK_FALSE(lse_rules_inside(a, b, Vec2(-0.001, 0.001)));
  // (b) P1 . PEdge > 0 but |P1| > |PEdge|: past the end, outside.
  CHECK_FALSE(lse_rules_inside(a, b, Vec2(0.021, 0.0)));
  CHECK_FALSE(lse_rules_inside(a, b, Vec2(0.0199, 0.003)));  // |P1| = 20.12 mm > 20 mm
  // (c) P1 . PEdge > 0 and |P1| < |PEdge|: inside.
  CHECK(lse_rules_inside(a, b, Vec2(0.01, 0.004)));
  CHECK(lse_rules_inside(a, b, Vec2(0.019, -0.002)));
  // (d) start == end: inside wherever the tip is.
  CHECK(lse_rules_inside(a, a, Vec2(0.05, -0.03)));
}

TEST_CASE("Element contact adds the radius R_res to the rules", "[collision]") {
  const auto lse = StrokeElement::line(Vec2(0.0, 0.0), Vec2(0.02, 0.0));
  const NearestPointOptions exact;
  auto c = element_contact(lse, Vec2(0.01, 0.004), 0.006, exact);
  CHECK(c.inside);
  CHECK(c.nearest.foot.isApprox(Vec2(0.01, 0.0)));
  CHECK(c.nearest.distance == Approx(0.004));
  CHECK_FALSE(element_contact(lse, Vec2(0.01, 0.007), 0.006, exact).inside);

  const Vec2 arc[3] = {{0.0, 0.0}, {0.01, 0.01}, {0.02, 0.0}};
  const auto cse = StrokeElement::bezier(arc, 3);
  c = element_contact(cse, Vec2(0.01, 0.003), 0.006, exact);  // below the apex (0.01, 0.005)
  CHECK(c.inside);
  CHECK(c.nearest.foot.x() == Approx(0.01));
  CHECK(c.nearest.distance == Approx(0.002).margin(1e-9));
  CHECK_FALSE(element_contact(cse, Vec2(-0.002, -0.002), 0.006, exact).inside);  // behind the start
  CHECK_FALSE(element_contact(cse, Vec2(0.022, -0.002), 0.006, exact).inside);   // past the end
}

TEST_CASE("Eq. (6): a feature plane is passed when V_t . V_f > 0", "[collision]") {
  const auto lse = StrokeElement::line(Vec2(0.0, 0.0), Vec2(0.0, -0.02));  // a vertical written downwards
  CHECK_FALSE(feature_plane_passed(lse, Vec2(0.003, -0.019)));
  CHECK(feature_plane_passed(lse, Vec2(0.003, -0.0201)));
  CHECK_FALSE(feature_plane_passed(lse, Vec2(0.0, -0.02)));  // on the plane: not yet written
}
