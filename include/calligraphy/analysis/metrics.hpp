#pragma once
/// \file metrics.hpp
/// Writing metrics of a pen trace against a reference stroke: spatial (deviation, tolerance tube,
/// discrete Frechet, DTW) and kinematic (writing time, mean speed, velocity peaks, normalised jerk).
/// Free functions on spans of points [m] and timestamps [s]; results are value types. Definitions,
/// units and sources of every metric: docs/metrics.md.
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/element.hpp"

namespace calligraphy {

// ---- Deviation -------------------------------------------------------------------------------

/// Deviation of one sample [m]: distance in the paper plane from `point_m` to the nearest element of
/// the reference stroke (the exact nearest point of each element, nearest_point.hpp). The same
/// definition as the trial recorder's per-tick deviation (trial.hpp). Throws InvalidArgument when the
/// reference is empty or a point is not finite.
double deviation_from_stroke_m(std::span<const StrokeElement> reference_m, const Vec2& point_m);

/// Summary of the deviations of a set of samples. All lengths in metres.
struct DeviationSummary {
  std::size_t samples = 0;
  double mean_m = 0.0;              ///< sum(d_i) / N
  double max_m = 0.0;               ///< max(d_i)
  double rms_m = 0.0;               ///< sqrt(sum(d_i^2) / N)
  double tube_radius_m = 0.0;       ///< radius of the tolerance tube the share refers to
  double outside_tube_share = 0.0;  ///< #{d_i > tube_radius_m} / N, in [0, 1]
};

/// Pools deviations sample by sample (several strokes pool into one character summary: every sample
/// weighs the same, as in the trial recorder's pooled mean). Never allocates.
class DeviationPool {
 public:
  /// Throws InvalidArgument when the tube radius is not finite or negative.
  explicit DeviationPool(double tube_radius_m);
  /// Adds one deviation [m]. Throws InvalidArgument for a negative or non-finite value.
  void add(double deviation_m);
  /// Adds every sample of `other`. Throws InvalidArgument when the tube radii differ.
  void merge(const DeviationPool& other);
  [[nodiscard]] std::size_t samples() const noexcept { return count_; }
  /// The summary. Throws InvalidArgument when nothing was added (a mean of no samples is undefined).
  [[nodiscard]] DeviationSummary summary() const;

