// A SAX handler for nlohmann::json (https://json.nlohmann.me/features/parsing/sax_interface/) that keeps
// only the medians of a hanzi-writer-data document and checks the bounds of character_library.hpp as the
// values arrive. The parser itself is iterative; the handler keeps one frame per open array or object
// and refuses to open more than kMaxJsonDepth, so nothing recurses on the input and no tree is built.
#include "model/median_json_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "calligraphy/model/character_library.hpp"
#include "core/json_document.hpp"
#include "model/corpus_store_format.hpp"

namespace calligraphy::detail {
namespace {

// What a value is, from where it stands in the document.
enum class Role : std::uint8_t { root, medians, median, point, coordinate, outlines, skipped };

struct Frame {
  Role role = Role::skipped;
  bool is_array = false;
  std::size_t count = 0;       // values seen so far in an array
  std::string segment;         // this container's name in its parent (JSON pointer segment, escaped)
  std::string key;             // the key read last in an object
  std::set<std::string> keys;  // every key of an object so far: one given twice is refused, as elsewhere
};

// Keys are free text of any length; an error names at most this many bytes of one.
constexpr std::size_t kMaxKeyShown = 64;
// Parser messages quote the token read last, which can be a long string.
constexpr std::size_t kMaxParserMessage = 240;

std::string pointer_segment(std::string_view key) {
  std::string out;
  for (const char c : key.substr(0, kMaxKeyShown)) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  if (key.size() > kMaxKeyShown) out += "...";
  return out;
}

std::string shortened(std::string text, std::size_t limit) {
  if (text.size() > limit) {
    text.resize(limit);
    text += "...";
  }
  return text;
}

std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

class MediansHandler {
 public:
  using json = nlohmann::json;

  explicit MediansHandler(MedianJsonResult& result) : result_(result) {}

  bool null() { return scalar("null"); }
  bool boolean(bool /*value*/) { return scalar("a boolean"); }
  bool string(json::string_t& value) {
    // A stroke's outline path (the outline reader reads it): bounded here, where every character file is
    // read first, so that a character whose outline no store can hold is refused at the door, named, rather
    // than stop a whole corpus build when the store is written.
    if (!frames_.empty() && frames_.back().role == Role::outlines &&
        value.size() > store::kMaxOutlinePathBytes) {
      return fail(next_path(), "outline path of " + std::to_string(value.size()) + " bytes, more than " +
                                   std::to_string(store::kMaxOutlinePathBytes));
    }
    return scalar("a string");
  }
  bool binary(json::binary_t& /*value*/) { return scalar("binary data"); }
  bool number_integer(json::number_integer_t value) { return number(static_cast<double>(value)); }
  bool number_unsigned(json::number_unsigned_t value) { return number(static_cast<double>(value)); }
  bool number_float(json::number_float_t value, const json::string_t& /*text*/) { return number(value); }

  bool start_object(std::size_t /*size*/) { return open(false, "an object"); }
  bool key(json::string_t& name) {
    frames_.back().key = name;
    // Any key given twice (a reader would take one of the two without a word), ignored ones included.
    if (!frames_.back().keys.insert(name).second) return fail(next_path(), "duplicate key");
    if (frames_.back().role == Role::root && name == "medians") seen_medians_ = true;
    return true;
  }
  bool end_object() {
    if (frames_.back().role == Role::root && !seen_medians_) return fail("/medians", "missing");
    frames_.pop_back();
    return true;
  }

