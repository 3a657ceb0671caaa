#pragma once
// Foot-point jumps on real characters: simulated trials of embedded characters (lock-step,
// novice writer, several seeds) are recorded, and each trace's WS ticks are replayed through each
// nearest-point method; a jump is a tick where the foot point on the active element moves more than
// a threshold (1 mm) from the previous WS tick of the same stroke. Used by `calligraphy bench jumps`
// and by the generated section of docs/nearest-point.md.
#include <cstdint>
#include <string>
#include <vector>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::cli {

struct JumpSettings {
  std::u32string characters;  ///< empty: every embedded character
  std::vector<std::uint64_t> seeds{1, 2, 3};
  std::vector<bool> guidance{true, false};  ///< trials with guidance on, and off (larger deviations)
  double threshold_m = 1e-3;                ///< a foot-point move above this between ticks is a jump [m]
  double subdivision_tolerance_m = 1e-5;    ///< e of the paper's subdivision [m] (the paper gives no value)
};

/// One method on the trials with guidance on or off.
struct JumpRow {
  std::string method;        ///< "exact", "tracker", "newton", "subdivision"
  bool guidance = true;      ///< of the trials replayed
  std::size_t strokes = 0;   ///< strokes with WS ticks, over all trials
  std::size_t ws_ticks = 0;  ///< WS ticks replayed
  std::size_t jumps = 0;     ///< ticks whose foot moved more than the threshold
  /// of which on the tick the active element changed (the feature plane was crossed): the foot moves
  /// to the next element, whatever the method
  std::size_t jumps_at_switch = 0;
  std::size_t strokes_with_jump = 0;
  double jumps_per_stroke = 0.0;
  double frac_strokes_with_jump = 0.0;
  double max_jump_m = 0.0;         ///< the largest foot move between consecutive WS ticks [m]
  std::vector<std::string> where;  ///< "永 stroke 2 seed 1" for each stroke with a jump (UTF-8)
};

struct JumpMeasurement {
  JumpSettings settings;
  std::size_t characters = 0;
  std::size_t trials = 0;
  std::size_t trials_completed = 0;  ///< every stroke written in order (guidance on and off together)
  std::vector<JumpRow> rows;
};

/// Runs the trials and the replays on the characters of `library` the settings name (by default every
/// embedded character). Deterministic for the library and the settings.
JumpMeasurement measure_foot_jumps(const CharacterLibrary& library, const JumpSettings& settings);

/// A JSON array of objects: method, guidance, strokes, ws_ticks, jumps, jumps_at_element_switch,
/// jumps_per_stroke, frac_strokes_with_jump, max_jump_m.
std::string foot_jumps_json(const JumpMeasurement& measurement);
/// The generated Markdown section of docs/nearest-point.md (between kJumpsGeneratedBegin and
/// kGeneratedEnd): settings and the table. `command` is the command line that regenerates it.
std::string foot_jumps_markdown(const JumpMeasurement& measurement, const std::string& command);

}  // namespace calligraphy::cli
