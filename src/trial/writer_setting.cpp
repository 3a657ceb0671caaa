#include "calligraphy/trial/writer_setting.hpp"

#include <optional>

#include "calligraphy/core/decimal_number.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy {

WriterSetting parse_writer_setting(std::string_view text) {
  const std::size_t equals = text.find('=');
  if (equals == std::string_view::npos) {
    throw InvalidArgument("writer setting '" + std::string(text) + "' must be key=value");
  }
  const std::string_view number = text.substr(equals + 1);
  const std::optional<double> value = parse_finite_double(number);
  if (!value) {
    throw InvalidArgument("writer setting '" + std::string(text) + "': '" + std::string(number) +
                          "' is not a number (a finite decimal within the range of a double is expected)");
  }
  return WriterSetting{std::string(text.substr(0, equals)), *value};
}

std::string writer_setting_text(const WriterSetting& setting) {
  return setting.key + "=" + shortest_decimal(setting.value);
}

}  // namespace calligraphy
