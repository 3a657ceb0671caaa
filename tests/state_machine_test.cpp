#include <catch2/catch.hpp>

#include "calligraphy/render/interaction_state.hpp"

using namespace calligraphy;
using S = InteractionState;

TEST_CASE("Every transition of the STG (Fig. 6)", "[states]") {
  const StateInputs lifted{false, true, true};
  const StateInputs outside_box{true, false, false};
  const StateInputs in_box{true, true, false};
  const StateInputs at_start{true, true, true};
  // From SS.
  CHECK(next_state(S::separation, lifted) == S::separation);
  CHECK(next_state(S::separation, outside_box) == S::adjusting);
  CHECK(next_state(S::separation, in_box) == S::calibration);
  CHECK(next_state(S::separation, at_start) == S::writing);
  // From AS.
  CHECK(next_state(S::adjusting, lifted) == S::separation);
  CHECK(next_state(S::adjusting, outside_box) == S::adjusting);
  CHECK(next_state(S::adjusting, in_box) == S::calibration);
  CHECK(next_state(S::adjusting, at_start) == S::writing);
  // From CS.
  CHECK(next_state(S::calibration, lifted) == S::separation);
  CHECK(next_state(S::calibration, outside_box) == S::adjusting);
  CHECK(next_state(S::calibration, in_box) == S::calibration);
  CHECK(next_state(S::calibration, at_start) == S::writing);
  // From WS: writing goes on while touching, wherever the tip goes; lifting ends it.
  CHECK(next_state(S::writing, lifted) == S::separation);
  CHECK(next_state(S::writing, outside_box) == S::writing);
  CHECK(next_state(S::writing, in_box) == S::writing);
  CHECK(next_state(S::writing, at_start) == S::writing);
  CHECK(std::string(to_string(S::writing)) == "WS");
  CHECK(std::string(to_string(S::separation)) == "SS");
}
