#pragma once
// Argument conversion for the bindings: Python values of the wrong type raise TypeError (out-of-range
// integers and unknown enum names InvalidArgument, a ValueError) naming the argument, instead of pybind11's
// "incompatible function arguments" or "Unable to cast Python instance to C++ type".
//
// `PyArgument<T>` accepts any Python object at call time and shows T's Python type in signatures and
// stubs ("rate_hz: float = 1000.0"); `take(arg, "rate_hz")` converts it. `Annotated<Tag>` takes any object
// for arguments of several types (ArrayLike: numpy-convertible, shown as numpy.typing.ArrayLike).
#include <pybind11/pybind11.h>

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"

namespace calligraphy::python {

namespace py = pybind11;

/// An argument converted to T in the function body by `take`, so that errors can name it.
template <typename T>
struct PyArgument {
  py::object object;
};

/// Any Python object, shown in signatures and stubs as `Tag::name` (a pybind11 const_name): for
/// arguments that take several types, converted in the function body.
template <typename Tag>
struct Annotated {
  py::object object;
};

struct ArrayLikeTag {
  static constexpr auto name = py::detail::const_name("numpy.typing.ArrayLike");
};
/// An array-like argument (list, tuple, numpy array); shapes are checked where it is used.
using ArrayLike = Annotated<ArrayLikeTag>;

struct ElementLikeTag {
  static constexpr auto name = py::detail::const_name("Union[StrokeElement, numpy.typing.ArrayLike]");
};
/// A stroke element: a StrokeElement or its control points (n, 2).
using ElementLike = Annotated<ElementLikeTag>;

struct PathTag {
  static constexpr auto name = py::detail::const_name("Union[str, os.PathLike]");
};
/// A file or folder: a str or a path-like object, converted with convert_named<std::filesystem::path>.
using PathLike = Annotated<PathTag>;

struct CharactersTag {
  static constexpr auto name = py::detail::const_name("Union[str, Character, Sequence[Character]]");
};
/// Characters: a str of one or more, a Character or a sequence of Characters.
using CharactersLike = Annotated<CharactersTag>;

struct ComparisonTag {
  static constexpr auto name = py::detail::const_name("bool");
};
/// The result of __eq__ / __ne__: a bool, or NotImplemented for another type (shown as bool).
using Comparison = Annotated<ComparisonTag>;

/// `repr(value)`, shortened to at most 60 characters, for messages.
std::string short_repr(py::handle value);

/// TypeError "<name>: expected <expected>, got <type> <repr>".
[[noreturn]] void throw_type_error(const std::string& name, const std::string& expected, py::handle value);

/// InvalidArgument "<name>: <value> is out of range: expected an int in <range>", the range of an integer
/// of `digits` value bits, signed or not; the bounds are also written as powers of two.
[[noreturn]] void throw_int_out_of_range(const std::string& name, py::handle value, bool is_signed,
                                         int digits);

/// The Python name of T: "float", "int", "str", "bool", or a bound class's name.
template <typename T>
std::string python_type_name() {
  if constexpr (std::is_base_of_v<py::detail::type_caster_generic, py::detail::make_caster<T>>) {
    return py::str(py::type::of<T>().attr("__name__"));
  } else {
    return py::detail::make_caster<T>::name.text;
  }
}

/// InvalidArgument (a ValueError) "<name>: <value> is out of range: expected an int in <min>..<max>",
/// the range of T ("0..2**64-1" for std::uint64_t).
template <typename T>
[[noreturn]] void throw_out_of_range(const std::string& name, py::handle value) {
  throw_int_out_of_range(name, value, std::numeric_limits<T>::is_signed,
                         static_cast<int>(std::numeric_limits<T>::digits));
}

/// Converts `value` to T, naming `name` in the TypeError (or, for an int out of T's range, ValueError).
/// Numbers: int or float (not bool) for double, int for integers; an enum takes a member or its name;
/// None is refused for every T.
/// Whether enumeration T has an EnumTable (calligraphy/core/schema.hpp): one spelling per value.
template <typename T>
inline constexpr bool kHasEnumTable = requires {
  EnumTable<T>::entries;
};

template <typename T>
T convert_named(py::handle value, const std::string& name) {
  if (value.is_none()) throw_type_error(name, python_type_name<T>(), value);
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
    if (PyBool_Check(value.ptr())) throw_type_error(name, python_type_name<T>(), value);
  }
  if constexpr (std::is_enum_v<T>) {
    // An enum also takes its one spelling, as the command line, the files and the library's own output write
    // it ("assist-as-needed": EnumTable), or else its member's name: "newton" for NearestPointMethod.newton.
    if (py::isinstance<py::str>(value)) {
      if constexpr (kHasEnumTable<T>) {
        if (const std::optional<T> spelled = enum_from_spelling<T>(std::string(py::str(value))))
          return *spelled;
      }
      const py::dict members = py::type::of<T>().attr("__members__");
      if (!members.contains(value)) {
        std::string known;
        if constexpr (kHasEnumTable<T>) {
          known = join_spellings(enum_spellings<T>(), ", ", "'");
        } else {
          for (const auto& item : members)
            known += (known.empty() ? "'" : ", '") + std::string(py::str(item.first)) + "'";
        }
        throw InvalidArgument(name + ": expected one of " + known + ", got " + short_repr(value));
      }
      if constexpr (kHasEnumTable<T>) {
        // A member's name that is not the spelling ("assist_as_needed"): read for one version, with a note.
        const std::string old_name = py::str(value);
        const std::string spelling(enum_spelling(members[value].template cast<T>()));
        const std::string note = name + ": '" + old_name + "' is spelled '" + spelling +
                                 "' (the old spelling is read for one more version)";
        if (PyErr_WarnEx(PyExc_DeprecationWarning, note.c_str(), 1) != 0) throw py::error_already_set();
      }
      return members[value].template cast<T>();
    }
  }
  if constexpr (std::is_same_v<T, std::filesystem::path>) {
    // A path-like object: its own __fspath__, whose exception (if it raises) is the caller's to see, never
    // read as a file name refused.
    if (!PyUnicode_Check(value.ptr()) && !PyBytes_Check(value.ptr()) && py::hasattr(value, "__fspath__"))
      return convert_named<T>(py::module_::import("os").attr("fspath")(value), name);
    // A bytes path as open() reads it (os.fsdecode), so that a NUL byte in it is refused as in a str rather
    // than cutting the name short.
    if (PyBytes_Check(value.ptr()))
      return convert_named<T>(py::module_::import("os").attr("fsdecode")(value), name);
  }
  try {
    if constexpr (std::is_enum_v<T>) {
      // TraceKind(-1) makes an instance that is no member: refused, as an unknown name is.
      const py::dict members = py::type::of<T>().attr("__members__");
      if (py::isinstance<T>(value)) {
        bool member = false;
        for (const auto& item : members) member = member || item.second.equal(value);
        if (!member) {
          throw InvalidArgument(name + ": " + short_repr(value) + " is not a member of " +
                                python_type_name<T>());
        }
      }
    }
    return value.cast<T>();
  } catch (const py::cast_error&) {
    if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
      if (PyLong_Check(value.ptr())) throw_out_of_range<T>(name, value);
      // A numpy integer (numpy.int64(-1) from numpy.arange) is an int out of range as well, not a value of
      // another type (numpy.bool_ and numpy's floats are no numbers.Integral).
      if (py::isinstance(value, py::module_::import("numbers").attr("Integral")))
        throw_out_of_range<T>(name, py::int_(py::reinterpret_borrow<py::object>(value)));
    }
    if constexpr (std::is_same_v<T, std::string>) {
      // A str that UTF-8 cannot encode ('\ud800', a lone surrogate) is of the right type and a wrong value.
      if (PyUnicode_Check(value.ptr())) {
        throw InvalidArgument(name + ": " + short_repr(value) +
                              " is not valid Unicode text (a lone surrogate has no UTF-8 encoding)");
      }
    }
    if constexpr (std::is_same_v<T, std::filesystem::path>) {
      // A str or path-like that the file system cannot take ("a\0b": a NUL byte) is a wrong value, as
      // os.fspath and open() say, not a value of another type.
      if (PyUnicode_Check(value.ptr()) || py::hasattr(value, "__fspath__")) {
        throw InvalidArgument(name + ": " + short_repr(value) +
                              " is not a file name (a NUL character, or text the file system cannot encode)");
      }
    }
    throw_type_error(name, python_type_name<T>(), value);
  }
}

template <typename T>
T take(const PyArgument<T>& argument, const std::string& name) {
  return convert_named<T>(argument.object, name);
}

}  // namespace calligraphy::python

namespace pybind11::detail {

template <typename T>
struct type_caster<calligraphy::python::PyArgument<T>> {
  using Value = calligraphy::python::PyArgument<T>;
  PYBIND11_TYPE_CASTER(Value, make_caster<T>::name);
  bool load(handle source, bool /*convert*/) {
    if (!source) return false;
    value.object = reinterpret_borrow<object>(source);
    return true;
  }
  static handle cast(const Value& v, return_value_policy /*policy*/, handle /*parent*/) {
    return v.object.inc_ref();
  }
};

template <typename Tag>
struct type_caster<calligraphy::python::Annotated<Tag>> {
  using Value = calligraphy::python::Annotated<Tag>;
  PYBIND11_TYPE_CASTER(Value, Tag::name);
  bool load(handle source, bool /*convert*/) {
    if (!source) return false;
    value.object = reinterpret_borrow<object>(source);
    return true;
  }
  static handle cast(const Value& v, return_value_policy /*policy*/, handle /*parent*/) {
    return v.object.inc_ref();
  }
};

}  // namespace pybind11::detail
