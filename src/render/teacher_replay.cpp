#include "calligraphy/render/teacher_replay.hpp"

#include <algorithm>
#include <string>

#include "calligraphy/collision/active_stroke.hpp"
#include "calligraphy/model/nearest_point.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/interaction_state.hpp"

namespace calligraphy {

TeacherReplay::TeacherReplay(const Scene& scene, std::span<const TeacherSample> samples,
                             const ForceLawParameters& force) {
  validate_teacher_trajectory(samples);
  times_s_.reserve(samples.size());
  positions_m_.reserve(samples.size());
  elements_.assign(samples.size(), 0);
  parameters_.assign(samples.size(), 0.0);
  for (const TeacherSample& s : samples) {
    times_s_.push_back(s.time_s);
    positions_m_.push_back(s.position_m.head<2>());
  }
  // Read the recording as the renderer reads a live pen: the window of a stroke opens when WS is entered
  // and closes when the stroke is written (its end passed, or a lift near it); a lift short of it reopens
  // the window at the next entry.
  const std::size_t strokes = scene.stroke_count();
  std::vector<Window> windows(strokes);
  ActiveStroke active(scene, force.acceptance);
  InteractionState state = InteractionState::separation;
  double entered_s = samples.front().time_s;
  const double paper_z = scene.layout.paper_z_m;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const TeacherSample& s = samples[i];
    if (active.finished()) break;
    const Vec2 tip = s.position_m.head<2>();
    StateInputs inputs;
    const double release_z =
        paper_z + (state == InteractionState::separation ? 0.0 : force.contact_hysteresis_m);
    inputs.touching = s.position_m.z() <= release_z;
    inputs.inside_box = active.character()->bounding_box.contains(tip);
    inputs.in_start_neighbourhood = (tip - active.stroke()->start()).norm() <= scene.layout.start_radius_m;
    InteractionState next = next_state(state, inputs);
    if (state == InteractionState::writing && next == InteractionState::separation) {
      const std::size_t index = active.strokes_written();
      if (active.lift().stroke_completed) {
        windows[index] = Window{entered_s, s.time_s};
        // The lift sample closes the window: the teacher is where it last wrote.
        if (i > 0) {
          elements_[i] = elements_[i - 1];
          parameters_[i] = parameters_[i - 1];
        }
      }
    }
    if (next == InteractionState::writing && state != InteractionState::writing) {
      entered_s = s.time_s;
      active.begin(tip);
    }
    if (next == InteractionState::writing) {
      const std::size_t index = active.strokes_written();
      const std::size_t last_element = active.stroke()->elements.size() - 1;
      if (active.advance(tip).stroke_completed) {
        windows[index] = Window{entered_s, s.time_s};
        next = InteractionState::calibration;
        elements_[i] = last_element;
        parameters_[i] = 1.0;
      } else {
        elements_[i] = active.element_index();
        parameters_[i] = nearest_point(*active.element(), tip, force.nearest).t;
      }
    }
    state = next;
  }
  if (!active.finished()) {
    const std::size_t missing = active.strokes_written();
    throw InvalidArgument("teacher trajectory: stroke " + std::to_string(missing) +
                          " of the scene (character " + std::to_string(active.character_index()) +
                          ", stroke " + std::to_string(active.stroke_index()) +
                          ") is never written in order, so it has nothing to replay");
  }
  windows_ = std::move(windows);
}

double TeacherReplay::stroke_begin_s(std::size_t scene_stroke) const noexcept {
  return scene_stroke < windows_.size() ? windows_[scene_stroke].begin_s : 0.0;
}

double TeacherReplay::stroke_end_s(std::size_t scene_stroke) const noexcept {
  return scene_stroke < windows_.size() ? windows_[scene_stroke].end_s : 0.0;
}

Vec2 TeacherReplay::position(std::size_t scene_stroke, double elapsed_s) const noexcept {
  if (scene_stroke >= windows_.size()) return Vec2::Zero();
  const Window& w = windows_[scene_stroke];
  const double t = std::clamp(w.begin_s + std::max(elapsed_s, 0.0), w.begin_s, w.end_s);
  const auto upper = std::upper_bound(times_s_.begin(), times_s_.end(), t);
  if (upper == times_s_.begin()) return positions_m_.front();
  if (upper == times_s_.end()) return positions_m_.back();
  const auto i = static_cast<std::size_t>(upper - times_s_.begin());
  const double span = times_s_[i] - times_s_[i - 1];
  const double f = span > 0.0 ? (t - times_s_[i - 1]) / span : 1.0;
  return positions_m_[i - 1] + f * (positions_m_[i] - positions_m_[i - 1]);
}

}  // namespace calligraphy

namespace calligraphy {

Vec2 TeacherReplay::attraction_point(std::size_t scene_stroke, double elapsed_s, std::size_t element_index,
                                     const StrokeElement& element) const noexcept {
  if (scene_stroke >= windows_.size()) return element.start();
  const Window& w = windows_[scene_stroke];
  const double t = std::clamp(w.begin_s + std::max(elapsed_s, 0.0), w.begin_s, w.end_s);
  // The last sample at or before t; within a window every sample has an element and a parameter.
  auto upper = std::upper_bound(times_s_.begin(), times_s_.end(), t);
  if (upper == times_s_.begin()) ++upper;
  const auto i = static_cast<std::size_t>(upper - times_s_.begin()) - 1;
  const std::size_t teacher_element = elements_[i];
  if (teacher_element > element_index) return element.end();
  if (teacher_element < element_index) return element.start();
  double u = parameters_[i];
  if (i + 1 < times_s_.size() && times_s_[i + 1] <= w.end_s && elements_[i + 1] == teacher_element &&
      times_s_[i + 1] > times_s_[i]) {
    const double f = std::clamp((t - times_s_[i]) / (times_s_[i + 1] - times_s_[i]), 0.0, 1.0);
    u += f * (parameters_[i + 1] - u);
  }
  return element.point(u);
}

}  // namespace calligraphy
