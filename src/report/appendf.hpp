#pragma once
// printf-style formatting appended to a string, for reports built as text (and then written, checked, by
// the caller) rather than printed piecemeal.
#include <cstdarg>
#include <cstdio>
#include <string>

namespace calligraphy {

/// Appends snprintf(pattern, values...) to `out`, whatever its length. A C variadic function, so that the
/// compiler checks every call's values against its pattern (the format attribute).
[[gnu::format(printf, 2, 3)]] inline void appendf(std::string& out, const char* pattern, ...) {
  std::va_list values;
  va_start(values, pattern);
  std::va_list again;
  va_copy(again, values);
  const int length = std::vsnprintf(nullptr, 0, pattern, values);
  va_end(values);
  if (length > 0) {
    const std::size_t old_size = out.size();
    out.resize(old_size + static_cast<std::size_t>(length) + 1);
    std::vsnprintf(out.data() + old_size, static_cast<std::size_t>(length) + 1, pattern, again);
    out.resize(old_size + static_cast<std::size_t>(length));
  }
  va_end(again);
}

}  // namespace calligraphy
