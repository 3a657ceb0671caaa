// A SAX handler for nlohmann::json (https://json.nlohmann.me/features/parsing/sax_interface/) that keeps
// only the `strokes` array of a hanzi-writer-data document, refusing more than kMaxJsonDepth levels of
// nesting, so nothing recurses on the input and no tree is built.
#include "model/outline_json_reader.hpp"

#include <nlohmann/json.hpp>

#include "calligraphy/model/character_library.hpp"

namespace calligraphy::detail {
namespace {

class OutlinesHandler {
 public:
  using json = nlohmann::json;

  explicit OutlinesHandler(OutlineJsonResult& result) : result_(result) {}

  bool null() { return value("null"); }
  bool boolean(bool /*value*/) { return value("a boolean"); }
  bool number_integer(json::number_integer_t /*value*/) { return value("a number"); }
  bool number_unsigned(json::number_unsigned_t /*value*/) { return value("a number"); }
  bool number_float(json::number_float_t /*value*/, const json::string_t& /*text*/) {
    return value("a number");
  }
  bool binary(json::binary_t& /*value*/) { return value("binary data"); }
  bool string(json::string_t& text) {
    if (in_strokes()) {
      if (paths_.size() >= kMaxCharacterStrokes) {
        return fail("/strokes/" + std::to_string(paths_.size()),
                    "more than " + std::to_string(kMaxCharacterStrokes) + " strokes");
      }
      paths_.push_back(std::move(text));
      return true;
    }
    return value("a string");
  }

  bool start_object(std::size_t /*size*/) { return open(false); }
  bool key(json::string_t& name) {
    if (depth_ == 1) {
      root_key_ = name;
      if (name == "strokes") {
        if (seen_strokes_) return fail("/strokes", "duplicate key");
        seen_strokes_ = true;
      }
    }
    return true;
  }
  bool end_object() {
    if (depth_ == 1 && !seen_strokes_) return fail("/strokes", "missing (no stroke outlines in this file)");
    --depth_;
    return true;
  }
  bool start_array(std::size_t /*size*/) { return open(true); }
  bool end_array() {
    if (depth_ == 2 && strokes_open_) {
      strokes_open_ = false;
      if (paths_.empty()) return fail("/strokes", "expected a non-empty array of SVG paths");
    }
    --depth_;
    return true;
  }

  bool parse_error(std::size_t position, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& /*e*/) {
    return fail("byte " + std::to_string(position), "malformed JSON");
  }

  void finish() {
    if (!result_.where.empty()) return;
    result_.paths = std::move(paths_);
    result_.ok = true;
  }

 private:
  [[nodiscard]] bool in_strokes() const { return strokes_open_ && depth_ == 2; }

  bool value(const char* kind) {
    if (depth_ == 0) return fail("/", std::string("expected a JSON object, got ") + kind);
    if (depth_ == 1 && root_key_ == "strokes") {
      return fail("/strokes", std::string("expected an array of SVG paths, got ") + kind);
    }
    if (in_strokes()) {
      return fail("/strokes/" + std::to_string(paths_.size()),
                  std::string("expected an SVG path, got ") + kind);
    }
    return true;
  }

  bool open(bool is_array) {
    if (depth_ >= kMaxJsonDepth)
      return fail("/", "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    if (depth_ == 0 && is_array) return fail("/", "expected a JSON object, got an array");
    if (depth_ == 1 && root_key_ == "strokes") {
      if (!is_array) return fail("/strokes", "expected an array of SVG paths, got an object");
      strokes_open_ = true;
    } else if (in_strokes()) {
      return fail("/strokes/" + std::to_string(paths_.size()),
                  std::string("expected an SVG path, got ") + (is_array ? "an array" : "an object"));
    }
    ++depth_;
    return true;
  }

  bool fail(std::string where, std::string what) {
    if (result_.where.empty()) {
      result_.where = std::move(where);
      result_.what = std::move(what);
    }
    return false;
  }

  OutlineJsonResult& result_;
  std::size_t depth_ = 0;
  std::string root_key_;
  bool seen_strokes_ = false;
  bool strokes_open_ = false;
  std::vector<std::string> paths_;
};

}  // namespace

OutlineJsonResult read_outlines_json(std::string_view json) {
  OutlineJsonResult result;
  OutlinesHandler handler(result);
  // JSON text never holds a NUL byte; the parser would take one for the end of its input and drop the rest.
  if (const std::size_t nul = json.find('\0'); nul != std::string_view::npos) {
    result.where = "byte " + std::to_string(nul + 1);
    result.what = "malformed JSON (a NUL byte, which JSON text never holds)";
    return result;
  }
  if (nlohmann::json::sax_parse(json.begin(), json.end(), &handler)) {
    handler.finish();
  } else if (result.where.empty()) {
    result.where = "/";
    result.what = "the JSON parser stopped without naming an error";
  }
  return result;
}

}  // namespace calligraphy::detail
