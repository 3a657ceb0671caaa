#pragma once
/// \file json_text.hpp
/// A JSON document (any nlohmann::basic_json; this header does not include nlohmann-json) as text, whatever
/// bytes its strings hold: JSON text is UTF-8, so a string that is not (a file or folder named in Latin-1 on
/// a Linux file system) is written with each byte that is not part of valid UTF-8 as the text `\xHH`, as
/// error messages write it (printable_text.hpp), instead of failing the write. Valid UTF-8 is written as it
/// is.
#include <string>

#include "calligraphy/core/printable_text.hpp"

namespace calligraphy {

namespace json_text_detail {

/// A copy of `value` with every string and key made valid UTF-8 (valid_utf8_text).
template <class Json>
Json with_valid_utf8(const Json& value) {
  if (value.is_string())
    return Json(valid_utf8_text(value.template get_ref<const typename Json::string_t&>()));
  if (value.is_array()) {
    Json out = Json::array();
    for (const Json& item : value) out.push_back(with_valid_utf8(item));
    return out;
  }
  if (value.is_object()) {
    Json out = Json::object();
    for (auto item = value.begin(); item != value.end(); ++item)
      out[valid_utf8_text(item.key())] = with_valid_utf8(item.value());
    return out;
  }
  return value;
}

}  // namespace json_text_detail

/// `document.dump(indent)` (-1: one line); strings that are not valid UTF-8 as described above. Throws only
/// std::bad_alloc.
template <class Json>
std::string json_text(const Json& document, int indent = -1) {
  try {
    return document.dump(indent);
  } catch (const typename Json::type_error& error) {
    constexpr int kInvalidUtf8 = 316;  // nlohmann-json's type_error.316: a string that is not UTF-8
    if (error.id != kInvalidUtf8) throw;
  }
  return json_text_detail::with_valid_utf8(document).dump(indent);
}

}  // namespace calligraphy