 private:
  double tube_radius_m_;
  std::size_t count_ = 0;
  std::size_t outside_ = 0;
  double sum_ = 0.0;
  double sum_squares_ = 0.0;
  double max_ = 0.0;
};

/// The summary of the union of the samples behind `parts` (every sample weighs the same): mean and
/// outside share weighted by sample counts, RMS from the pooled mean square, max of the maxima. Throws
/// InvalidArgument when `parts` is empty, a part has no sample or the tube radii differ.
DeviationSummary pool_deviation_summaries(std::span<const DeviationSummary> parts);

/// Deviation summary of `samples_m` against the reference stroke. Throws InvalidArgument for no
/// samples, an empty reference, a non-finite point or a bad tube radius.
DeviationSummary deviation_summary(std::span<const Vec2> samples_m,
                                   std::span<const StrokeElement> reference_m, double tube_radius_m);

// ---- Curve distances -------------------------------------------------------------------------

/// Largest number of cells (n x m) `discrete_frechet_distance` and `dtw_mean_distance` accept, so that a
/// call is bounded (about 0.1 s); `compare_curves` resamples to stay below it.
inline constexpr std::size_t kMaxCurveCells = std::size_t{4096} * 4096;

/// Discrete Frechet distance between two polylines (Eiter & Mannila 1994, "Computing discrete Frechet
/// distance", TU Wien CD-TR 94/64): the least, over monotone couplings of the vertices, of the largest
/// coupled distance. Units of the input (m). O(n m) time, O(m) memory (two rolling rows). Throws
/// InvalidArgument for an empty polyline, a non-finite point or more than kMaxCurveCells cells.
double discrete_frechet_distance(std::span<const Vec2> a, std::span<const Vec2> b);

/// Dynamic time warping distance (Sakoe & Chiba 1978, IEEE Trans. ASSP 26(1):43-49), steps (1,0), (0,1),
/// (1,1) of weight 1 and no window: the warping path minimising the sum of point distances is found, and
/// the result is that sum divided by the number of point pairs on the path, i.e. the mean point
/// distance along the optimal path. So it is a length in the input's units (m), comparable to the mean
/// deviation. O(n m) time, O(m) memory. Throws as `discrete_frechet_distance`.
double dtw_mean_distance(std::span<const Vec2> a, std::span<const Vec2> b);

/// `count` points equally spaced by arc length along the polyline, both ends included (a polyline of
/// zero length gives `count` copies of its first point). Throws InvalidArgument for an empty polyline,
/// a non-finite point, a length beyond a double's range (points 1e308 m apart) or count < 2.
std::vector<Vec2> resample_by_arc_length(std::span<const Vec2> polyline, std::size_t count);

/// The reference stroke as a polyline equally spaced by arc length: every element is first split into
/// kReferenceChordsPerElement chords of equal parameter step (chord error well below 10 um for the
/// strokes of a 6 cm character), then the polyline is resampled at the largest spacing <= step_m that
/// divides its length, with at most max_points points (the spacing grows beyond step_m above that).
/// Throws InvalidArgument for an empty reference, step_m not finite or <= 0, or max_points < 2.
std::vector<Vec2> reference_polyline_m(std::span<const StrokeElement> reference_m, double step_m,
                                       std::size_t max_points);
inline constexpr int kReferenceChordsPerElement = 128;

/// How written samples are compared with the reference curve.
/// `reference_step_m` is in its table (`ParameterTable<CurveComparisonOptions>`); `max_points`, a count, is
/// checked beside it.
struct CurveComparisonOptions {
  double reference_step_m = 0.25e-3;  ///< arc-length step of the resampled reference [m], > 0
  std::size_t max_points = 2000;      ///< most points per curve, 2..4096 (bounds the O(n m) work)
};

/// The numeric fields of CurveComparisonOptions but the count `max_points` (parameter_table.hpp).
template <>
struct ParameterTable<CurveComparisonOptions> {
  static constexpr std::string_view name = "CurveComparisonOptions";
  [[nodiscard]] static std::span<const ParameterField<CurveComparisonOptions>> fields() noexcept;
};

/// Discrete Frechet and DTW distances [m] of written samples to a reference curve.
struct CurveDistances {
  double frechet_m = 0.0;
  double dtw_m = 0.0;
};

/// Frechet and DTW of the written samples against the reference stroke, traversed forwards (or from its
/// end to its start when `reference_reversed`). The reference is `reference_polyline_m(reference,
/// options.reference_step_m, options.max_points)`; the written samples are used as recorded (consecutive
/// repeats dropped) unless there are more than options.max_points, in which case they are replaced by
/// options.max_points points equally spaced by arc length. Throws InvalidArgument for no samples, an empty
/// reference, a non-finite point or options out of range.
CurveDistances compare_curves(std::span<const Vec2> samples_m, std::span<const StrokeElement> reference_m,
                              const CurveComparisonOptions& options = {}, bool reference_reversed = false);

// ---- Kinematics ------------------------------------------------------------------------------

/// How speed and jerk are estimated from samples. The two real-valued fields are in their table
/// (`ParameterTable<KinematicsOptions>`); `max_grid_points`, a count, is checked beside it.
struct KinematicsOptions {
  /// Cut-off of the low-pass filter applied to the positions before differentiating [Hz]: a Gaussian
  /// whose gain is 1/sqrt(2) at this frequency (sigma = 0.1325 / cutoff s). Pen-tip movement in
  /// handwriting has little power above about 10 Hz (Teulings & Maarse 1984, Human Movement Science
  /// 3:193-217). 0 switches the filter off. Must be finite and >= 0.
  double low_pass_cutoff_hz = 10.0;
  /// A velocity peak counts when the filtered speed rises by at least this share of its maximum above the
  /// last trough and falls again by as much (hysteresis, so that ripple is not counted). In (0, 1).
  double peak_prominence = 0.1;
  /// Most points of the uniform time grid the samples are interpolated on (bounds the work). >= 16.
  std::size_t max_grid_points = 1'000'000;
};

/// The numeric fields of KinematicsOptions but the count `max_grid_points` (parameter_table.hpp).
template <>
struct ParameterTable<KinematicsOptions> {
  static constexpr std::string_view name = "KinematicsOptions";
  [[nodiscard]] static std::span<const ParameterField<KinematicsOptions>> fields() noexcept;
};

/// Kinematics of one stroke (one pen-down segment).
struct StrokeKinematics {
  double writing_time_s = 0.0;      ///< T = t_last - t_first [s]
  double path_length_m = 0.0;       ///< L = sum |p_(i+1) - p_i| over the raw samples [m]
  double mean_speed_m_per_s = 0.0;  ///< L / T [m/s]
  int velocity_peaks = 0;           ///< peaks of the filtered speed (see KinematicsOptions::peak_prominence)
  /// sqrt(0.5 * integral(|jerk|^2 dt) * T^5 / L^2), dimensionless (Teulings et al. 1997, Experimental
  /// Neurology 146:159-170; Hogan & Sternad 2009, J. Motor Behavior 41(6):529-534). sqrt(360) = 18.97 for
  /// a minimum-jerk movement.
  double normalised_jerk = 0.0;
};

/// Kinematics of a stroke from its samples. The samples are linearly interpolated on a uniform time grid
/// (step: the mean sampling interval, kept within [sigma / 16, sigma / 4] of the filter; at most 16 grid
/// points per sampling interval and max_grid_points in all, so the work is bounded by the sample count),
/// extended at both ends by the pen resting at its first and last position, low-pass filtered, and
/// differentiated by central differences (speed: first, jerk: third); the jerk integral runs over the
/// extended grid. Throws InvalidArgument when the spans differ in size, hold fewer than 2 samples, hold a
/// non-finite value, when a time goes backwards (naming the index), when T or L is 0, or for bad options.
StrokeKinematics stroke_kinematics(std::span<const double> times_s, std::span<const Vec2> positions_m,
                                   const KinematicsOptions& options = {});

// ---- Everything of one stroke ----------------------------------------------------------------

/// Options of `stroke_writing_metrics`.
struct MetricsOptions {
  /// Radius of the tolerance tube around the reference [m]: 2 mm, about half the width of a brush stroke
  /// on a 6 cm character (a choice; no published standard). Finite, >= 0.
  double tube_radius_m = 2e-3;
  CurveComparisonOptions curves{};
  KinematicsOptions kinematics{};
};

/// The numeric field of MetricsOptions itself, `tube_radius_m` (parameter_table.hpp).
template <>
struct ParameterTable<MetricsOptions> {
  static constexpr std::string_view name = "MetricsOptions";
  [[nodiscard]] static std::span<const ParameterField<MetricsOptions>> fields() noexcept;
};

/// All metrics of one written stroke against its reference.
struct StrokeWritingMetrics {
  DeviationSummary deviation;
  CurveDistances curves;
  StrokeKinematics kinematics;
};

/// Deviation, curve distances (reference traversed backwards when `reference_reversed`) and kinematics of
/// one written stroke. Throws as `deviation_summary`, `compare_curves` and `stroke_kinematics`.
StrokeWritingMetrics stroke_writing_metrics(std::span<const double> times_s,
                                            std::span<const Vec2> positions_m,
                                            std::span<const StrokeElement> reference_m,
                                            const MetricsOptions& options = {},
                                            bool reference_reversed = false);

// ---- Everything of one character -------------------------------------------------------------

/// Metrics of one character written as several pen-down segments (score.hpp makes them from a trace).
/// Spatial values come from the segments matched to reference strokes; they are absent when no stroke
/// was matched. Timing covers every pen-down segment, also those too short to be scored.
struct CharacterWritingMetrics {
  /// Pooled over the samples of all matched strokes (`pool_deviation_summaries`), as the trial recorder
  /// pools its mean deviation over the ticks of all completed strokes.
  std::optional<DeviationSummary> deviation;
  std::optional<double> frechet_m;  ///< max over matched strokes: a Frechet distance is a worst case [m]
  std::optional<double> dtw_m;      ///< mean over matched strokes weighted by their sample counts [m]
  std::size_t pen_lifts = 0;        ///< pen-up gaps between two pen-down segments
  double writing_time_s = 0.0;      ///< sum over pen-down segments of t_last - t_first [s]
  double in_air_time_s = 0.0;       ///< sum of the gaps: t_first(next segment) - t_last(segment) [s]
  /// First pen-down sample to last pen-down sample = writing + in air [s]; absent without a pen-down.
  std::optional<double> total_time_s;
  double path_length_m = 0.0;                ///< pen-down path length, all segments [m]
  std::optional<double> mean_speed_m_per_s;  ///< path_length_m / writing_time_s, absent for zero time
  int velocity_peaks = 0;                    ///< sum over the scored segments
  std::optional<double> normalised_jerk;     ///< mean over the scored segments
};

}  // namespace calligraphy