  bool start_array(std::size_t /*size*/) { return open(true, "an array"); }
  bool end_array() {
    const Frame& frame = frames_.back();
    switch (frame.role) {
      case Role::medians:
        if (medians_.empty()) return fail(path(), "expected a non-empty array of medians");
        break;
      case Role::median:
        if (median_.size() < 2) {
          return fail(path(),
                      "a median needs at least 2 distinct points, got " + std::to_string(median_.size()));
        }
        if (!has_two_distinct_points(median_)) {
          return fail(path(), "a median needs at least 2 distinct points, all " +
                                  std::to_string(median_.size()) + " are equal");
        }
        medians_.push_back(std::move(median_));
        median_.clear();
        break;
      case Role::outlines:  // counted only: one outline per median (the outline reader reads them)
        outline_count_ = frame.count;
        break;
      case Role::point:
        if (frame.count != 2) {
          return fail(path(), "expected a point [x, y] of two numbers, got " + std::to_string(frame.count));
        }
        median_.push_back(point_);
        break;
      default:
        break;
    }
    frames_.pop_back();
    return true;
  }

  bool parse_error(std::size_t position, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& e) {
    if (e.id == 406) {  // out_of_range.406: a number beyond double's range, such as 1e400
      return fail(next_path(), "number out of range (" +
                                   shortened(json_detail::parser_reason(e.what()), kMaxParserMessage) + ")");
    }
    if (const std::string kind = json_detail::non_json_kind(text_); !kind.empty())
      return fail("/", "not a JSON document: it is " + kind);
    return fail(
        "line:column " + line_column(position) + " (at " + next_path() + ")",
        "malformed JSON (" + shortened(json_detail::parser_reason(e.what()), kMaxParserMessage) + ")");
  }

  void finish() {
    if (!result_.where.empty()) return;
    if (outline_count_ && *outline_count_ != medians_.size()) {
      fail("/strokes", std::to_string(*outline_count_) + " stroke outlines for " +
                           std::to_string(medians_.size()) +
                           " medians: a character file has one outline per median");
      return;
    }
    result_.medians = std::move(medians_);
    result_.ok = true;
  }

  void set_text(std::string_view text) { text_ = text; }

  // JSON text never holds a NUL byte; the parser would take one for the end of its input and drop the rest.
  void nul_byte(std::size_t offset) {
    if (const std::string kind = json_detail::non_json_kind(text_); !kind.empty()) {
      fail("/", "not a JSON document: it is " + kind);
      return;
    }
    fail("line:column " + line_column(offset + 1),
         "malformed JSON (a NUL byte, which JSON text never holds)");
  }

 private:
  static bool has_two_distinct_points(const std::vector<Vec2>& median) {
    return std::any_of(median.begin(), median.end(), [&](const Vec2& p) { return p != median.front(); });
  }

  // The role of the next value, from the frame it goes into.
  [[nodiscard]] Role next_role() const {
    if (frames_.empty()) return Role::root;
    const Frame& frame = frames_.back();
    switch (frame.role) {
      case Role::root:
        if (frame.key == "strokes") return Role::outlines;
        return frame.key == "medians" ? Role::medians : Role::skipped;
      case Role::medians:
        return Role::median;
      case Role::median:
        return Role::point;
      case Role::point:
        return Role::coordinate;
      default:
        return Role::skipped;
    }
  }

  [[nodiscard]] std::string path() const {
    std::string out;
    for (const Frame& frame : frames_) {
      if (!frame.segment.empty()) out += "/" + frame.segment;
    }
    return out.empty() ? "/" : out;
  }

  // JSON pointer of the value about to be read.
  [[nodiscard]] std::string next_path() const {
    if (frames_.empty()) return "/";
    const Frame& frame = frames_.back();
    const std::string here = path();
    return (here == "/" ? "" : here) + "/" +
           (frame.is_array ? std::to_string(frame.count) : pointer_segment(frame.key));
  }

