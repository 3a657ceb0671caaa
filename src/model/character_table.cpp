#include <string>

#include "calligraphy/model/character.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

std::size_t CharacterTable::feature_point_count() const {
  std::size_t n = 0;
  for (const auto& f : feature_point_indices) n += f.size();
  return n;
}

CharacterTable character_table(const Character& character) {
  CharacterTable table;
  for (const Stroke& stroke : character.strokes) {
    table.typical_stroke_ids.push_back(stroke.typical_id);
    std::vector<std::vector<int>> elements;
    std::vector<int> features;
    int joint = -1;  // index of the previous element's end, shared with the next element's start
    for (const StrokeElement& element : stroke.elements) {
      if (element.degree < 1 || element.degree > kMaxElementDegree) {  // control[] holds degree + 1 points
        throw InvalidArgument("character_table: stroke " + std::to_string(table.typical_stroke_ids.size()) +
                              " element " + std::to_string(elements.size() + 1) + ": degree " +
                              std::to_string(element.degree) + " outside 1-4");
      }
      std::vector<int> indices;
      for (int i = 0; i <= element.degree; ++i) {
        if (i == 0 && joint >= 0) {
          indices.push_back(joint);
          continue;
        }
        table.control_points.push_back(element.control[static_cast<std::size_t>(i)]);
        indices.push_back(static_cast<int>(table.control_points.size()) - 1);
      }
      features.push_back(indices.front());
      joint = indices.back();
      elements.push_back(std::move(indices));
    }
    if (joint >= 0) features.push_back(joint);
    table.element_control_indices.push_back(std::move(elements));
    table.feature_point_indices.push_back(std::move(features));
  }
  return table;
}

}  // namespace calligraphy
