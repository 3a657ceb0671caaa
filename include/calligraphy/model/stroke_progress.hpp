#pragma once
/// \file stroke_progress.hpp
/// How far a pen has written the active stroke, and whether that stroke is written: the one rule of
/// stroke acceptance, used by the renderer tick by tick and by `match_stroke` (stroke_matcher.hpp) on a
/// recorded trace, so that both give the same verdict for the same pen path.
///
/// The paper advances the active element when the tip crosses the feature plane at the element's end
/// (section 4.3.3, eq. 6) and completes the stroke at the last plane. A hand does not do that: it rounds
/// a corner inside the fitted corner point (whose plane it then never crosses), and it lifts the pen short
/// of the end about as often as past it. Here progress is the arc length, along the stroke's centre line
/// (`StrokeCentreLine`: the data's median, which is what the outline shows), of the pen's foot point,
/// credited only while the pen moves forward along the line and stays within a corridor; the active
/// element is the one whose arc contains the progress, so a corner counts as gone round once the pen has
/// gone round it on either side, and no feature plane is needed. This resolves the corner and end
/// ambiguity of the paper's section 6 with one rule:
///
///   a stroke of length L (along the centre line, from its first feature point to its last) is written
///   when the pen entered it in the start neighbourhood (WS) and, within `corridor_m` of it and with a
///   mean distance of at most `allowed_mean_deviation_m(L)`, went along it for at least L - S(L), S(L) =
///   `allowed_shortfall_m(L)`, leaving at most `allowed_end_gap_m(L)` unwritten at either end. The
///   tolerances grow with L up to a cap and scale with the character's size (StrokeAcceptance). The
///   way along counts the arc the pen gained, plus up to `displacement_m` of run before the start and past
///   the end, so that a copy displaced along the stroke is written and a half stroke is not.
///
/// It completes when the pen is lifted, short of the end or past it. Past the end the pen may move freely
/// within the end neighbourhood (`follow_through_m`). A pen that leaves it before lifting completes the
/// stroke if it is still on it (it came back along the stroke) and otherwise has gone on into another
/// shape (a scribble that began with the stroke, a stroke run on into the next) and loses it.
///
/// Servo path: `begin`, `update` and `lift` are noexcept, allocation-free and O(centre-line points).
#include <cstddef>
#include <cstdint>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy {

/// A pen-down refused at its lift, as the renderer (servo ticks) and the score (trace samples) see it:
/// whether it is a miss (StrokeAcceptance::counts_as_miss).
struct RefusedPenDown {
  bool entered_ws = false;        ///< it came within the start radius of the stroke due's start (WS)
  bool in_character_box = false;  ///< it touched the paper inside the character's box
  double path_m = 0.0;            ///< its path from touch-down to lift [m]
  std::size_t samples = 0;        ///< its samples on the paper
};

