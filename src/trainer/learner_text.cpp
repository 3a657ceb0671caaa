// The learner's words (learner_text.hpp).
#include "trainer/learner_text.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace calligraphy::trainer {
namespace {

// A distance as a person reads it: whole millimetres from 2 mm, one decimal below.
std::string millimetres(double metres) {
  const double mm = std::abs(metres) * 1e3;
  char text[32];
  std::snprintf(text, sizeof text, mm >= 2.0 ? "%.0f mm" : "%.1f mm", mm);
  return text;
}

std::string stroke_label(std::size_t stroke_1based) {
  std::string text = "Stroke ";
  text += std::to_string(stroke_1based);
  return text;
}

}  // namespace

LearnerDevice learner_device(const std::string& device, bool hardware, bool simulated_writer) noexcept {
  if (simulated_writer) return LearnerDevice::simulated_writer;
  if (device == "mouse") return LearnerDevice::mouse;
  if (device == "mouse-hand") return LearnerDevice::mouse_hand;
  if (hardware) return LearnerDevice::haptic;
  return LearnerDevice::simulated_device;
}

std::string device_line(LearnerDevice device, bool guidance) {
  switch (device) {
    case LearnerDevice::mouse:
      return "Hold the left mouse button and draw each stroke; a mouse cannot push back, so nothing is felt.";
    case LearnerDevice::mouse_hand:
      return guidance
                 ? "Hold the left mouse button and draw each stroke; the mouse moves a simulated pen that is "
                   "pulled towards the stroke on screen, but a mouse cannot push back, so nothing is felt."
                 : "Hold the left mouse button and draw each stroke; the mouse moves a simulated pen, and "
                   "a mouse cannot push back, so nothing is felt.";
    case LearnerDevice::haptic:
      return guidance
                 ? "Press the pen to the paper at the red circle and draw each stroke; you feel the paper, "
                   "and the pen guides your hand along the stroke."
                 : "Press the pen to the paper at the red circle and draw each stroke; you feel the paper "
                   "only: no guidance in this trial.";
    case LearnerDevice::simulated_writer:
      return "A simulated writer writes this trial: watch it write; nothing is needed from you.";
    case LearnerDevice::simulated_device:
      return "The device is simulated: nothing moves it from here, and nothing is felt.";
  }
  return {};
}

std::string guidance_words(LearnerDevice device, bool guidance) {
  if (!guidance) return "guidance off";
  switch (device) {
    case LearnerDevice::haptic:
      return "guidance on";
    case LearnerDevice::mouse_hand:
      return "guidance on the simulated pen, not felt";
    case LearnerDevice::simulated_writer:
      return "guidance on the simulated writer's pen";
    case LearnerDevice::mouse:
    case LearnerDevice::simulated_device:
      break;
  }
  return "no force output: guidance not felt";
}

std::string stroke_of(std::size_t stroke_1based, std::size_t strokes) {
  if (stroke_1based > strokes) return "Every stroke written";
  return stroke_label(stroke_1based) + " of " + std::to_string(strokes);
}

std::string offset_words(const Vec2& offset_m) {
  const double ax = std::abs(offset_m.x());
  const double ay = std::abs(offset_m.y());
  const double larger = std::max(ax, ay);
  const auto named = [&](double a) { return a >= larger / 3.0; };
  std::string text;
  if (ax > 0.0 && named(ax)) text += millimetres(ax) + (offset_m.x() < 0.0 ? " left" : " right");
  if (ay > 0.0 && named(ay)) {
    if (!text.empty()) text += " and ";
    text += millimetres(ay) + (offset_m.y() > 0.0 ? " above" : " below");
  }
  if (text.empty()) text = "0.0 mm";
  return text;
}

Feedback stroke_written(std::size_t stroke_1based, double mean_deviation_m,
                        const StrokeAcceptance& acceptance) {
  Feedback f;
  f.text = stroke_label(stroke_1based);
  if (!std::isfinite(mean_deviation_m)) {
    f.text += ": written";
    f.tone = FeedbackTone::good;
    return f;
  }
  const bool good = mean_deviation_m <= 0.5 * acceptance.mean_deviation_m;
  f.text += good ? ": good, " : ": written, ";
  char mm[32];  // an average to a tenth of a millimetre
  std::snprintf(mm, sizeof mm, "%.1f mm", mean_deviation_m * 1e3);
  f.text += mm;
  f.text += " off on average";
  if (!good) f.text += "; keep to the middle of the stroke";
  f.tone = good ? FeedbackTone::good : FeedbackTone::fix;
  return f;
}

Feedback stroke_refused(const RefusedAttempt& attempt) {
  Feedback f;
  f.tone = FeedbackTone::fix;
  const std::string stroke = stroke_label(attempt.stroke_1based);
  switch (attempt.refusal) {
    case StrokeRefusal::too_short:
      f.text = stroke + ": too short; carry on to the end";
      return f;
    case StrokeRefusal::backwards:
      f.text = stroke + ": written backwards; start at the other end";
      return f;
    case StrokeRefusal::wrong_place:
      if (attempt.start_offset_m && attempt.start_offset_m->norm() > attempt.start_radius_m) {
        // "left of the start", "right of the start"; "above the start", "... and 2 mm below the start"
        const std::string where = offset_words(*attempt.start_offset_m);
        const bool vertical_last = where.ends_with("above") || where.ends_with("below");
        f.text = stroke + ": started " + where + (vertical_last ? " the start" : " of the start");
      } else {
        f.text = stroke + ": off the stroke; follow the outline";
      }
      return f;
    case StrokeRefusal::wrong_order:
      if (attempt.written_instead_1based && *attempt.written_instead_1based != attempt.stroke_1based) {
        f.text = "That was stroke " + std::to_string(*attempt.written_instead_1based) + "; stroke " +
                 std::to_string(attempt.stroke_1based) + " comes first";
      } else {
        f.text = stroke + " comes first: that stroke comes later";
      }
      return f;
    case StrokeRefusal::wrong_stroke:
      if (attempt.written_instead_1based && *attempt.written_instead_1based != attempt.stroke_1based) {
        f.text = "That was stroke " + std::to_string(*attempt.written_instead_1based) +
                 "; now write stroke " + std::to_string(attempt.stroke_1based);
      } else {
        f.text = stroke + ": that was another stroke's shape";
      }
      return f;
    case StrokeRefusal::none:
      break;
  }
  f.text = stroke + ": not written; try it again";
  return f;
}

Feedback stroke_hint(std::size_t stroke_1based) {
  std::string text = "Here is stroke ";
  text += std::to_string(stroke_1based);
  text += ": follow the blue path from its start";
  return {text, FeedbackTone::hint};
}

Feedback stroke_assisted(std::size_t stroke_1based) {
  return {stroke_label(stroke_1based) + " shown and counted as assisted", FeedbackTone::hint};
}

}  // namespace calligraphy::trainer
