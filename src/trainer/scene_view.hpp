#pragma once
// Draws the row of characters and the live trial into the window's background (paper section 7.2,
// Figs. 30-31, and Hanzi Writer's look): filled stroke outlines in light grey, the active character's in
// yellow; the reference (the fitted stroke elements) in blue; the pen's trace while writing in light
// green, a refused attempt in grey until the next touch-down; a red ellipse at the active stroke's start (at
// every stroke's start once the trial ended); the pen tip (HIP, and the VTP on the paper when the HIP is
// below it) with its height on a gauge; the in-plane force as an arrow.
#include <array>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "trainer/demonstration.hpp"
#include "trainer/layout.hpp"
#include "trainer/trainer.hpp"
#include "trainer/trial_view.hpp"

struct ImDrawList;

namespace calligraphy::trainer {

/// A character's drawing, prepared once: outline polygons with their triangles, and the reference
/// strokes sampled, all in data units.
struct CharacterArt {
  std::vector<OutlinePolygon> polygons;
  std::vector<std::vector<std::array<int, 3>>> triangles;  // per polygon
  std::vector<std::size_t> polygon_stroke;                 // per polygon: its stroke
  std::vector<std::vector<Vec2>> reference;                // per stroke: the elements sampled
};

CharacterArt prepare_art(const TrainerCharacter& character);

/// Draws everything but the panel. `view` may be null (no trial yet). `demo`, when given, is a stroke-order
/// demonstration: the paper shows the outlines and the strokes drawn so far, numbered, and nothing of the
/// trial. `learner`: the active stroke is highlighted in a deeper yellow than its character, and the force
/// arrow and the pen's height gauge (the engineer's) are left out.
void draw_scene(ImDrawList& draw, const WindowLayout& layout, const std::vector<CharacterArt>& art,
                const Scene& trial_scene, const TrialView* view, const DemoView* demo = nullptr,
                bool learner = false);

}  // namespace calligraphy::trainer