/// Tolerances of stroke acceptance, SI units. Defaults for a 60 mm character box from how far people's
/// strokes lie from hanzi-writer-data's medians: hand-drawn centre lines of an independent data set,
/// aligned to the medians, have a discrete Frechet distance of median 2.3 mm, 95th percentile 3.4 mm,
/// largest 6.1 mm, and end points within 3.5 mm of the medians' (measured with Hanzi Writer's own
/// matcher, chanind/hanzi-writer 3.7.3 `strokeMatches.ts`, whose end-point tolerance is 250/1024 of the
/// box, 14.6 mm here, and whose length test accepts 35 % of a stroke: both too lenient to refuse half
/// strokes). They scale with the character's size (`reference_character_size_m`; an attempt applies
/// `for_character_size`). docs/stroke-acceptance.md has the measured acceptance.
struct StrokeAcceptance {
  /// Farthest a pen may be from the centre line and still make progress [m]: people's largest Frechet
  /// distance, 6.1 mm, plus 0.4 mm.
  double corridor_m = 0.0065;
  /// Largest mean distance of the pen from the centre line over its path in WS [m] (each distance capped
  /// at twice the corridor): people's 95th-percentile Frechet distance is 3.4 mm and their mean distance
  /// far less; a stroke moved 3 mm or more across is in the wrong place.
  double mean_deviation_m = 0.003;
  /// How much shorter than the stroke the pen's way along it may be [m]: each end within 3.5 mm of the
  /// median's, not both 3.5 mm short at once.
  double shortfall_m = 0.006;
  /// The same as a fraction of the stroke's length, the smaller applying: a half stroke (0.5) is refused
  /// with a margin on the shortest strokes (dots), where 6 mm would be most of the stroke.
  double shortfall_fraction = 0.35;
  /// How far a copy of the stroke may be displaced along it [m]: up to this much run before the start or
  /// past the end counts towards the way along, and either end may be left unwritten by this much on a
  /// short stroke. People's copies lie a median 2.3 mm from the medians (Frechet distance).
  double displacement_m = 0.0025;
  /// How far along the centre line, ahead of and behind the progress, the foot point is looked for [m]:
  /// the most a foot may run ahead in one step (a corner cut inside by 2.5 mm skips about 5 mm of a
  /// right angle); shorter than a stroke's return to itself past a hook.
  double lookahead_m = 0.006;
  /// Most arc credited per length of pen motion, dimensionless, >= 1: a pen cutting a corner gains more
  /// arc than it moves (1.4 times at a right angle, 2.6 times for a 135-degree turn cut close to its
  /// corner, which hands do not do by much); a path that jumps between the legs of a folded stroke would
  /// gain far more. Past it the progress catches up as the pen moves on.
  double max_gain_ratio = 2.0;
  /// Radius of the end neighbourhood a pen past the end may move in before it lifts [m]: people end up
  /// to 3.5 mm past the end (the measured end scatter), a brush's exit further; a pen that leaves it
  /// before lifting and off the stroke loses the stroke.
  double follow_through_m = 0.008;

  // Tolerances that grow with the movement, as people's accuracy falls with it: the end-point scatter of
  // an aimed movement grows in proportion to its amplitude at a given movement time (Schmidt, Zelaznik,
  // Hawkins, Frank & Quinn 1979, "Motor-output variability: a theory for the accuracy of rapid motor
  // acts", Psychological Review 86:415-451; Fitts 1954). Another hand's strokes (KanjiVG's centre lines,
  // aligned to the medians) end within 3.5 mm of the medians' on 5-8 mm strokes at the 90th percentile,
  // within 6.6 mm on strokes of 48 mm and more (docs/stroke-acceptance.md). Each tolerance is its value
  // above (the floor) plus its growth times the stroke's length L, up to its cap.