  [[nodiscard]] std::string line_column(std::size_t byte) const {
    std::size_t line = 1;
    std::size_t column = 1;
    const std::size_t end = std::min(byte > 0 ? byte - 1 : 0, text_.size());
    for (std::size_t i = 0; i < end; ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    return std::to_string(line) + ":" + std::to_string(column);
  }

  bool fail(std::string where, std::string what) {
    if (result_.where.empty()) {  // the first error is the one to report
      result_.where = std::move(where);
      result_.what = std::move(what);
    }
    return false;
  }

  // Checks a value of any kind against the role of its position; counts it in its array.
  bool arrive(const char* kind, bool is_array, bool is_number) {
    const Role role = next_role();
    switch (role) {
      case Role::root:
        if (kind != std::string_view("an object"))
          return fail("/", std::string("expected a JSON object, got ") + kind);
        break;
      case Role::medians:
        if (!is_array)
          return fail(next_path(), std::string("expected a non-empty array of medians, got ") + kind);
        break;
      case Role::median:
        if (!is_array)
          return fail(next_path(), std::string("expected a median (an array of points), got ") + kind);
        if (frames_.back().count >= kMaxCharacterStrokes) {
          return fail(next_path(), "more than " + std::to_string(kMaxCharacterStrokes) + " medians");
        }
        break;
      case Role::point:
        if (!is_array)
          return fail(next_path(), std::string("expected a point [x, y] of two numbers, got ") + kind);
        if (frames_.back().count >= kMaxMedianPoints) {
          return fail(next_path(), "more than " + std::to_string(kMaxMedianPoints) + " points in one median");
        }
        if (points_ >= kMaxCharacterPoints) {
          return fail(next_path(),
                      "more than " + std::to_string(kMaxCharacterPoints) + " points in all medians");
        }
        ++points_;
        break;
      case Role::coordinate:
        if (!is_number) return fail(next_path(), std::string("expected a number, got ") + kind);
        if (frames_.back().count >= 2)
          return fail(next_path(), "expected a point [x, y] of two numbers, got more");
        break;
      case Role::outlines:
      case Role::skipped:
        break;
    }
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().count;
    return true;
  }

  bool scalar(const char* kind) { return arrive(kind, false, false); }

  bool number(double value) {
    if (next_role() == Role::coordinate) {
      const std::string where = next_path();
      if (!(std::abs(value) <= kMaxDataCoordinate)) {
        return fail(where, "coordinate " + format_number(value) + " is outside +-" +
                               format_number(kMaxDataCoordinate) + " data units");
      }
      point_[static_cast<Eigen::Index>(std::min<std::size_t>(frames_.back().count, 1))] = value;
    }
    return arrive("a number", false, true);
  }

  bool open(bool is_array, const char* kind) {
    if (frames_.size() >= kMaxJsonDepth) {
      return fail(next_path(), "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    }
    const Role role = next_role();
    std::string segment;
    if (!frames_.empty()) {
      const Frame& parent = frames_.back();
      segment = parent.is_array ? std::to_string(parent.count) : pointer_segment(parent.key);
    }
    if (!arrive(kind, is_array, false)) return false;
    Frame frame;
    frame.role = role;
    frame.is_array = is_array;
    frame.segment = std::move(segment);
    frames_.push_back(std::move(frame));
    return true;
  }

  MedianJsonResult& result_;
  std::string_view text_;
  std::vector<Frame> frames_;
  bool seen_medians_ = false;
  std::optional<std::size_t> outline_count_;  // the root's "strokes" array, when it has one
  std::size_t points_ = 0;                    // in all medians so far
  std::vector<std::vector<Vec2>> medians_;
  std::vector<Vec2> median_;
  Vec2 point_ = Vec2::Zero();
};

}  // namespace

MedianJsonResult read_medians_json(std::string_view json) {
  MedianJsonResult result;
  MediansHandler handler(result);
  handler.set_text(json);
  if (const std::size_t nul = json.find('\0'); nul != std::string_view::npos) {
    handler.nul_byte(nul);
    return result;
  }
  const bool parsed = nlohmann::json::sax_parse(json.begin(), json.end(), &handler);
  if (parsed) {
    handler.finish();
  } else if (result.where.empty()) {
    result.where = "/";
    result.what = "the JSON parser stopped without naming an error";
  }
  return result;
}

}  // namespace calligraphy::detail
