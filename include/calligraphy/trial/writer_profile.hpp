#pragma once
/// \file writer_profile.hpp
/// How a simulated writer writes: its hand, its closed loop, its bias, the errors it makes and how it
/// learns. Plain fields, settable one by one from C++ (then `validate()`), or by name with
/// `set_writer_parameter` (for a command line or Python). Every constant and its source:
/// docs/writer.md. A value type of the trial layer (a trial record states the profile that wrote it,
/// recorded_trial.hpp); the writer that executes it is sim's (calligraphy/sim/simulated_writer.hpp).
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/trial/writer_setting.hpp"

namespace calligraphy {

/// A simulated writer's profile. Units as named; defaults are the `novice` profile.
struct WriterProfile {
  std::string name = "novice";

  // Hand impedance holding the stylus: F = k (x_d - x) + b (x_d' - x') + noise + tremor.
  double hand_stiffness_n_per_m = 150.0;  ///< k [N/m], > 0 (a relaxed grip; assumed)
  double hand_damping_n_s_per_m = 3.0;    ///< b [N s/m], >= 0
  double noise_fraction = 0.05;      ///< signal-dependent force noise, std dev / |F| (Harris & Wolpert 1998)
  double tremor_amplitude_n = 0.05;  ///< in-plane tremor force amplitude [N], >= 0
  double tremor_frequency_hz = 9.0;  ///< tremor frequency [Hz], > 0 (8-12 Hz physiological)

  // Movement: minimum-jerk segments (Flash & Hogan 1985) along the writer's copy of each stroke.
  double writing_speed_m_s = 0.025;  ///< mean writing speed with the pen on the stroke [m/s], > 0
  double travel_speed_m_s = 0.08;    ///< mean speed of pen-up moves [m/s], > 0
  double press_depth_m = 0.005;      ///< how far below the paper the hand aims while writing [m], >= 0
  double lift_height_m = 0.01;       ///< pen-up height above the paper [m], > 0
  /// Most the writer cuts inside a corner of the stroke [m], >= 0: each corner is cut by a uniform draw in
  /// [0, this] (the data's medians round their corners over 2-3 vertices; people's copies lie a median
  /// 2.3 mm from them, docs/stroke-acceptance.md).
  double corner_cut_m = 0.0015;
  /// Where the pen is lifted, relative to the end of the stroke the writer sees on the display: a uniform
  /// draw from `end_short_m` short of it to `end_past_m` past it [m], both >= 0 (another hand's strokes end
  /// 2 mm short to 2.5 mm past hanzi-writer-data's medians, within 3.5 mm; docs/stroke-acceptance.md).
  double end_short_m = 0.002;
  double end_past_m = 0.0025;     ///< see `end_short_m` [m], >= 0
  double follow_through_m = 0.0;  ///< a run past the end added to the draw (a brush's exit) [m], >= 0

  // Systematic bias of the writer's copy of the character, so that guidance has work to do.
  double bias_offset_m = 0.002;  ///< offset of the whole copy [m], >= 0
  double scale_error = 0.06;  ///< relative mis-scale of the copy about the character centre, in (-0.5, 0.5)
  double stroke_jitter_m = 0.001;  ///< std dev of a per-attempt random offset [m], >= 0

  // Closed loop: the writer sees its pen and the reference late, corrects, and paces itself.
  double visual_delay_s =
      0.12;  ///< visuomotor delay [s], in [0, 0.5] (Miall et al. 1993; Saunders & Knill 2005)
  double vision_period_s = 0.01;  ///< interval between visual updates [s], in [0.001, 0.1]
  double correction_rate_per_s =
      4.0;  ///< rate at which a seen error beyond the tolerance is removed [1/s], >= 0
  double error_tolerance_m = 0.001;  ///< seen error the writer leaves uncorrected [m], >= 0
  double steering_width_m =
      0.004;  ///< width W of the tunnel in the steering law v = (W - 2|e|) / tau [m], > 0
  double min_speed_fraction = 0.3;  ///< least share of `writing_speed_m_s` however large the error, in (0, 1]
  double error_filter_s = 0.1;      ///< time constant of the seen error that sets the speed [s], > 0
  double speed_time_constant_s = 0.15;  ///< time constant of the speed command [s], > 0

