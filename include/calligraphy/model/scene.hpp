#pragma once
/// \file scene.hpp
/// A scene places characters on the paper plane in metres: the data box of each character (y up)
/// maps to the plane z = z0 of device space, x right, y away from the writer, +z out of the paper.
/// Several characters lie in a row, the paper's character group (Fig. 30). A scene holds only the
/// characters it is given.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "calligraphy/model/character.hpp"

namespace calligraphy {

/// Maps a character's data box to metres on the paper: p_m = origin_m + metres_per_unit * p_data.
struct Placement {
  Vec2 origin_m = Vec2::Zero();                  ///< where the data point (0, 0) lands [m]
  double metres_per_unit = 0.06 / kDataBoxSize;  ///< scale [m per data unit]

  [[nodiscard]] Vec2 to_paper(const Vec2& data) const { return origin_m + metres_per_unit * data; }
  [[nodiscard]] Vec2 to_data(const Vec2& paper_m) const { return (paper_m - origin_m) / metres_per_unit; }
};

/// How a scene lays characters out.
struct SceneLayout {
  double character_size_m = 0.06;  ///< side of each character's data box on paper [m]
  double spacing_m = 0.066;        ///< centre-to-centre distance in the row [m]
  Vec2 centre_m = Vec2::Zero();    ///< centre of the row on the paper [m]
  double paper_z_m = 0.0;          ///< z0, height of the paper plane in device space [m]
  double box_margin_m = 0.005;     ///< bounding box margin around the strokes (paper Fig. 5) [m]
  double start_radius_m = 0.005;   ///< radius of the start-point neighbourhood (paper Fig. 5, Table 1) [m]
};

/// The centre line a person follows when writing a stroke: the data's median (what the outline shows,
/// brush hooks included), or the elements sampled densely when the stroke has no median. Progress and
/// acceptance of a stroke are measured along it (model/stroke_progress.hpp).
struct StrokeCentreLine {
  std::vector<Vec2> points_m;  ///< polyline [m], at least 2 points, no repeats
  std::vector<double> arc_m;   ///< arc length from the first point to each point [m], same size
  /// Arc [m] of each element's end feature point projected on the line, non-decreasing, one per element:
  /// the last is where the stroke ends; the others are the corners between elements.
  std::vector<double> element_end_arc_m;
  double start_arc_m = 0.0;  ///< arc [m] of the first feature point projected on the line
  [[nodiscard]] double length_m() const { return arc_m.empty() ? 0.0 : arc_m.back(); }
  /// The centre line of a stroke from its median (or elements) and elements, in the same units.
  static StrokeCentreLine of(const std::vector<Vec2>& median, const std::vector<StrokeElement>& elements);
};

/// A stroke in metres.
struct PlacedStroke {
  int typical_id = 0;
  std::vector<StrokeElement> elements;     ///< control points in metres on the paper
  std::vector<double> attraction_factors;  ///< one per feature point, dimensionless
  std::vector<Vec2> median_m;              ///< the source median in metres, for drawing
  StrokeCentreLine centre_line;            ///< what progress is measured along (set by Scene::lay_out)
  double character_size_m = 0.06;          ///< side of its character's data box on paper [m] (Scene::lay_out)
  [[nodiscard]] const Vec2& start() const { return elements.front().start(); }
  [[nodiscard]] const Vec2& end() const { return elements.back().end(); }
  [[nodiscard]] double length_m() const;
};

/// A character placed on the paper.
struct PlacedCharacter {
  char32_t code_point = 0;
  Placement placement;
  std::vector<PlacedStroke> strokes;
  Eigen::AlignedBox2d bounding_box;  ///< strokes' box plus the margin [m]
};

/// The most characters one scene holds: a row of them is written in one trial (at the default 66 mm
/// spacing, 1000 characters are 66 m of paper), and each costs memory and loading time, so a longer text
/// is refused up front (Scene::lay_out; front ends check the count before loading the characters).
inline constexpr std::size_t kMaxSceneCharacters = 1000;

/// The farthest the row's centre and the paper's height may lie from the device's origin [m]: farther than
/// any haptic device reaches, and near enough that every position of a trial stays a finite number (a paper
/// at 1e308 m made the simulated pen's position overflow).
inline constexpr double kMaxLayoutOffsetM = kDeviceReachM;
/// The largest side of a character's box and centre-to-centre spacing [m]: the same reach
/// (kMaxLayoutOffsetM).
inline constexpr double kMaxLayoutSizeM = kMaxLayoutOffsetM;
/// The largest bounding-box margin and start-point radius [m]: 0.1 m, more than the side of a character
/// (60 mm by default) and twenty times the paper's start neighbourhood (5 mm, Fig. 5): a larger one is a
/// typing error.
inline constexpr double kMaxLayoutMarginM = 0.1;
/// The ranges of SceneLayout's fields [m], as Scene::lay_out checks them and a trial record's schema states
/// them: a character's side and the spacing in (0, kMaxLayoutSizeM], the box margin in [0,
/// kMaxLayoutMarginM], the start radius in (0, kMaxLayoutMarginM], each coordinate of the row's centre and
/// the paper's height in
/// [-kMaxLayoutOffsetM, kMaxLayoutOffsetM].
inline constexpr ParameterRange kLayoutSizeRange{.low = 0.0, .high = kMaxLayoutSizeM, .low_open = true};
inline constexpr ParameterRange kLayoutMarginRange{.low = 0.0, .high = kMaxLayoutMarginM};
inline constexpr ParameterRange kLayoutRadiusRange{.low = 0.0, .high = kMaxLayoutMarginM, .low_open = true};
inline constexpr ParameterRange kLayoutOffsetRange{.low = -kMaxLayoutOffsetM, .high = kMaxLayoutOffsetM};

/// Throws InvalidArgument "<what>: N characters, more than a scene's limit of kMaxSceneCharacters" when
/// `count` > kMaxSceneCharacters.
void check_scene_size(std::size_t count, const std::string& what);

/// Characters placed in a row, written left to right.
struct Scene {
  std::vector<PlacedCharacter> characters;
  SceneLayout layout;

  [[nodiscard]] std::size_t stroke_count() const;
  /// Scene for the given characters. Throws InvalidArgument for a non-positive size, radius or spacing,
  /// or more than kMaxSceneCharacters characters.
  static Scene lay_out(const std::vector<Character>& characters, const SceneLayout& layout = {});
};

}  // namespace calligraphy
