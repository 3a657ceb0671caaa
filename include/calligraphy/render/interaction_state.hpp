#pragma once
/// \file interaction_state.hpp
/// Interaction states of the virtual pen tip (VTP) and the paper (paper section 2.3, Tables 1-2, the
/// state transition graph of Fig. 6).
#include <cstdint>

namespace calligraphy {

enum class InteractionState : std::uint8_t {
  separation,   ///< SS: VTP not touching the paper. Zero force.
  adjusting,    ///< AS: touching, outside the active character's bounding box. Zero force.
  calibration,  ///< CS: touching, inside the box, not in the active stroke's start neighbourhood. Normal
                ///< force only.
  writing,      ///< WS: touching, entered at the start neighbourhood, writing. Normal and in-plane forces.
};

/// "SS", "AS", "CS" or "WS".
const char* to_string(InteractionState state) noexcept;

/// What the state machine needs to know each tick.
struct StateInputs {
  bool touching = false;                ///< the tip is at or below the paper plane
  bool inside_box = false;              ///< inside the active character's bounding box
  bool in_start_neighbourhood = false;  ///< within the start radius of the active stroke's start point
};

/// One step of the STG (Fig. 6): lifting always gives SS; WS persists while touching; otherwise the
/// touching states are chosen by the box and the start neighbourhood.
InteractionState next_state(InteractionState current, const StateInputs& inputs) noexcept;

}  // namespace calligraphy
