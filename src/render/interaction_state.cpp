#include "calligraphy/render/interaction_state.hpp"

namespace calligraphy {

const char* to_string(InteractionState state) noexcept {
  switch (state) {
    case InteractionState::separation:
      return "SS";
    case InteractionState::adjusting:
      return "AS";
    case InteractionState::calibration:
      return "CS";
    case InteractionState::writing:
      return "WS";
  }
  return "?";
}

InteractionState next_state(InteractionState current, const StateInputs& in) noexcept {
  if (!in.touching) return InteractionState::separation;
  if (current == InteractionState::writing) return InteractionState::writing;
  if (in.in_start_neighbourhood) return InteractionState::writing;
  return in.inside_box ? InteractionState::calibration : InteractionState::adjusting;
}

}  // namespace calligraphy
