#pragma once
/// \file parameter_table.hpp
/// One table per parameter struct (the force law, each guidance law and per-repetition rule, the stroke
/// acceptance, the safety chain, passivity, the simulated writer's profile): every numeric field's name,
/// unit, range and one-line documentation, next to a pointer to the member. The table is the one
/// definition of a field's range: the struct's validation walks it, the trial specification and a study
/// protocol read their values against the same entries, and Python's documentation of the fields is read
/// from it (docs/force-rendering.md, "Parameter tables"). Defaults stay the struct's own member
/// initialisers. In `core` because structs of every layer from `model` up have one.
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <string_view>

namespace calligraphy {

/// The values a field accepts: finite and between `low` and `high`, each end closed or open. An infinite
/// `high` is unbounded above (the value must still be finite).
struct ParameterRange {
  double low = 0.0;
  double high = std::numeric_limits<double>::infinity();
  bool low_open = false;   ///< `low` itself is refused ("(low" rather than "[low")
  bool high_open = false;  ///< `high` itself is refused ("high)" rather than "high]")

  /// True when `value` is finite and within the range.
  [[nodiscard]] bool contains(double value) const noexcept;
  /// The range as the documentation and the errors write it, with the unit after each bound when one is
  /// given: ">= 0 N/m", "> 0 m", "in [0, 1]", "in (0, 0.006] m".
  [[nodiscard]] std::string text(std::string_view unit = {}) const;
};

/// The ranges most fields share: any finite value >= 0, and any finite value > 0.
inline constexpr ParameterRange kNonNegativeRange{};
inline constexpr ParameterRange kPositiveRange{.low_open = true};

/// One numeric field of parameter struct `S`.
template <typename S>
struct ParameterField {
  std::string_view name;  ///< the member's name, units in it ("constraint_radius_m")
  std::string_view unit;  ///< "N/m", "m", "s", "Hz", "N s/m"; empty when dimensionless
  ParameterRange range;   ///< the values `validate` accepts
  /// One line, what the value is, without unit or range; no colon (Python's stub generator reads
  /// "words:" at the start of a property's documentation as its type).
  std::string_view doc;
  double S::*member;  ///< where the value lives
  /// A count kept as a double (a number of misses): only whole numbers are accepted, and the schema, the
  /// JSON Schema, the options and Python give it as an integer.
  bool whole_number = false;

  /// The field's default: the struct's own member initialiser.
  [[nodiscard]] double default_value() const { return S{}.*member; }
  /// One line for documentation: the doc, the unit in brackets and the range, e.g.
  /// "R_res, radius of the constraint space [m], > 0 m".
  [[nodiscard]] std::string description() const {
    std::string out(doc);
    if (!unit.empty()) out += " [" + std::string(unit) + "]";
    return out + ", " + range.text(unit);
  }
};

/// The table of parameter struct `S`, specialised next to each struct: `name` (the struct's name in
/// errors, "FadingGuidance") and `fields()` (every numeric field, in declaration order).
template <typename S>
struct ParameterTable;

/// Throws InvalidArgument "Struct.field = value unit must be in [low, high]" (or "must be finite and
/// >= low unit" when unbounded above) unless `range` contains `value`. `qualified_name`: "Struct.field".
void check_parameter(std::string_view qualified_name, double value, std::string_view unit,
                     const ParameterRange& range);

/// Throws InvalidArgument "Struct.field = value must be a whole number" unless `value` is one.
void check_whole_parameter(std::string_view qualified_name, double value);

/// Throws InvalidArgument: `struct_name`'s table has no entry for a member it was asked about.
[[noreturn]] void throw_parameter_not_in_table(std::string_view struct_name);

/// Checks every field of `object` against its table, in table order; throws InvalidArgument naming the
/// first field out of range (check_parameter) or, for a count, not a whole number. Cross-field rules are
/// the struct's own, after this.
template <typename S>
void check_parameters(const S& object) {
  for (const ParameterField<S>& field : ParameterTable<S>::fields()) {
    const double value = object.*field.member;
    // The name is built only for an error: a profile is checked for every trial a study plans.
    if (field.range.contains(value) && (!field.whole_number || value == std::floor(value))) continue;
    const std::string name = std::string(ParameterTable<S>::name) + "." + std::string(field.name);
    check_parameter(name, value, field.unit, field.range);
    check_whole_parameter(name, value);
  }
}

/// The table entry of `member`. Throws InvalidArgument when the member has none (a programming error).
template <typename S>
[[nodiscard]] const ParameterField<S>& parameter_field(double S::*member) {
  for (const ParameterField<S>& field : ParameterTable<S>::fields()) {
    if (field.member == member) return field;
  }
  throw_parameter_not_in_table(ParameterTable<S>::name);
}

/// Checks `value` as `member`'s table entry does, naming the field "Struct.field" (a value held outside the
/// struct, e.g. the trial specification's per-mode fields).
template <typename S>
void check_parameter(double S::*member, double value) {
  const ParameterField<S>& field = parameter_field(member);
  if (field.range.contains(value)) return;
  check_parameter(std::string(ParameterTable<S>::name) + "." + std::string(field.name), value, field.unit,
                  field.range);
}

}  // namespace calligraphy
