// SVG path data (M, L, Q, C, S, Z and their relative forms) to closed polygons or open polylines
// (stroke_outline.hpp).
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/stroke_outline.hpp"

namespace calligraphy {
namespace {

class PathParser {
 public:
  PathParser(std::string_view text, double tolerance, bool closed)
      : text_(text), tolerance_(tolerance), closed_(closed) {}

  std::vector<OutlinePolygon> parse() {
    char command = 0;
    while (skip_separators(), position_ < text_.size()) {
      const char c = text_[position_];
      if (std::isalpha(static_cast<unsigned char>(c))) {
        command = c;
        ++position_;
        if (command == 'Z' || command == 'z') {
          if (!closed_ && open_) add(start_);
          close_subpath();
          continue;
        }
      } else if (command == 0) {
        fail("expected a command (M, L, Q, C, S or Z), got '" + std::string(1, c) + "'");
      } else if (command == 'Z' || command == 'z') {
        fail("a number after Z");
      }
      run(command);
      previous_ = command;
      // After a moveto, further coordinate pairs are implicit linetos (SVG 1.1, 8.3.2).
      if (command == 'M') command = 'L';
      if (command == 'm') command = 'l';
    }
    close_subpath();
    return std::move(polygons_);
  }

 private:
  void run(char command) {
    const bool relative = std::islower(static_cast<unsigned char>(command)) != 0;
    const Vec2 origin = relative ? current_ : Vec2::Zero();
    switch (command) {
      case 'M':
      case 'm': {
        const Vec2 p = origin + point();
        close_subpath();
        current_ = start_ = p;
        add(p);
        break;
      }
      case 'L':
      case 'l':
        require_subpath();
        current_ = origin + point();
        add(current_);
        break;
      case 'Q':
      case 'q': {
        require_subpath();
        const Vec2 c = origin + point();
        const Vec2 end = origin + point();
        const Vec2 p0 = current_;
        const int n = segments(0.25 * (p0 - 2.0 * c + end).norm());
        for (int i = 1; i <= n; ++i) {
          const double t = static_cast<double>(i) / n;
          add((1 - t) * (1 - t) * p0 + 2 * t * (1 - t) * c + t * t * end);
        }
        current_ = end;
        break;
      }
      case 'C':
      case 'c': {
        require_subpath();
        const Vec2 c1 = origin + point();
        const Vec2 c2 = origin + point();
        cubic(c1, c2, origin + point());
        break;
      }
      case 'S':
      case 's': {
        // The first control point is the previous cubic's second one reflected about the current point,
        // or the current point after any other command (SVG 1.1, 8.3.6).
        require_subpath();
        const bool after_cubic = previous_ == 'C' || previous_ == 'c' || previous_ == 'S' || previous_ == 's';
        const Vec2 c1 = after_cubic ? Vec2(2.0 * current_ - last_control_) : current_;
        const Vec2 c2 = origin + point();
        cubic(c1, c2, origin + point());
        break;
      }
      default:
        --position_;
        fail(std::string("unsupported path command '") + command + "' (only M, L, Q, C, S and Z)");
    }
  }

  void cubic(const Vec2& c1, const Vec2& c2, const Vec2& end) {
    const Vec2 p0 = current_;
    const double second = std::max((p0 - 2.0 * c1 + c2).norm(), (c1 - 2.0 * c2 + end).norm());
    const int n = segments(0.75 * second);
    for (int i = 1; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      const double u = 1 - t;
      add(u * u * u * p0 + 3 * u * u * t * c1 + 3 * u * t * t * c2 + t * t * t * end);
    }
    last_control_ = c2;
    current_ = end;
  }

  // Segments for a curve whose linear-interpolation error over step h = 1/n is `bound` h^2.
  int segments(double bound) const {
    const double n = std::ceil(std::sqrt(bound / tolerance_));
    return n < 1.0 ? 1 : (n > kMaxCurveSegments ? kMaxCurveSegments : static_cast<int>(n));
  }

  void require_subpath() const {
    if (!open_) fail("a drawing command before the first M");
  }

  void add(const Vec2& p) {
    if (++vertices_ > kMaxOutlineVertices) {
      fail("more than " + std::to_string(kMaxOutlineVertices) + " vertices after flattening");
    }
    if (!open_) {
      polygons_.emplace_back();
      open_ = true;
    }
    OutlinePolygon& polygon = polygons_.back();
    if (polygon.empty() || polygon.back() != p) polygon.push_back(p);
  }

  void close_subpath() {
    if (!open_) return;
    open_ = false;
    OutlinePolygon& polygon = polygons_.back();
    if (closed_) {
      if (polygon.size() > 1 && polygon.back() == polygon.front()) polygon.pop_back();
      if (polygon.size() < 3) fail("a subpath of fewer than 3 distinct vertices");
    } else if (polygon.size() < 2) {
      fail("a subpath of fewer than 2 distinct vertices");
    }
    current_ = start_;
  }

  Vec2 point() {
    const double x = number();
    const double y = number();
    return Vec2(x, y);
  }

  double number() {
    skip_separators();
    if (position_ >= text_.size()) fail("expected a number, got the end of the path");
    const char* first = text_.data() + position_;
    const char* last = text_.data() + text_.size();
    const char* begin = (*first == '+') ? first + 1 : first;  // from_chars takes no leading '+'
    double value = 0.0;
    const auto [end, error] = std::from_chars(begin, last, value);
    if (error != std::errc() || end == begin) {
      fail("expected a number, got '" + std::string(text_.substr(position_, 12)) + "'");
    }
    if (!(std::abs(value) <= kMaxDataCoordinate)) {
      fail("coordinate " + std::string(first, end) + " is outside +-1e5 data units");
    }
    position_ = static_cast<std::size_t>(end - text_.data());
    return value;
  }

  void skip_separators() {
    while (position_ < text_.size() &&
           (text_[position_] == ',' || std::isspace(static_cast<unsigned char>(text_[position_])))) {
      ++position_;
    }
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw DataError("SVG path: byte " + std::to_string(position_) + ": " + what);
  }

  std::string_view text_;
  double tolerance_;
  bool closed_;
  char previous_ = 0;
  Vec2 last_control_ = Vec2::Zero();
  std::size_t position_ = 0;
  std::size_t vertices_ = 0;
  bool open_ = false;
  Vec2 current_ = Vec2::Zero();
  Vec2 start_ = Vec2::Zero();
  std::vector<OutlinePolygon> polygons_;
};

}  // namespace

std::vector<OutlinePolygon> parse_svg_path(std::string_view path, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    throw InvalidArgument("parse_svg_path: tolerance " + shortest_decimal(tolerance) + " must be > 0");
  }
  return PathParser(path, tolerance, true).parse();
}

std::vector<std::vector<Vec2>> parse_svg_polylines(std::string_view path, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    throw InvalidArgument("parse_svg_polylines: tolerance " + shortest_decimal(tolerance) + " must be > 0");
  }
  return PathParser(path, tolerance, false).parse();
}

bool polygon_contains(const OutlinePolygon& polygon, const Vec2& point) {
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[j];
    if ((a.y() > point.y()) != (b.y() > point.y()) &&
        point.x() < (b.x() - a.x()) * (point.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace calligraphy
