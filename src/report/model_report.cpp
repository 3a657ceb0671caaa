#include "calligraphy/report/model_report.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "report/appendf.hpp"

namespace calligraphy {
namespace {

std::string unicode_name(char32_t cp) {
  if (cp == 0) return {};
  char text[12];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(cp));
  return text;
}

}  // namespace

std::string model_json(const Character& character) {
  const CharacterTable table = character_table(character);
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
  const nlohmann::json doc = {
      {"character", encode_utf8(character.code_point)}, {"typical_strokes", character.strokes.size()},
      {"typical_stroke_ids", table.typical_stroke_ids}, {"control_points", table.control_points.size()},
      {"feature_points", table.feature_point_count()},  {"strokes", strokes}};
  return json_text(doc, 2) + "\n";
}

std::string model_text(const Character& character) {
  const CharacterTable table = character_table(character);
  std::string out;
  appendf(out, "Character %s, from %s\n", describe_character(character.code_point).c_str(),
          character.source.c_str());
  appendf(out, "  Number of typical strokes  %zu\n", character.strokes.size());
  out += "  ID array of typical strokes";
  for (int id : table.typical_stroke_ids) appendf(out, " %d", id);
  appendf(out, "\n  Number of control points   %zu\n", table.control_points.size());
  appendf(out, "  Number of feature points   %zu\n\n", table.feature_point_count());
  for (std::size_t s = 0; s < character.strokes.size(); ++s) {
    const Stroke& stroke = character.strokes[s];
    const TypicalStroke& type = typical_stroke(stroke.typical_id);
    std::size_t lines = 0;
    for (const StrokeElement& e : stroke.elements) lines += e.kind == ElementKind::line ? 1 : 0;
    appendf(out, "  stroke %zu: ID %d %s %s %s  elements %zu (%zu LSE, %zu CSE)  feature points %zu [", s + 1,
            type.id, std::string(type.acronym).c_str(), std::string(type.name_zh).c_str(),
            type.unicode ? unicode_name(type.unicode).c_str() : "-", stroke.elements.size(), lines,
            stroke.elements.size() - lines, stroke.feature_point_count());
    for (std::size_t k = 0; k < stroke.feature_point_count(); ++k) {
      appendf(out, "%s(%.1f, %.1f)", k ? " " : "", stroke.feature_point(k).x(), stroke.feature_point(k).y());
    }
    out += "]  attraction [";
    for (std::size_t k = 0; k < stroke.attraction_factors.size(); ++k) {
      appendf(out, "%s%.2f", k ? " " : "", stroke.attraction_factors[k]);
    }
    out += "]\n";
    for (const StrokeElement& e : stroke.elements) {
      appendf(out, "    %s degree %d:", e.kind == ElementKind::line ? "LSE" : "CSE", e.degree);
      for (int i = 0; i <= e.degree; ++i) {
        appendf(out, " (%.1f, %.1f)", e.control[static_cast<std::size_t>(i)].x(),
                e.control[static_cast<std::size_t>(i)].y());
      }
      out += "\n";
    }
  }
  return out;
}

}  // namespace calligraphy
