#include "calligraphy/report/model_svg.hpp"

#include <cstdio>

#include "calligraphy/core/unicode.hpp"
#include "report/markup_escape.hpp"

namespace calligraphy {
namespace {

// SVG coordinates of a model point (data units, y up).
std::string xy(const Vec2& p) {
  char text[64];
  std::snprintf(text, sizeof text, "%.1f,%.1f", p.x(), kDataBoxTop - p.y());
  return text;
}

std::string attribute(const char* name, double value) {
  char text[64];
  std::snprintf(text, sizeof text, " %s=\"%.1f\"", name, value);
  return text;
}

// Appends "<command>x,y" for each point (GCC 12 warns falsely on "literal" + std::string temporaries).
void add(std::string& out, const char* command, const Vec2& p) {
  out += command;
  out += xy(p);
}

std::string element_path(const StrokeElement& e) {
  std::string d;
  add(d, "M", e.start());
  if (e.degree == 1) {
    add(d, " L", e.end());
  } else if (e.degree == 2) {
    add(d, " Q", e.control[1]);
    add(d, " ", e.control[2]);
  } else if (e.degree == 3) {
    add(d, " C", e.control[1]);
    add(d, " ", e.control[2]);
    add(d, " ", e.control[3]);
  } else {  // SVG has no quartic: a fine polyline along the curve
    for (int i = 1; i <= 32; ++i) add(d, " L", e.point(i / 32.0));
  }
  return d;
}

}  // namespace

std::string model_svg(const Character& character) {
  std::string svg;
  svg += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  svg +=
      "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 1024 1024\" width=\"512\" height=\"512\">\n";
  svg += "<title>Model of " + escape_markup(describe_character(character.code_point)) + "</title>\n";
  svg +=
      "<style>.median{fill:none;stroke:#ccc;stroke-width:24;stroke-linecap:round;stroke-linejoin:round}"
      ".element{fill:none;stroke:#000;stroke-width:4}"
      ".control-polygon{fill:none;stroke:#36c;stroke-width:1.5;stroke-dasharray:6 4}"
      ".control-point{fill:#fff;stroke:#36c;stroke-width:2}"
      ".feature-point{fill:#e00;stroke:none}"
      ".stroke-number{font:bold 36px sans-serif;fill:#06a}</style>\n";
  svg += "<rect x=\"0\" y=\"0\" width=\"1024\" height=\"1024\" fill=\"#fff\" stroke=\"#999\"/>\n";
  for (std::size_t s = 0; s < character.strokes.size(); ++s) {
    const Stroke& stroke = character.strokes[s];
    svg += "<g class=\"stroke\" id=\"stroke-" + std::to_string(s + 1) + "\" data-typical-id=\"" +
           std::to_string(stroke.typical_id) + "\">\n";
    if (stroke.median.size() >= 2) {
      svg += "<polyline class=\"median\" points=\"";
      for (std::size_t i = 0; i < stroke.median.size(); ++i) add(svg, i ? " " : "", stroke.median[i]);
      svg += "\"/>\n";
    }
    for (const StrokeElement& e : stroke.elements) {
      svg += "<path class=\"element\" data-kind=\"" +
             std::string(e.kind == ElementKind::line ? "line" : "bezier") + "\" d=\"" + element_path(e) +
             "\"/>\n";
      if (e.degree > 1) {
        svg += "<polyline class=\"control-polygon\" points=\"";
        for (int i = 0; i <= e.degree; ++i) add(svg, i ? " " : "", e.control[static_cast<std::size_t>(i)]);
        svg += "\"/>\n";
        for (int i = 1; i < e.degree; ++i) {
          const Vec2& c = e.control[static_cast<std::size_t>(i)];
          svg += "<circle class=\"control-point\"" + attribute("cx", c.x()) +
                 attribute("cy", kDataBoxTop - c.y()) + " r=\"6\"/>\n";
        }
      }
    }
    for (std::size_t k = 0; k < stroke.feature_point_count(); ++k) {
      const Vec2& f = stroke.feature_point(k);
      svg += "<circle class=\"feature-point\"" + attribute("cx", f.x()) +
             attribute("cy", kDataBoxTop - f.y()) + " r=\"8\"/>\n";
    }
    const Vec2& start = stroke.feature_point(0);
    svg += "<text class=\"stroke-number\"" + attribute("x", start.x() - 34.0) +
           attribute("y", kDataBoxTop - start.y() - 12.0) + ">" + std::to_string(s + 1) + "</text>\n";
    svg += "</g>\n";
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace calligraphy