  /// Growth of the shortfall with the stroke's length, dimensionless: the shortfall allowed is
  /// min(`shortfall_fraction` L, `shortfall_m` + this L, `shortfall_cap_m`).
  double shortfall_per_length = 0.15;
  /// Most shortfall allowed on any stroke [m].
  double shortfall_cap_m = 0.013;
  /// Growth of the mean deviation allowed with the stroke's length, dimensionless: the limit is
  /// min(`mean_deviation_m` + this L, `mean_deviation_cap_m`).
  double deviation_per_length = 0.01;
  /// Most mean deviation allowed on any stroke [m]: well under the smallest parallel shift refused, 4 mm
  /// (3.5 mm credited 1.9 % of shifted strokes on KanjiVG's lines, 3.2 mm 1.3 %).
  double mean_deviation_cap_m = 0.0032;
  /// Least either end may be left unwritten by on a stroke long enough [m], beside the shortfall and the
  /// displacement: the end-point scatter of an aimed movement has a floor that does not shrink with its
  /// amplitude (the intercept of Schmidt et al. 1979's linear law), and a pen released by a person stops
  /// short of where it aimed. Another hand's ends (KanjiVG's lines aligned to the medians) lie up to 3.5 mm
  /// from the medians' on 5-8 mm strokes (90th percentile), and a pointer is released up to 1.5 mm shorter
  /// still. 0: no such floor (records before version 5).
  double end_gap_m = 0.0045;
  /// The same floor as a fraction of the stroke's length, the smaller applying, dimensionless: a half
  /// stroke leaves one end unwritten by half the stroke (0.5), so 0.4 keeps it refused on a dot.
  double end_gap_fraction = 0.4;
  /// A path centred on a dot or a short tick may cover less of it (a rule beside the shortfall's, added in
  /// version 7 of a trial record): the data's medians run to the tips of the ink, and the ink of a dot
  /// reaches past the pen's path at both ends by about the brush's radius, a large part of a short stroke;
  /// another hand's centre lines (KanjiVG's, drawn as a pen's path) cover the middle 46-63 % of such
  /// medians. A path is written by this rule when the stroke's length L is in [`centred_min_length_m`,
  /// `centred_max_length_m`], its way along is at least this fraction of L, the gaps it leaves at the two
  /// ends differ by at most `centred_balance_fraction` L, each within the end gap allowed, and its mean
  /// deviation within the limit. A half stroke leaves one end whole and the other half unwritten: not
  /// centred. Chosen on the tuning half of the KanjiVG characters (docs/stroke-acceptance.md). 0: no such
  /// rule (records before version 7).
  double centred_coverage_fraction = 0.55;
  /// Most the gaps a centred path leaves at the two ends may differ by, as a fraction of L.
  double centred_balance_fraction = 0.1;
  /// Shortest stroke the centred rule applies to [m]: below it a half stroke copied up to 2.2 mm along
  /// lands on the middle as often as a person's dot (docs/stroke-acceptance.md).
  double centred_min_length_m = 0.008;
  /// Longest stroke the centred rule applies to [m]: beyond it the brush's radius is a small part of the
  /// stroke, and the end-point scatter's rule alone applies. Below `centred_min_length_m`: no stroke.
  double centred_max_length_m = 0.02;
  /// The character size the lengths above are for [m]: in a character of another size
  /// (`SceneLayout::character_size_m`) every length scales by size / this. 0: lengths are absolute
  /// (records before version 4).
  double reference_character_size_m = 0.06;

  /// Refused attempts at one stroke after which it is shown as a hint (a whole number; 0: never). Hanzi
  /// Writer's `showHintAfterMisses` is 3. The one definition of the quiz's too (QuizOptions::hint_after(),
  /// unless its option overrides it).
  double hint_after_misses = 3.0;
  /// Refused attempts at one stroke after which it is demonstrated and credited as assisted, and the
  /// next stroke is active (a whole number; 0: never, a learner may stay on a stroke for ever). Hanzi
  /// Writer's `markStrokeCorrectAfterMisses`. 5: two more tries after the hint, so that a stroke refused
  /// on 1 % of attempts is almost never assisted (1e-10) while a learner never stays stuck.
  double assist_after_misses = 5.0;
  /// Least pen path of a refused pen-down for it to count as a miss [m] (a rule added in version 8 of a
  /// trial record): every pen-down refused at its lift counts, whether or not it came near the stroke's
  /// start (WS) but touched the character's box, as Hanzi Writer counts every stroke drawn on it that does
  /// not match; a touch that barely moves (shorter than this, or fewer than kMinMissSamples samples) is no
  /// attempt. The same threshold as the
  /// score's ignored pen-downs (ScoreOptions::min_segment_length_m). Not scaled with the character: it is
  /// the pen's jitter, not the stroke's size. 0: only a lift in WS is a miss, however short (records
  /// before version 8), so that a stroke written a start radius or more away is never hinted or credited.
  double miss_min_path_m = 0.001;

