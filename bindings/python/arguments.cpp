#include "arguments.hpp"

namespace calligraphy::python {

std::string short_repr(py::handle value) {
  std::string text = py::repr(value);
  constexpr std::size_t kMax = 60;
  if (text.size() > kMax) text = text.substr(0, kMax - 3) + "...";
  return text;
}

void throw_type_error(const std::string& name, const std::string& expected, py::handle value) {
  const std::string type = py::str(py::type::handle_of(value).attr("__name__"));
  throw py::type_error(name + ": expected " + expected + ", got " + type + " " + short_repr(value));
}

}  // namespace calligraphy::python
