#include "calligraphy/core/parameter_table.hpp"

#include <cmath>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {
namespace {

std::string with_unit(const std::string& number, std::string_view unit) {
  return unit.empty() ? number : number + " " + std::string(unit);
}

// A bound as people write it: whole numbers in digits (100000, not 1e+05), others in their shortest form.
std::string bound_text(double value) {
  if (std::abs(value) < 1e15 && value == std::trunc(value))
    return std::to_string(static_cast<long long>(value));
  return shortest_decimal(value);
}

}  // namespace

bool ParameterRange::contains(double value) const noexcept {
  if (!std::isfinite(value)) return false;
  const bool above_low = low_open ? value > low : value >= low;
  const bool below_high = high_open ? value < high : value <= high;
  return above_low && below_high;
}

std::string ParameterRange::text(std::string_view unit) const {
  if (std::isinf(high)) return with_unit((low_open ? "> " : ">= ") + bound_text(low), unit);
  return with_unit(std::string("in ") + (low_open ? "(" : "[") + bound_text(low) + ", " + bound_text(high) +
                       (high_open ? ")" : "]"),
                   unit);
}

void check_parameter(std::string_view qualified_name, double value, std::string_view unit,
                     const ParameterRange& range) {
  if (range.contains(value)) return;
  throw InvalidArgument(std::string(qualified_name) + " = " + with_unit(shortest_decimal(value), unit) +
                        " must be " + (std::isinf(range.high) ? "finite and " : "") + range.text(unit));
}

void check_whole_parameter(std::string_view qualified_name, double value) {
  if (value == std::floor(value)) return;
  throw InvalidArgument(std::string(qualified_name) + " = " + shortest_decimal(value) +
                        " must be a whole number");
}

void throw_parameter_not_in_table(std::string_view struct_name) {
  throw InvalidArgument(std::string(struct_name) + ": no table entry for this member");
}

}  // namespace calligraphy
