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

void throw_int_out_of_range(const std::string& name, py::handle value, bool is_signed, int digits) {
  // Python computes the bounds: digits may be 64, past what a long long holds.
  const py::int_ two(2);
  const py::object top = two.attr("__pow__")(digits);
  const py::object max = top - py::int_(1);
  const py::object min = is_signed ? py::object(py::int_(0) - top) : py::object(py::int_(0));
  const std::string power = "2**" + std::to_string(digits);
  const std::string range = std::string(py::str(min)) + ".." + std::string(py::str(max)) + " (" +
                            (is_signed ? "-" + power : std::string("0")) + ".." + power + "-1)";
  throw InvalidArgument(name + ": " + short_repr(value) + " is out of range: expected an int in " + range);
}

}  // namespace calligraphy::python
