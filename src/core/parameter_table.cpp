#include "calligraphy/core/parameter_table.hpp"

#include <charconv>
#include <cmath>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

// The shortest text that reads back as the same double, so that a value just outside a bound does not
// print as the bound itself.
std::string number_text(double value) {
  char text[32];
  const auto [end, error] = std::to_chars(text, text + sizeof text, value);
  return error == std::errc() ? std::string(text, end) : std::string("?");
}

std::string with_unit(const std::string& number, std::string_view unit) {
  return unit.empty() ? number : number + " " + std::string(unit);
}

}  // namespace

bool ParameterRange::contains(double value) const noexcept {
  if (!std::isfinite(value)) return false;
  const bool above_low = low_open ? value > low : value >= low;
  const bool below_high = high_open ? value < high : value <= high;
  return above_low && below_high;
}

std::string ParameterRange::text(std::string_view unit) const {
  if (std::isinf(high)) return with_unit((low_open ? "> " : ">= ") + number_text(low), unit);
  return with_unit(std::string("in ") + (low_open ? "(" : "[") + number_text(low) + ", " + number_text(high) +
                       (high_open ? ")" : "]"),
                   unit);
}

void check_parameter(std::string_view qualified_name, double value, std::string_view unit,
                     const ParameterRange& range) {
  if (range.contains(value)) return;
  throw InvalidArgument(std::string(qualified_name) + " = " + with_unit(number_text(value), unit) +
                        " must be " + (std::isinf(range.high) ? "finite and " : "") + range.text(unit));
}

void throw_parameter_not_in_table(std::string_view struct_name) {
  throw InvalidArgument(std::string(struct_name) + ": no table entry for this member");
}

}  // namespace calligraphy
