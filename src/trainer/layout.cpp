#include "trainer/layout.hpp"

#include <algorithm>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::trainer {

WindowLayout::WindowLayout(std::size_t count, double width_px, double height_px, double panel_px) {
  const SceneLayout scene;  // the layout every trial and the row use
  area_width_ = width_px - panel_px;
  height_ = height_px;
  constexpr double kMarginPx = 24.0;
  if (count == 0) throw InvalidArgument("the trainer needs at least one character");
  if (area_width_ < 4 * kMarginPx || height_px < 4 * kMarginPx) {
    throw InvalidArgument("window " + std::to_string(static_cast<int>(width_px)) + "x" +
                          std::to_string(static_cast<int>(height_px)) + " is too small for the trainer");
  }
  const double n = static_cast<double>(count);
  const double row_width_m = (n - 1.0) * scene.spacing_m + scene.character_size_m;
  scale_ = std::min((area_width_ - 2 * kMarginPx) / row_width_m,
                    (height_px - 2 * kMarginPx) / scene.character_size_m);
  row_origin_px_ = Vec2(area_width_ / 2.0, height_px / 2.0);
  const double side_px = scene.character_size_m * scale_;
  for (std::size_t k = 0; k < count; ++k) {
    const Vec2 centre_m((static_cast<double>(k) - (n - 1.0) / 2.0) * scene.spacing_m, 0.0);
    row_centre_m_.push_back(centre_m);
    // The data box is centred on the character's centre (Scene::lay_out).
    const Vec2 centre_px(row_origin_px_.x() + centre_m.x() * scale_,
                         row_origin_px_.y() - centre_m.y() * scale_);
    boxes_.push_back(ScreenBox{centre_px.x() - side_px / 2.0, centre_px.y() - side_px / 2.0, side_px});
  }
}

Vec2 WindowLayout::to_screen(std::size_t character, const Vec2& trial_m) const {
  const Vec2 row_m = trial_m + row_centre_m_.at(character);  // each trial is centred at the origin
  return Vec2(row_origin_px_.x() + row_m.x() * scale_, row_origin_px_.y() - row_m.y() * scale_);
}

Vec2 WindowLayout::to_trial(std::size_t character, const Vec2& screen_px) const {
  const Vec2 row_m((screen_px.x() - row_origin_px_.x()) / scale_,
                   (row_origin_px_.y() - screen_px.y()) / scale_);
  return row_m - row_centre_m_.at(character);
}

Vec2 WindowLayout::row_to_screen(const Vec2& row_m) const {
  return Vec2(row_origin_px_.x() + row_m.x() * scale_, row_origin_px_.y() - row_m.y() * scale_);
}

Vec2 WindowLayout::screen_to_row(const Vec2& screen_px) const {
  return Vec2((screen_px.x() - row_origin_px_.x()) / scale_, (row_origin_px_.y() - screen_px.y()) / scale_);
}

Vec2 WindowLayout::data_to_screen(std::size_t character, const Vec2& data) const {
  const ScreenBox& b = box(character);
  return Vec2(b.x_px + data.x() / kDataBoxSize * b.size_px,
              b.y_px + (kDataBoxTop - data.y()) / kDataBoxSize * b.size_px);
}

}  // namespace calligraphy::trainer
