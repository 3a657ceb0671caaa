#include "core/json_document.hpp"

#include <algorithm>
#include <cctype>
#include <functional>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "core/json_reader.hpp"

namespace calligraphy::json_detail {
namespace {

// Where the parser is, as a JSON pointer, for errors the parser reports without a position (a number
// that overflows a double): one frame per open object (its last key) or array (elements finished).
class PointerTracker {
 public:
  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
        frames_.push_back({false, 0, {}});
        break;
      case Event::array_start:
        frames_.push_back({true, 0, {}});
        break;
      case Event::key:
        if (!frames_.empty() && parsed.is_string()) frames_.back().key = parsed.get_ref<const std::string&>();
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_.empty()) frames_.pop_back();
        finished_element();
        break;
      case Event::value:
        finished_element();
        break;
    }
    return true;
  }

  [[nodiscard]] std::string pointer() const {
    std::string at;
    for (const Frame& frame : frames_) {
      at = frame.array ? child_pointer(at, frame.elements) : child_pointer(at, frame.key);
    }
    return at;
  }

 private:
  struct Frame {
    bool array;
    std::size_t elements;
    std::string key;
  };
  void finished_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().elements;
  }
  std::vector<Frame> frames_;
};

// Refuses a key given twice in one object: nlohmann/json keeps the last and drops the other without a word,
// so `{"seed": 1, "seed": 2}` would run a trial, or read a session, other than the one its reader sees first
// (RFC 8259, section 4: "The names within an object SHOULD be unique"; software differs on which it takes).
// A SAX pass over a document already parsed: linear in the text, and it builds nothing.
class DuplicateKeys : public nlohmann::json_sax<nlohmann::json> {
 public:
  bool null() override { return value(); }
  bool boolean(bool /*val*/) override { return value(); }
  bool number_integer(number_integer_t /*val*/) override { return value(); }
  bool number_unsigned(number_unsigned_t /*val*/) override { return value(); }
  bool number_float(number_float_t /*val*/, const string_t& /*s*/) override { return value(); }
  bool string(string_t& /*val*/) override { return value(); }
  bool binary(binary_t& /*val*/) override { return value(); }
  bool start_object(std::size_t /*elements*/) override {
    frames_.push_back({false, 0, {}, {}});
    return true;
  }
  bool key(string_t& val) override {
    Frame& frame = frames_.back();
    frame.key = val;
    if (!frame.keys.insert(val).second) {
      duplicate_ = pointer();
      return false;
    }
    return true;
  }
  bool end_object() override { return end(); }
  bool start_array(std::size_t /*elements*/) override {
    frames_.push_back({true, 0, {}, {}});
    return true;
  }
  bool end_array() override { return end(); }
  bool parse_error(std::size_t /*position*/, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& /*ex*/) override {
    return false;
  }

  /// The pointer of the first key given twice; nullopt when every key is given once.
  [[nodiscard]] const std::optional<std::string>& duplicate() const { return duplicate_; }

 private:
  struct Frame {
    bool array;
    std::size_t elements;
    std::string key;
    std::unordered_set<std::string> keys;
  };
  bool value() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().elements;
    return true;
  }
  bool end() {
    frames_.pop_back();
    return value();
  }
  [[nodiscard]] std::string pointer() const {
    std::string at;
    for (const Frame& frame : frames_) {
      at = frame.array ? child_pointer(at, frame.elements) : child_pointer(at, frame.key);
    }
    return at;
  }
  std::vector<Frame> frames_;
  std::optional<std::string> duplicate_;
};

}  // namespace

