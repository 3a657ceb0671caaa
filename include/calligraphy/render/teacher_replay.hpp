#pragma once
/// \file teacher_replay.hpp
/// A teacher's recorded trial as time-indexed guidance (record and replay: Henmi & Yoshikawa 1998,
/// Feygin, Keehner & Tendick 2002). The recording is read with the renderer's own rules: the interaction
/// states of Fig. 6 and the active stroke with its feature planes (paper sections 2.3 and 4.3), so that
/// each stroke of the scene gets the window of the recording in which the teacher wrote it, from entering
/// WS on the attempt that was accepted to writing its last feature point, and each sample of a window
/// gets the teacher's active element and the parameter of its foot point there. During a replayed trial
/// the attraction point of stroke k is where the teacher was `elapsed` seconds into stroke k's window,
/// kept on the trainee's active element (section 4.3: only the active element exerts force, which
/// keeps a teacher who is already round a corner from pulling across it): the teacher's foot point when
/// the teacher is on that element, its end when the teacher is further on, its start when behind.
#include <cstddef>
#include <span>
#include <vector>

#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/guidance_mode.hpp"

namespace calligraphy {

struct ForceLawParameters;

class TeacherReplay {
 public:
  /// No recording: `empty()`.
  TeacherReplay() = default;
  /// Reads `samples` (the teacher's trial on the same scene, device frame [m], times [s]) with the
  /// contact hysteresis and feature-plane margin of `force`. Throws InvalidArgument for a bad trajectory
  /// (validate_teacher_trajectory) and when the teacher never wrote a stroke of the scene in order,
  /// naming the stroke (scene index, character and stroke within it).
  TeacherReplay(const Scene& scene, std::span<const TeacherSample> samples, const ForceLawParameters& force);

  [[nodiscard]] bool empty() const noexcept { return windows_.empty(); }
  /// Number of strokes with a window (the scene's stroke count, or 0 when empty).
  [[nodiscard]] std::size_t stroke_count() const noexcept { return windows_.size(); }
  /// Teacher's time [s] at which stroke `scene_stroke` (0-based over the scene) was entered and completed.
  [[nodiscard]] double stroke_begin_s(std::size_t scene_stroke) const noexcept;
  [[nodiscard]] double stroke_end_s(std::size_t scene_stroke) const noexcept;
  /// The teacher's pen on the paper plane [m], `elapsed_s` after the start of stroke `scene_stroke`'s
  /// window, clamped to the window (before: its first point, after: its last point); linear between
  /// samples. Zero for an index out of range. Servo path: noexcept, no allocation.
  [[nodiscard]] Vec2 position(std::size_t scene_stroke, double elapsed_s) const noexcept;
  /// The attraction point on the trainee's active element `element` (index `element_index` within
  /// stroke `scene_stroke`) `elapsed_s` into the stroke's window (see the file comment) [m]. Servo
  /// path: noexcept, no allocation.
  [[nodiscard]] Vec2 attraction_point(std::size_t scene_stroke, double elapsed_s, std::size_t element_index,
                                      const StrokeElement& element) const noexcept;

 private:
  struct Window {
    double begin_s = 0.0;
    double end_s = 0.0;
  };
  std::vector<double> times_s_;
  std::vector<Vec2> positions_m_;
  std::vector<std::size_t> elements_;  // the teacher's active element at each sample (inside a window)
  std::vector<double> parameters_;     // the parameter of the teacher's foot point on it
  std::vector<Window> windows_;
};

}  // namespace calligraphy
