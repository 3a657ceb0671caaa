#pragma once
// printf-style formatting appended to a string, for reports built as text (and then written, checked, by
// the caller) rather than printed piecemeal.
#include <cstdio>
#include <string>

namespace calligraphy {

/// Appends snprintf(pattern, values...) to `out`, whatever its length.
template <typename... Values>
void appendf(std::string& out, const char* pattern, Values... values) {
  const int length = std::snprintf(nullptr, 0, pattern, values...);
  if (length <= 0) return;
  const std::size_t old_size = out.size();
  out.resize(old_size + static_cast<std::size_t>(length) + 1);
  std::snprintf(out.data() + old_size, static_cast<std::size_t>(length) + 1, pattern, values...);
  out.resize(old_size + static_cast<std::size_t>(length));
}

}  // namespace calligraphy
