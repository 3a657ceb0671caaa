// `calligraphy model CHAR [--json] [--svg FILE] [--data DIR]`: the character's Table-3 data (paper section
// 3.5) and, per stroke, its typical stroke, elements, feature points and attraction factors; --svg
// draws the model like the paper's Fig. 13.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/report/model_svg.hpp"
#include "calligraphy/report/trial_report.hpp"
#include "cli/commands.hpp"
#include "cli/library_options.hpp"
#include "core/unicode.hpp"

namespace calligraphy::cli {
namespace {

std::string unicode_name(char32_t cp) {
  if (cp == 0) return {};
  char text[12];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(cp));
  return text;
}

nlohmann::json model_json(const Character& character, const CharacterTable& table) {
  nlohmann::json strokes = nlohmann::json::array();
  for (std::size_t s = 0; s < character.strokes.size(); ++s) {
    const Stroke& stroke = character.strokes[s];
    const TypicalStroke& type = typical_stroke(stroke.typical_id);
    nlohmann::json feature_points = nlohmann::json::array();
    for (std::size_t k = 0; k < stroke.feature_point_count(); ++k) {
      feature_points.push_back({stroke.feature_point(k).x(), stroke.feature_point(k).y()});
    }
    nlohmann::json elements = nlohmann::json::array();
    for (const StrokeElement& e : stroke.elements) {
      nlohmann::json points = nlohmann::json::array();
      for (int i = 0; i <= e.degree; ++i) {
        points.push_back(
            {e.control[static_cast<std::size_t>(i)].x(), e.control[static_cast<std::size_t>(i)].y()});
      }
      elements.push_back({{"kind", e.kind == ElementKind::line ? "line" : "bezier"},
                          {"degree", e.degree},
                          {"control_points", points}});
    }
    strokes.push_back(
        {{"typical_id", stroke.typical_id},
         {"acronym", std::string(type.acronym)},
         {"name", std::string(type.name_zh)},
         {"pinyin", std::string(type.pinyin)},
         {"element_count", stroke.elements.size()},
         {"feature_points", feature_points},
         {"unicode", type.unicode ? nlohmann::json(unicode_name(type.unicode)) : nlohmann::json(nullptr)},
         {"elements", elements},
         {"feature_point_indices", table.feature_point_indices[s]},
         {"attraction_factors", stroke.attraction_factors}});
  }
  return {{"character", encode_utf8(character.code_point)}, {"typical_strokes", character.strokes.size()},
          {"typical_stroke_ids", table.typical_stroke_ids}, {"control_points", table.control_points.size()},
          {"feature_points", table.feature_point_count()},  {"strokes", strokes}};
}

void print_model(const Character& character, const CharacterTable& table) {
  std::printf("Character %s, from %s\n", describe_character(character.code_point).c_str(),
              character.source.c_str());
  std::printf("  Number of typical strokes  %zu\n", character.strokes.size());
  std::printf("  ID array of typical strokes");
  for (int id : table.typical_stroke_ids) std::printf(" %d", id);
  std::printf("\n  Number of control points   %zu\n", table.control_points.size());
  std::printf("  Number of feature points   %zu\n\n", table.feature_point_count());
  for (std::size_t s = 0; s < character.strokes.size(); ++s) {
    const Stroke& stroke = character.strokes[s];
    const TypicalStroke& type = typical_stroke(stroke.typical_id);
    std::size_t lines = 0;
    for (const StrokeElement& e : stroke.elements) lines += e.kind == ElementKind::line ? 1 : 0;
    std::printf("  stroke %zu: ID %d %s %s %s  elements %zu (%zu LSE, %zu CSE)  feature points %zu [", s + 1,
                type.id, std::string(type.acronym).c_str(), std::string(type.name_zh).c_str(),
                type.unicode ? unicode_name(type.unicode).c_str() : "-", stroke.elements.size(), lines,
                stroke.elements.size() - lines, stroke.feature_point_count());
    for (std::size_t k = 0; k < stroke.feature_point_count(); ++k) {
      std::printf("%s(%.1f, %.1f)", k ? " " : "", stroke.feature_point(k).x(), stroke.feature_point(k).y());
    }
    std::printf("]  attraction [");
    for (std::size_t k = 0; k < stroke.attraction_factors.size(); ++k) {
      std::printf("%s%.2f", k ? " " : "", stroke.attraction_factors[k]);
    }
    std::printf("]\n");
    for (const StrokeElement& e : stroke.elements) {
      std::printf("    %s degree %d:", e.kind == ElementKind::line ? "LSE" : "CSE", e.degree);
      for (int i = 0; i <= e.degree; ++i) {
        std::printf(" (%.1f, %.1f)", e.control[static_cast<std::size_t>(i)].x(),
                    e.control[static_cast<std::size_t>(i)].y());
      }
      std::printf("\n");
    }
  }
}

}  // namespace

int command_model(const Args& args) {
  const Arguments arguments(args, {"data", "store", "svg"}, {"json"});
  if (arguments.positionals().size() != 1) throw UsageError("model takes exactly one character");
  const std::u32string chars = characters_from(arguments.positionals()[0]);
  if (chars.size() != 1)
    throw UsageError("model takes exactly one character, got " + std::to_string(chars.size()));
  const Character character = CharacterSource(arguments).load(chars[0]);
  const CharacterTable table = character_table(character);
  if (const auto path = arguments.option("svg")) write_file(*path, model_svg(character));
  if (arguments.flag("json")) {
    std::cout << model_json(character, table).dump(2) << "\n";
  } else {
    print_model(character, table);
  }
  return 0;
}

}  // namespace calligraphy::cli
