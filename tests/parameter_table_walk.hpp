#pragma once
// Walks a parameter table through the function that takes its struct: for each entry the default lies in
// its range, and a value just outside each bound (and NaN and the infinities) makes `use` throw
// InvalidArgument naming "Struct.field = ". For the option structs that have no validate() of their own.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/parameter_table.hpp"

template <typename S, typename Use>
void check_table_through(Use use) {
  using calligraphy::ParameterField;
  using calligraphy::ParameterTable;
  CHECK_NOTHROW(use(S{}));
  REQUIRE(!ParameterTable<S>::fields().empty());
  for (const ParameterField<S>& field : ParameterTable<S>::fields()) {
    const std::string qualified = std::string(ParameterTable<S>::name) + "." + std::string(field.name);
    INFO(qualified);
    CHECK(!field.doc.empty());
    CHECK(field.doc.find(':') == std::string_view::npos);
    CHECK(field.range.contains(field.default_value()));
    std::vector<double> outside{std::numeric_limits<double>::quiet_NaN(), INFINITY, -INFINITY};
    outside.push_back(field.range.low_open ? field.range.low : std::nextafter(field.range.low, -INFINITY));
    if (std::isfinite(field.range.high))
      outside.push_back(field.range.high_open ? field.range.high
                                              : std::nextafter(field.range.high, INFINITY));
    for (const double value : outside) {
      INFO(value);
      S object{};
      object.*field.member = value;
      CHECK_THROWS_AS(use(object), calligraphy::InvalidArgument);
      CHECK_THROWS_WITH(use(object), Catch::Contains(qualified + " = "));
    }
  }
}