  /// The values of the fields above as records before version 4 ran them: no growth with the stroke's
  /// length, no cap, no scaling with the character size, no assisted credit, no floor of the end gap.
  void use_fixed_tolerances() noexcept;
  /// The rule as records of version 4 ran it: no floor of the end gap (`end_gap_m` 0).
  void use_version_4_end_gaps() noexcept { end_gap_m = 0.0; }
  /// The rule as records of versions 4 to 6 ran it: no centred coverage (`centred_coverage_fraction` 0).
  void use_version_6_coverage() noexcept { centred_coverage_fraction = 0.0; }
  /// The misses as records before version 8 counted them: a lift in WS only (`miss_min_path_m` 0).
  void use_version_7_misses() noexcept { miss_min_path_m = 0.0; }
  /// True when `pen_down`, refused at its lift, counts as a miss of the stroke due: with `miss_min_path_m`
  /// > 0, one that entered WS or touched the character's box, with a path of at least `miss_min_path_m`
  /// over at least kMinMissSamples samples (a pen resting outside the box is no attempt at the character);
  /// with 0, one that entered WS.
  [[nodiscard]] bool counts_as_miss(const RefusedPenDown& pen_down) const noexcept;
  /// True when a path that leaves `start_gap_m` and `finish_gap_m` [m] of a stroke of `length_m` unwritten,
  /// with `way_along_m` along it, is centred on it and covers enough of it (`centred_coverage_fraction`).
  [[nodiscard]] bool centred_cover(double length_m, double way_along_m, double start_gap_m,
                                   double finish_gap_m) const noexcept;
  /// This acceptance for a character of side `character_size_m` [m]: every length scaled by size /
  /// `reference_character_size_m` (unchanged when that is 0).
  [[nodiscard]] StrokeAcceptance for_character_size(double character_size_m) const noexcept;
  /// The largest mean deviation allowed on a stroke of `length_m` [m].
  [[nodiscard]] double allowed_mean_deviation_m(double length_m) const noexcept;

  /// Throws InvalidArgument naming the field when a value is outside its range
  /// (`ParameterTable<StrokeAcceptance>`: each length in (0, 0.1] m (`end_gap_m` and the centred rule's
  /// [0, 0.1]), the fractions in (0, 1) and [0, 1), the gain ratio in [1, 100], the miss counts in
  /// [0, 1000]), or a miss count is not a whole number.
  void validate() const;
  /// The most a stroke of `length_m` may be written short by [m]: min(`shortfall_fraction` L,
  /// `shortfall_m` + `shortfall_per_length` L, `shortfall_cap_m`).
  [[nodiscard]] double allowed_shortfall_m(double length_m) const noexcept;
  /// The most either end of a stroke of `length_m` may be left unwritten by [m]: max(S(L),
  /// `displacement_m`, min(`end_gap_m`, `end_gap_fraction` L)), S(L) = allowed_shortfall_m(L).
  [[nodiscard]] double allowed_end_gap_m(double length_m) const noexcept;
  bool operator==(const StrokeAcceptance&) const = default;
};

/// Fewest samples a pen-down has for its refusal to count as a miss (StrokeAcceptance::counts_as_miss), and
/// for the score to judge it at all (ScoreOptions::min_segment_samples): two samples are a touch, not a path.
inline constexpr std::size_t kMinMissSamples = 3;

/// The fields of StrokeAcceptance (parameter_table.hpp): the one definition of their units and ranges, which
/// its validate(), a protocol's "acceptance" and a trial record read. A length beyond 0.1 m, more than the
/// 60 mm character box, would accept anything.
template <>
struct ParameterTable<StrokeAcceptance> {
  static constexpr std::string_view name = "StrokeAcceptance";
  [[nodiscard]] static std::span<const ParameterField<StrokeAcceptance>> fields() noexcept;
};

