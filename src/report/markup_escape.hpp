#pragma once
// Text put into HTML or SVG (an XML document) as character data or an attribute's value: the five characters
// markup gives a meaning to, each written as its reference, so that a name (a character `<`, a condition, a
// subject, a title) shows as text and never becomes markup. One escape for every page and figure.
#include <string>
#include <string_view>

namespace calligraphy {

/// `text` with `&`, `<`, `>`, `"` and `'` written as `&amp;`, `&lt;`, `&gt;`, `&quot;` and `&#39;` (valid
/// in HTML and XML alike); every other byte as it is.
inline std::string escape_markup(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace calligraphy
