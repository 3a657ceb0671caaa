#include "calligraphy/model/scene.hpp"

#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

double PlacedStroke::length_m() const {
  double length = 0.0;
  for (const auto& e : elements) length += e.arc_length();
  return length;
}

std::size_t Scene::stroke_count() const {
  std::size_t n = 0;
  for (const auto& c : characters) n += c.strokes.size();
  return n;
}

void check_scene_size(std::size_t count, const std::string& what) {
  if (count > kMaxSceneCharacters) {
    throw InvalidArgument(what + ": " + std::to_string(count) + " characters, more than a scene's limit of " +
                          std::to_string(kMaxSceneCharacters));
  }
}

Scene Scene::lay_out(const std::vector<Character>& characters, const SceneLayout& layout) {
  check_scene_size(characters.size(), "Scene::lay_out");
  // Each field by its name, in its range (the ranges SchemaOf<SceneLayout> states for a trial record).
  const auto check = [](const char* field, double value, const ParameterRange& range, const char* what) {
    if (range.contains(value)) return;
    throw InvalidArgument(std::string("SceneLayout.")
                              .append(field)
                              .append(" = ")
                              .append(shortest_decimal(value))
                              .append(" m is out of range: expected ")
                              .append(what)
                              .append(range.text("m")));
  };
  check("character_size_m", layout.character_size_m, kLayoutSizeRange, "a length ");
  check("spacing_m", layout.spacing_m, kLayoutSizeRange, "a length ");
  check("start_radius_m", layout.start_radius_m, kLayoutRadiusRange, "a length ");
  check("box_margin_m", layout.box_margin_m, kLayoutMarginRange, "a length ");
  for (const double c : {layout.centre_m.x(), layout.centre_m.y()})
    check("centre_m", c, kLayoutOffsetRange, "each coordinate ");
  check("paper_z_m", layout.paper_z_m, kLayoutOffsetRange, "");
  Scene scene;
  scene.layout = layout;
  const double n = static_cast<double>(characters.size());
  for (std::size_t k = 0; k < characters.size(); ++k) {
    const Character& character = characters[k];
    PlacedCharacter placed;
    placed.code_point = character.code_point;
    placed.placement.metres_per_unit = layout.character_size_m / kDataBoxSize;
    const Vec2 box_centre_data(kDataBoxSize / 2.0, (kDataBoxTop + kDataBoxBottom) / 2.0);
    const Vec2 centre =
        layout.centre_m + Vec2((static_cast<double>(k) - (n - 1.0) / 2.0) * layout.spacing_m, 0.0);
    placed.placement.origin_m = centre - placed.placement.metres_per_unit * box_centre_data;
    for (const Stroke& stroke : character.strokes) {
      PlacedStroke ps;
      ps.typical_id = stroke.typical_id;
      ps.attraction_factors = stroke.attraction_factors;
      for (StrokeElement e : stroke.elements) {
        for (int i = 0; i <= e.degree; ++i) {
          auto& c = e.control[static_cast<std::size_t>(i)];
          c = placed.placement.to_paper(c);
          placed.bounding_box.extend(c);
        }
        ps.elements.push_back(e);
      }
      for (const Vec2& p : stroke.median) ps.median_m.push_back(placed.placement.to_paper(p));
      ps.centre_line = StrokeCentreLine::of(ps.median_m, ps.elements);
      ps.character_size_m = layout.character_size_m;
      placed.strokes.push_back(std::move(ps));
    }
    placed.bounding_box.min().array() -= layout.box_margin_m;
    placed.bounding_box.max().array() += layout.box_margin_m;
    scene.characters.push_back(std::move(placed));
  }
  return scene;
}

}  // namespace calligraphy