/// Why a stroke attempt was not accepted, in the learner's terms.
enum class StrokeRefusal : std::uint8_t {
  none,          ///< accepted (or still being written)
  too_short,     ///< went along the stroke but stopped before its end neighbourhood
  backwards,     ///< written from its end towards its start
  wrong_place,   ///< not along the stroke: started elsewhere, or too far from it on average
  wrong_stroke,  ///< another stroke's shape, or a stroke of the character already written
  wrong_order,   ///< a stroke of the character that comes later
};

/// "too_short", "backwards", "wrong_place", "wrong_stroke", "wrong_order", or "none".
[[nodiscard]] const char* to_string(StrokeRefusal refusal) noexcept;

/// Progress of one pen-down attempt at one stroke. Value type; `begin` starts an attempt.
class StrokeProgressTracker {
 public:
  /// Starts an attempt at `stroke` (which must outlive the attempt) with the pen at `tip_m` [m], where
  /// it entered WS. `acceptance` is copied; it must be valid.
  void begin(const PlacedStroke& stroke, const Vec2& tip_m, const StrokeAcceptance& acceptance) noexcept;
  /// The pen at `tip_m` [m] on the paper. Returns true when this step completes the stroke: the pen had
  /// passed the end (everything else holding) and now left the end neighbourhood along the stroke; the
  /// attempt then ends. Leaving it off the stroke ends the attempt refused (`in_attempt` false, `refusal`
  /// wrong_stroke).
  bool update(const Vec2& tip_m) noexcept;
  /// The pen was lifted: true when the stroke is written (short of the end, within the tolerances). The
  /// attempt ends either way.
  bool lift() noexcept;

  [[nodiscard]] bool in_attempt() const noexcept { return attempt_; }
  /// The pen has passed the end with the stroke written: nothing is left to guide it to.
  [[nodiscard]] bool passed_end() const noexcept { return passed_end_; }
  /// Furthest arc credited along the centre line [m].
  [[nodiscard]] double progress_m() const noexcept { return progress_m_; }
  /// The pen's way along the stroke so far [m]: arc gained plus run before the start and past the end
  /// (each up to `displacement_m`).
  [[nodiscard]] double way_along_m() const noexcept;
  /// The stroke's length L between its first and last feature points along the centre line [m].
  [[nodiscard]] double stroke_length_m() const noexcept;
  /// Mean distance of the pen from the centre line over its path so far [m].
  [[nodiscard]] double mean_deviation_m() const noexcept;
  /// The element that contains the progress: 0 before the first corner, the last one after the last.
  [[nodiscard]] std::size_t element_index() const noexcept;
  /// Why the attempt would be refused if the pen were lifted now (none when it would be accepted).
  [[nodiscard]] StrokeRefusal refusal() const noexcept;

 private:
  struct Foot {
    double arc_m;
    double distance_m;
    Vec2 tangent;
  };
  [[nodiscard]] Foot foot_near(const Vec2& tip_m, double from_arc_m, double to_arc_m) const noexcept;
  [[nodiscard]] bool written() const noexcept;

  const PlacedStroke* stroke_ = nullptr;
  StrokeAcceptance acceptance_{};
  double entry_arc_m_ = 0.0;  // foot of the pen where it entered
  double progress_m_ = 0.0;   // furthest foot credited
  Vec2 last_tip_m_ = Vec2::Zero();
  double travel_m_ = 0.0;              // pen path length in this attempt
  double distance_integral_m2_ = 0.0;  // integral of the capped distance over the pen path
  double entry_distance_m_ = 0.0;
  double backward_m_ = 0.0;        // pen motion against the line within the corridor
  double before_start_m_ = 0.0;    // how far before the start the pen entered, along the stroke
  double past_end_m_ = 0.0;        // how far past the end the pen went, along the stroke
  bool outside_corridor_ = false;  // the last step was outside the corridor
  bool attempt_ = false;
  bool passed_end_ = false;  // written up to the end; waiting for the lift in the end neighbourhood
  bool lost_ = false;        // left the end neighbourhood across: refused
};

}  // namespace calligraphy
