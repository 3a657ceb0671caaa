#pragma once
/// \file writer_setting.hpp
/// One setting of the simulated writer's profile, as a trial specification states it: a field's name and a
/// number, typed, so that no number passes through text inside the program. The trial layer holds and
/// records settings; the simulated writer (calligraphy/sim's writer_profile.hpp) knows their names and
/// ranges and applies them.
#include <string>
#include <string_view>

namespace calligraphy {

/// One numeric field of a writer profile set to a value: what `--writer-param key=value` states.
struct WriterSetting {
  std::string key;     ///< a name of sim's `writer_parameter_names()`
  double value = 0.0;  ///< in the field's unit and range (sim's ParameterTable<WriterProfile>)
  bool operator==(const WriterSetting&) const = default;
};

/// The setting "key=value" as a command line gives it. Throws InvalidArgument naming the setting when
/// there is no '=' or the value is not a finite decimal number (the key is checked where it is applied).
[[nodiscard]] WriterSetting parse_writer_setting(std::string_view text);

/// The texts `parse_writer_setting` reads, as an ECMA-262 pattern (JSON Schema's): a key without '=', '=',
/// then a decimal number. It also matches a number beyond a double (1e999), which the parser refuses.
inline constexpr std::string_view kWriterSettingTextPattern =
    "^[^=]*=-?([0-9]+\\.?[0-9]*|\\.[0-9]+)([eE][+-]?[0-9]+)?$";

/// "key=value", the value in the shortest digits that read back to the same double: the command line's
/// form of `setting`, which `parse_writer_setting` reads back equal.
[[nodiscard]] std::string writer_setting_text(const WriterSetting& setting);

}  // namespace calligraphy
