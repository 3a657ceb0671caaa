#pragma once
// Where things go in the trainer's window: the row of character boxes (the paper's character group,
// Fig. 30) on the left, the panel on the right. Maps between window pixels (x right, y down) and paper
// metres: each trial lays its one character out at the device's centre, and the row shows it at its
// place, so a trial's metres are shifted by that character's offset in the row.
#include <cstddef>
#include <vector>

#include "calligraphy/model/scene.hpp"

namespace calligraphy::trainer {

/// A character's data box on screen: top-left corner and side [px].
struct ScreenBox {
  double x_px = 0.0;
  double y_px = 0.0;
  double size_px = 0.0;
};

class WindowLayout {
 public:
  /// The row of `count` characters (Scene::lay_out's defaults) in a window of the given size [px], the
  /// panel `panel_px` wide on the right. Throws InvalidArgument for a count of 0 or a window too small.
  WindowLayout(std::size_t count, double width_px, double height_px, double panel_px);

  [[nodiscard]] std::size_t count() const noexcept { return boxes_.size(); }
  [[nodiscard]] const ScreenBox& box(std::size_t character) const { return boxes_.at(character); }
  /// Pixels per metre of paper.
  [[nodiscard]] double scale_px_per_m() const noexcept { return scale_; }
  /// Window pixel of a point in the trial of character `character` [m].
  [[nodiscard]] Vec2 to_screen(std::size_t character, const Vec2& trial_m) const;
  /// Trial metres of a window pixel, for the trial of character `character`.
  [[nodiscard]] Vec2 to_trial(std::size_t character, const Vec2& screen_px) const;
  /// Window pixel of a point of a trial whose scene is the whole row (Scene::lay_out of every character) [m].
  [[nodiscard]] Vec2 row_to_screen(const Vec2& row_m) const;
  /// Row metres of a window pixel (the inverse of row_to_screen).
  [[nodiscard]] Vec2 screen_to_row(const Vec2& screen_px) const;
  /// Window pixel of a point in character data units (the 1024 box, y up).
  [[nodiscard]] Vec2 data_to_screen(std::size_t character, const Vec2& data) const;
  /// The left part of the window the row is drawn in [px].
  [[nodiscard]] double area_width_px() const noexcept { return area_width_; }
  [[nodiscard]] double height_px() const noexcept { return height_; }

 private:
  std::vector<ScreenBox> boxes_;
  std::vector<Vec2> row_centre_m_;  // each character's centre in row metres
  double scale_ = 1.0;
  Vec2 row_origin_px_ = Vec2::Zero();  // window pixel of row metres (0, 0)
  double area_width_ = 0.0;
  double height_ = 0.0;
};

}  // namespace calligraphy::trainer