  // Responses to the display.
  double reaction_time_s = 0.15;  ///< how long a resistance lasts before the writer reacts [s], > 0
  double resistance_threshold_n =
      0.15;  ///< in-plane force against the intended motion that counts as resistance [N], > 0
  double expected_drag_ratio =
      0.2;  ///< paper drag the writer takes as normal, share of the normal force, >= 0
  double correction_per_attempt =
      0.5;  ///< share of the bias and error rates removed on each re-attempt, in [0, 1]
  int max_attempts_per_stroke = 5;  ///< attempts at one stroke before the writer gives up, >= 1

  // Error modes: probabilities per stroke attempt (order and direction: per stroke of the plan), in [0, 1].
  double order_error_probability = 0.0;       ///< a stroke is swapped with the next one in the writer's order
  double backwards_probability = 0.0;         ///< a stroke is written from its end to its start
  double mid_stroke_lift_probability = 0.02;  ///< the pen is lifted in the middle of a stroke
  double outside_touch_probability = 0.02;    ///< the pen touches the paper outside the character's box (AS)
  double hesitation_probability = 0.05;       ///< the writer pauses before a stroke or at a corner
  double hesitation_s = 0.5;                  ///< mean length of a pause [s], >= 0

  // Learning across repetitions (writer_learning.hpp).
  double learning_rate =
      0.0;  ///< lambda of the exponential practice law per repetition, >= 0; 0 = no learning

  /// A relaxed learner with a visible bias who knows the stroke order (the defaults).
  static WriterProfile novice();
  /// A stiffer, faster, nearly unbiased writer without errors.
  static WriterProfile skilled();
  /// The paper's foreign student (section 7): larger bias, strokes out of order and backwards, slower.
  static WriterProfile foreign();
  /// Throws InvalidArgument naming the field, its value and its range when a value is out of range or
  /// not finite (`ParameterTable<WriterProfile>`; `max_attempts_per_stroke` in [1, 1000]).
  void validate() const;
};

/// The numeric fields of WriterProfile but `max_attempts_per_stroke` (parameter_table.hpp): the one
/// definition of their units and ranges, read by `validate`, `set_writer_parameter` and Python.
template <>
struct ParameterTable<WriterProfile> {
  static constexpr std::string_view name = "WriterProfile";
  [[nodiscard]] static std::span<const ParameterField<WriterProfile>> fields() noexcept;
};

/// The names of the named profiles, "novice", "skilled" and "foreign": the one list the CLI's
/// `--writer-profile`, specifications, session.json and Python take.
[[nodiscard]] std::span<const std::string_view> writer_profile_names() noexcept;

/// The profile called `name`, one of `writer_profile_names()`. Throws InvalidArgument naming the unknown
/// name and the known ones.
[[nodiscard]] WriterProfile writer_profile(std::string_view name);

/// Names of the numeric fields `set_writer_parameter` knows, in declaration order.
[[nodiscard]] std::vector<std::string> writer_parameter_names();

/// The numeric field called `key` (e.g. "bias_offset_m"). Throws InvalidArgument naming an unknown key.
[[nodiscard]] double writer_parameter(const WriterProfile& profile, std::string_view key);

/// Sets the numeric field called `key` to `value` and validates the result; on any error `profile` is
/// unchanged. Throws InvalidArgument naming an unknown key (and listing the known ones), a value that
/// is not a whole number for `max_attempts_per_stroke`, or the field `validate` refuses.
void set_writer_parameter(WriterProfile& profile, std::string_view key, double value);

}  // namespace calligraphy