std::string non_json_kind(std::string_view text) {
  const auto starts = [&text](std::string_view prefix) { return text.substr(0, prefix.size()) == prefix; };
  // The binary kinds by their signatures: the trace file (report/trace_hdf5.cpp), gzip (RFC 1952), the
  // corpus store (model/corpus_store_format.hpp) and HDF5 (its format specification, "Superblock").
  if (starts("calligraphy-trace\n")) return "a calligraphy trace file (a session's .trace.h5)";
  if (starts("\x1f\x8b")) return "gzip-compressed data";
  if (starts("CLGSTORE")) return "a corpus store (corpus build)";
  if (starts("\x89HDF\r\n\x1a\n")) return "an HDF5 file";
  if (text.empty()) return "empty (0 bytes)";  // "at byte 1" would name a byte it does not have
  std::string_view rest = text;
  if (rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // a UTF-8 byte-order mark
  const std::size_t first = rest.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  rest.remove_prefix(first);
  for (const char c : rest.substr(0, 64)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 && c != '\t' && c != '\r' && c != '\n') return "binary data";
  }
  if (rest.front() == '<') return "markup (an SVG drawing, an HTML page or XML)";
  std::string_view line = rest.substr(0, rest.find('\n'));
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  // A CSV header starts with a column's name (a letter, a digit, '_' or a quoted name) and has a comma: not a
  // comment ("// a, b") or a stray character before a JSON object.
  const auto first_char = static_cast<unsigned char>(rest.front());
  const bool csv_line = rest.front() == '"'
                            ? line.find("\",\"") != std::string_view::npos
                            : (std::isalnum(first_char) != 0 || rest.front() == '_' || first_char >= 0x80) &&
                                  line.find(',') != std::string_view::npos;
  if (csv_line) {
    constexpr std::size_t kShown = 60;
    std::size_t cut = std::min(line.size(), kShown);
    while (cut < line.size() && cut > 0 && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) --cut;
    return "CSV text (its first line: " + std::string(line.substr(0, cut)) +
           (cut < line.size() ? "...)" : ")");
  }
  return {};
}

std::string parser_reason(const std::string& what) {
  std::string reason = what;
  if (reason.starts_with("[json.exception.")) {
    if (const std::size_t bracket = reason.find("] "); bracket != std::string::npos)
      reason.erase(0, bracket + 2);
  }
  // "parse error at line 1, column 2: syntax error ...": the position is the reader's to state.
  if (reason.starts_with("parse error")) {
    if (const std::size_t colon = reason.find(": "); colon != std::string::npos) reason.erase(0, colon + 2);
  }
  return reason;
}

nlohmann::json parse_json_document(std::string_view text, const std::string& source) {
  // The plain parser first: linear in the text. A parser with a callback is not (nlohmann/json 3.11's
  // callback parser scans an object's parent for a discarded value at every object's end, so an array of n
  // objects, a session plan, takes n^2 steps); it runs only to name where a document that failed fails.
  // JSON text never holds a NUL byte; the parser would take one for the end of its input and drop the rest.
  // A file of another kind (gzip, a trace, a store) holds some: it is named for what it is.
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    if (const std::string kind = non_json_kind(text); !kind.empty())
      throw DataError(source + ": not a JSON document: it is " + kind);
    throw DataError(source + ": not valid JSON at byte " + std::to_string(nul + 1) +
                    ": a NUL byte, which JSON text never holds");
  }
  try {
    nlohmann::json document = nlohmann::json::parse(text.begin(), text.end());
    DuplicateKeys keys;
    (void)nlohmann::json::sax_parse(text.begin(), text.end(), &keys);
    if (const std::optional<std::string>& at = keys.duplicate()) {
      throw DataError(source + ": " + *at +
                      ": the key is given twice in its object (a reader would take one " +
                      "and silently drop the other)");
    }
    return document;
  } catch (const nlohmann::json::exception&) {
    // Parsed again below, with the pointer tracked, for the error's words.
  }
  PointerTracker tracker;
  try {
    return nlohmann::json::parse(text.begin(), text.end(), std::ref(tracker));
  } catch (const nlohmann::json::parse_error& e) {
    if (const std::string kind = non_json_kind(text); !kind.empty())
      throw DataError(source + ": not a JSON document: it is " + kind);
    throw DataError(source + ": not valid JSON at byte " + std::to_string(e.byte) + ": " +
                    parser_reason(e.what()));
  } catch (const nlohmann::json::exception& e) {
    // A number beyond a double's range (1e999): the parser's only error without a byte offset.
    const std::string pointer = tracker.pointer();
    // "[json.exception.out_of_range.406] number overflow parsing '1e999'"
    const std::string reason = parser_reason(e.what());
    const std::size_t open = reason.find('\'');
    const std::size_t close = open == std::string::npos ? open : reason.find('\'', open + 1);
    const std::string literal =
        close == std::string::npos ? std::string() : reason.substr(open + 1, close - open - 1);
    throw NumberOverflow(source + ": " + (pointer.empty() ? "/" : pointer) +
                             ": not a finite number (beyond the range of a double): " + reason,
                         pointer.empty() ? "/" : pointer, literal);
  }
}

}  // namespace calligraphy::json_detail
