#include "calligraphy/sim/writer_profile.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/decimal_number.hpp"

namespace calligraphy {
namespace {

struct Field {
  const char* name;
  double WriterProfile::*member;
};

// Every numeric field but `max_attempts_per_stroke` (an int, handled on its own).
constexpr std::array kFields = {
    Field{"hand_stiffness_n_per_m", &WriterProfile::hand_stiffness_n_per_m},
    Field{"hand_damping_n_s_per_m", &WriterProfile::hand_damping_n_s_per_m},
    Field{"noise_fraction", &WriterProfile::noise_fraction},
    Field{"tremor_amplitude_n", &WriterProfile::tremor_amplitude_n},
    Field{"tremor_frequency_hz", &WriterProfile::tremor_frequency_hz},
    Field{"writing_speed_m_s", &WriterProfile::writing_speed_m_s},
    Field{"travel_speed_m_s", &WriterProfile::travel_speed_m_s},
    Field{"press_depth_m", &WriterProfile::press_depth_m},
    Field{"lift_height_m", &WriterProfile::lift_height_m},
    Field{"corner_cut_m", &WriterProfile::corner_cut_m},
    Field{"end_short_m", &WriterProfile::end_short_m},
    Field{"end_past_m", &WriterProfile::end_past_m},
    Field{"follow_through_m", &WriterProfile::follow_through_m},
    Field{"bias_offset_m", &WriterProfile::bias_offset_m},
    Field{"scale_error", &WriterProfile::scale_error},
    Field{"stroke_jitter_m", &WriterProfile::stroke_jitter_m},
    Field{"visual_delay_s", &WriterProfile::visual_delay_s},
    Field{"vision_period_s", &WriterProfile::vision_period_s},
    Field{"correction_rate_per_s", &WriterProfile::correction_rate_per_s},
    Field{"error_tolerance_m", &WriterProfile::error_tolerance_m},
    Field{"steering_width_m", &WriterProfile::steering_width_m},
    Field{"min_speed_fraction", &WriterProfile::min_speed_fraction},
    Field{"error_filter_s", &WriterProfile::error_filter_s},
    Field{"speed_time_constant_s", &WriterProfile::speed_time_constant_s},
    Field{"reaction_time_s", &WriterProfile::reaction_time_s},
    Field{"resistance_threshold_n", &WriterProfile::resistance_threshold_n},
    Field{"expected_drag_ratio", &WriterProfile::expected_drag_ratio},
    Field{"correction_per_attempt", &WriterProfile::correction_per_attempt},
    Field{"order_error_probability", &WriterProfile::order_error_probability},
    Field{"backwards_probability", &WriterProfile::backwards_probability},
    Field{"mid_stroke_lift_probability", &WriterProfile::mid_stroke_lift_probability},
    Field{"outside_touch_probability", &WriterProfile::outside_touch_probability},
    Field{"hesitation_probability", &WriterProfile::hesitation_probability},
    Field{"hesitation_s", &WriterProfile::hesitation_s},
    Field{"learning_rate", &WriterProfile::learning_rate},
};
constexpr const char* kAttemptsKey = "max_attempts_per_stroke";

std::string known_keys() {
  std::string list;
  for (const std::string& name : writer_parameter_names()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

const Field* find_field(std::string_view key) {
  for (const Field& f : kFields) {
    if (key == f.name) return &f;
  }
  return nullptr;
}

[[noreturn]] void unknown_key(std::string_view key) {
  throw InvalidArgument("unknown writer parameter '" + std::string(key) + "'; known: " + known_keys());
}

// Throws naming the field when `value` is not finite or outside [low, high] (open ends when asked).
void check_range(const char* field, double value, double low, double high, bool low_open = false,
                 bool high_open = false) {
  const bool above = low_open ? value > low : value >= low;
  const bool below = high_open ? value < high : value <= high;
  if (std::isfinite(value) && above && below) return;
  const std::string range = std::string(low_open ? "(" : "[") + std::to_string(low) + ", " +
                            (std::isinf(high) ? std::string("inf") : std::to_string(high)) +
                            (high_open || std::isinf(high) ? ")" : "]");
  throw InvalidArgument("WriterProfile." + std::string(field) + " = " + std::to_string(value) +
                        " must be finite and in " + range);
}

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

WriterProfile WriterProfile::novice() { return WriterProfile{}; }

WriterProfile WriterProfile::skilled() {
  WriterProfile p;
  p.name = "skilled";
  p.hand_stiffness_n_per_m = 600.0;
  p.hand_damping_n_s_per_m = 8.0;
  p.writing_speed_m_s = 0.04;
  p.bias_offset_m = 0.0005;
  p.scale_error = 0.02;
  p.stroke_jitter_m = 0.0003;
  p.noise_fraction = 0.02;
  p.tremor_amplitude_n = 0.01;
  p.error_tolerance_m = 0.0005;
  p.mid_stroke_lift_probability = 0.0;
  p.outside_touch_probability = 0.0;
  p.hesitation_probability = 0.0;
  return p;
}

WriterProfile WriterProfile::foreign() {
  WriterProfile p;
  p.name = "foreign";
  p.writing_speed_m_s = 0.018;
  p.bias_offset_m = 0.003;
  p.scale_error = 0.1;
  p.stroke_jitter_m = 0.0015;
  p.error_tolerance_m = 0.0015;
  p.order_error_probability = 0.25;
  p.backwards_probability = 0.12;
  p.mid_stroke_lift_probability = 0.05;
  p.outside_touch_probability = 0.05;
  p.hesitation_probability = 0.2;
  p.hesitation_s = 0.8;
  return p;
}

void WriterProfile::validate() const {
  check_range("hand_stiffness_n_per_m", hand_stiffness_n_per_m, 0.0, 1e4, true);
  check_range("hand_damping_n_s_per_m", hand_damping_n_s_per_m, 0.0, 1e3);
  check_range("noise_fraction", noise_fraction, 0.0, 1.0);
  check_range("tremor_amplitude_n", tremor_amplitude_n, 0.0, 10.0);
  check_range("tremor_frequency_hz", tremor_frequency_hz, 0.0, 100.0, true);
  check_range("writing_speed_m_s", writing_speed_m_s, 0.0, 10.0, true);
  check_range("travel_speed_m_s", travel_speed_m_s, 0.0, 10.0, true);
  check_range("press_depth_m", press_depth_m, 0.0, 0.1);
  check_range("lift_height_m", lift_height_m, 0.0, 0.2, true);
  check_range("corner_cut_m", corner_cut_m, 0.0, 0.02);
  check_range("end_short_m", end_short_m, 0.0, 0.02);
  check_range("end_past_m", end_past_m, 0.0, 0.02);
  check_range("follow_through_m", follow_through_m, 0.0, 0.05);
  check_range("bias_offset_m", bias_offset_m, 0.0, 0.05);
  check_range("scale_error", scale_error, -0.5, 0.5, true, true);
  check_range("stroke_jitter_m", stroke_jitter_m, 0.0, 0.05);
  check_range("visual_delay_s", visual_delay_s, 0.0, 0.5);
  check_range("vision_period_s", vision_period_s, 0.001, 0.1);
  check_range("correction_rate_per_s", correction_rate_per_s, 0.0, 100.0);
  check_range("error_tolerance_m", error_tolerance_m, 0.0, 0.05);
  check_range("steering_width_m", steering_width_m, 0.0, 0.1, true);
  check_range("min_speed_fraction", min_speed_fraction, 0.0, 1.0, true);
  check_range("error_filter_s", error_filter_s, 0.0, 10.0, true);
  check_range("speed_time_constant_s", speed_time_constant_s, 0.0, 10.0, true);
  check_range("reaction_time_s", reaction_time_s, 0.0, 10.0, true);
  check_range("resistance_threshold_n", resistance_threshold_n, 0.0, 100.0, true);
  check_range("expected_drag_ratio", expected_drag_ratio, 0.0, 10.0);
  check_range("correction_per_attempt", correction_per_attempt, 0.0, 1.0);
  check_range("order_error_probability", order_error_probability, 0.0, 1.0);
  check_range("backwards_probability", backwards_probability, 0.0, 1.0);
  check_range("mid_stroke_lift_probability", mid_stroke_lift_probability, 0.0, 1.0);
  check_range("outside_touch_probability", outside_touch_probability, 0.0, 1.0);
  check_range("hesitation_probability", hesitation_probability, 0.0, 1.0);
  check_range("hesitation_s", hesitation_s, 0.0, 60.0);
  check_range("learning_rate", learning_rate, 0.0, kInf);
  if (max_attempts_per_stroke < 1 || max_attempts_per_stroke > 1000) {
    throw InvalidArgument("WriterProfile.max_attempts_per_stroke = " +
                          std::to_string(max_attempts_per_stroke) + " must be in [1, 1000]");
  }
}

WriterProfile writer_profile(std::string_view name) {
  if (name == "novice") return WriterProfile::novice();
  if (name == "skilled") return WriterProfile::skilled();
  if (name == "foreign") return WriterProfile::foreign();
  throw InvalidArgument("unknown writer profile '" + std::string(name) +
                        "'; known: novice, skilled, foreign");
}

std::vector<std::string> writer_parameter_names() {
  std::vector<std::string> names;
  for (const Field& f : kFields) names.emplace_back(f.name);
  names.emplace_back(kAttemptsKey);
  return names;
}

double writer_parameter(const WriterProfile& profile, std::string_view key) {
  if (key == kAttemptsKey) return static_cast<double>(profile.max_attempts_per_stroke);
  const Field* f = find_field(key);
  if (f == nullptr) unknown_key(key);
  return profile.*(f->member);
}

void set_writer_parameter(WriterProfile& profile, std::string_view key, double value) {
  WriterProfile changed = profile;
  if (key == kAttemptsKey) {
    if (!std::isfinite(value) || value != std::floor(value) || std::abs(value) > 1e9) {
      throw InvalidArgument("writer parameter max_attempts_per_stroke = " + std::to_string(value) +
                            " must be a whole number");
    }
    changed.max_attempts_per_stroke = static_cast<int>(value);
  } else {
    const Field* f = find_field(key);
    if (f == nullptr) unknown_key(key);
    changed.*(f->member) = value;
  }
  changed.validate();
  profile = std::move(changed);
}

void apply_writer_setting(WriterProfile& profile, std::string_view setting) {
  const std::size_t equals = setting.find('=');
  if (equals == std::string_view::npos) {
    throw InvalidArgument("writer setting '" + std::string(setting) + "' must be key=value");
  }
  const std::string_view key = setting.substr(0, equals);
  const std::string_view text = setting.substr(equals + 1);
  const std::optional<double> value = parse_finite_double(text);
  if (!value) {
    throw InvalidArgument("writer setting '" + std::string(setting) + "': '" + std::string(text) +
                          "' is not a number (a finite decimal within the range of a double is expected)");
  }
  set_writer_parameter(profile, key, *value);
}

}  // namespace calligraphy
