#include "core/json_document.hpp"

#include <functional>
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

}  // namespace

nlohmann::json parse_json_document(std::string_view text, const std::string& source) {
  // The plain parser first: linear in the text. A parser with a callback is not (nlohmann/json 3.11's
  // callback parser scans an object's parent for a discarded value at every object's end, so an array of n
  // objects, a session plan, takes n^2 steps); it runs only to name where a document that failed fails.
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::exception&) {
    // Parsed again below, with the pointer tracked, for the error's words.
  }
  PointerTracker tracker;
  try {
    return nlohmann::json::parse(text.begin(), text.end(), std::ref(tracker));
  } catch (const nlohmann::json::parse_error& e) {
    throw DataError(source + ": not valid JSON at byte " + std::to_string(e.byte) + ": " + e.what());
  } catch (const nlohmann::json::exception& e) {
    // A number beyond a double's range (1e999): the parser's only error without a byte offset.
    const std::string pointer = tracker.pointer();
    std::string reason = e.what();  // "[json.exception.out_of_range.406] number overflow parsing '1e999'"
    if (const std::size_t bracket = reason.find("] "); bracket != std::string::npos)
      reason.erase(0, bracket + 2);
    throw DataError(source + ": " + (pointer.empty() ? "/" : pointer) +
                    ": not a finite number (beyond the range of a double): " + reason);
  }
}

}  // namespace calligraphy::json_detail
