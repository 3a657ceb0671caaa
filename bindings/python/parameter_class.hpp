#pragma once
// Binds a C++ parameter struct (ForceLawParameters, WriterProfile, ...) as a Python class with every
// field: keyword-only constructor `Cls(**fields)` starting from the C++ defaults, one property per field
// (typed, documented with its unit), `replace(**fields)`, `to_dict()`, `validate()`, `__eq__` and a
// `__repr__` that reads back as a constructor call.
//
// Values are checked where they are set: a value of the wrong type raises TypeError naming the field,
// and the whole struct is validated (the C++ `validate()`, or the given check) after the constructor and
// after each assignment, so an out-of-range value raises ValueError (InvalidArgument) at once and the
// object keeps its previous value.
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "arguments.hpp"
#include "calligraphy/core/parameter_table.hpp"
#include "numpy_arrays.hpp"

namespace calligraphy::python {

template <typename S>
class ParameterClass {
 public:
  using Validator = std::function<void(const S&)>;

  ParameterClass(py::handle scope, const char* name, std::string doc, Validator validate)
      : cls_(scope, name), name_(name), doc_(std::move(doc)), shared_(std::make_shared<Shared>()) {
    shared_->validate = std::move(validate);
  }

  /// Adds field `name` (the C++ member's name, units in it) with its documentation.
  template <typename T>
  ParameterClass& field(const char* name, T S::*member, const std::string& doc) {
    Field f;
    f.name = name;
    const std::string qualified = name_ + "." + name;
    auto shared = shared_;
    if constexpr (std::is_same_v<T, Vec2> || std::is_same_v<T, Vec3>) {
      constexpr int dim = static_cast<int>(T::RowsAtCompileTime);
      f.type = "numpy.typing.ArrayLike";
      f.set = [member, qualified](S& s, py::handle v) { s.*member = vector_from<T>(v, qualified); };
      f.repr = [member](const S& s) {
        std::string text = "(";
        for (int k = 0; k < dim; ++k)
          text += (k ? ", " : "") + std::string(py::repr(py::float_((s.*member)[k])));
        return text + ")";
      };
      f.to_python = [member](const S& s) {
        py::list out;
        for (int k = 0; k < dim; ++k) out.append((s.*member)[k]);
        return py::object(out);
      };
      f.equal = [member](const S& a, const S& b) { return a.*member == b.*member; };
      cls_.def_property(
          name, [member](const S& s) { return read_only(to_array(s.*member)); },
          [member, qualified, shared](S& s, const ArrayLike& v) {
            S copy = s;
            copy.*member = vector_from<T>(v.object, qualified);
            shared->validate(copy);
            s = copy;
          },
          (doc + " Shape (" + std::to_string(dim) + ",), float64, read-only copy.").c_str());
    } else if constexpr (std::is_arithmetic_v<T> || std::is_same_v<T, std::string> || std::is_enum_v<T>) {
      f.type = python_type_name<T>();
      f.set = [member, qualified](S& s, py::handle v) { s.*member = convert_named<T>(v, qualified); };
      f.repr = [member](const S& s) {
        // An enum shows as "Type.name" (its str), which reads back in Python; others as their repr.
        if constexpr (std::is_enum_v<T>) return std::string(py::str(py::cast(s.*member)));
        return std::string(py::repr(py::cast(s.*member)));
      };
      f.to_python = [member](const S& s) { return py::cast(s.*member); };
      f.equal = [member](const S& a, const S& b) { return a.*member == b.*member; };
      cls_.def_property(
          name, [member](const S& s) { return s.*member; },
          [member, qualified, shared](S& s, const PyArgument<T>& v) {
            S copy = s;
            copy.*member = take(v, qualified);
            shared->validate(copy);
            s = copy;
          },
          doc.c_str());
    } else {
      // A nested parameter struct, bound before: returned by reference into the parent, so that
      // `parent.child.field = x` changes the parent (and is checked by the child's own setter).
      f.type = python_type_name<T>();
      f.set = [member, qualified](S& s, py::handle v) {
        // A dict of the nested struct's fields works too (what to_dict and pickling give).
        if (py::isinstance<py::dict>(v)) {
          s.*member = py::type::of<T>()(**py::reinterpret_borrow<py::dict>(v)).template cast<T>();
        } else {
          s.*member = convert_named<T>(v, qualified);
        }
      };
      f.repr = [member](const S& s) { return std::string(py::repr(py::cast(s.*member))); };
      f.to_python = [member](const S& s) { return py::cast(s.*member).attr("to_dict")(); };
      f.equal = [member](const S& a, const S& b) { return py::cast(a.*member).equal(py::cast(b.*member)); };
      cls_.def_property(
          name,
          py::cpp_function([member](S& s) -> T& { return s.*member; },
                           py::return_value_policy::reference_internal),
          [member, qualified, shared](S& s, const PyArgument<T>& v) {
            S copy = s;
            copy.*member = take(v, qualified);
            shared->validate(copy);
            s = copy;
          },
          doc.c_str());
    }
    shared_->fields.push_back(std::move(f));
    return *this;
  }

  /// Adds the numeric field `member` as its `ParameterTable<S>` entry names and documents it (the doc, the
  /// unit and the range: parameter_table.hpp), so that Python's documentation cannot drift from the check.
  ParameterClass& field(double S::*member) {
    const ParameterField<S>& entry = parameter_field(member);
    // The tables' names are string literals: data() is null-terminated and lives as long as the program.
    if (entry.whole_number) return count_field(entry.name.data(), member, entry.description());
    return field(entry.name.data(), member, entry.description());
  }

  /// Adds field `name`, a count the C++ struct keeps as a double (ParameterField::whole_number), as an int:
  /// read as an int, set with an int (a float is refused, as for every int argument), checked whole.
  ParameterClass& count_field(const char* name, double S::*member, const std::string& doc) {
    Field f;
    f.name = name;
    f.type = python_type_name<std::int64_t>();
    const std::string qualified = name_ + "." + name;
    auto shared = shared_;
    const auto value = [member](const S& s) { return static_cast<std::int64_t>(std::llround(s.*member)); };
    f.set = [member, qualified](S& s, py::handle v) {
      s.*member = static_cast<double>(convert_named<std::int64_t>(v, qualified));
    };
    f.repr = [value](const S& s) { return std::to_string(value(s)); };
    f.to_python = [value](const S& s) { return py::object(py::int_(value(s))); };
    f.equal = [member](const S& a, const S& b) { return a.*member == b.*member; };
    cls_.def_property(
        name, [value](const S& s) { return value(s); },
        [member, qualified, shared](S& s, const PyArgument<std::int64_t>& v) {
          S copy = s;
          copy.*member = static_cast<double>(take(v, qualified));
          shared->validate(copy);
          s = copy;
        },
        doc.c_str());
    shared_->fields.push_back(std::move(f));
    return *this;
  }

  /// Adds field `name` holding one of several parameter classes bound before (a std::variant of them, e.g.
  /// ForceLawParameters::guidance_law): read as a copy of the alternative held (assign a new one to change
  /// it), set with an instance of any alternative or a dict of its fields with "law" naming its class
  /// (what to_dict gives).
  template <typename... Alternatives>
  ParameterClass& variant_field(const char* name, std::variant<Alternatives...> S::*member,
                                const std::string& doc) {
    using V = std::variant<Alternatives...>;
    Field f;
    f.name = name;
    const std::string qualified = name_ + "." + name;
    std::string type = "Union[";
    ((type += python_type_name<Alternatives>() + ", "), ...);
    f.type = type.substr(0, type.size() - 2) + "]";
    const std::string expected = f.type;
    const auto convert = [qualified, expected](py::handle v) -> V {
      if (py::isinstance<py::dict>(v)) {
        py::dict fields = py::reinterpret_borrow<py::dict>(v).attr("copy")();
        const std::string law = fields.contains("law") ? std::string(py::str(fields.attr("pop")("law"))) : "";
        std::optional<V> out;
        ((law == python_type_name<Alternatives>()
              ? void(out = V(py::type::of<Alternatives>()(**fields).template cast<Alternatives>()))
              : void()),
         ...);
        if (!out) throw py::type_error(qualified + ": a dict needs \"law\", one of " + expected);
        return *out;
      }
      std::optional<V> out;
      ((!out && py::isinstance<Alternatives>(v) ? void(out = V(v.cast<Alternatives>())) : void()), ...);
      if (!out) throw_type_error(qualified, expected, v);
      return *out;
    };
    f.set = [member, convert](S& s, py::handle v) { s.*member = convert(v); };
    f.repr = [member](const S& s) {
      return std::visit([](const auto& law) { return std::string(py::repr(py::cast(law))); }, s.*member);
    };
    f.to_python = [member](const S& s) {
      return std::visit(
          [](const auto& law) {
            py::object object = py::cast(law);
            py::dict out;
            out["law"] = object.get_type().attr("__name__");
            for (const auto item : py::dict(object.attr("to_dict")())) out[item.first] = item.second;
            return py::object(out);
          },
          s.*member);
    };
    f.equal = [member](const S& a, const S& b) { return a.*member == b.*member; };
    auto shared = shared_;
    cls_.def_property(
        name,
        [member](const S& s) { return std::visit([](const auto& law) { return py::cast(law); }, s.*member); },
        [member, convert, shared](S& s, const py::object& v) {
          S copy = s;
          copy.*member = convert(v);
          shared->validate(copy);
          s = copy;
        },
        (doc + " One of " + expected + "; a copy: assign a new one to change it.").c_str());
    shared_->fields.push_back(std::move(f));
    return *this;
  }

  /// Adds the constructor and the generic methods; returns the class for further definitions.
  py::class_<S>& finish() {
    auto shared = shared_;
    const std::string name = name_;
    const S defaults{};
    // A class without fields (FixedGuidance) takes no arguments: a bare "*" is not a Python signature.
    std::string signature = "__init__(self: " + name + (shared->fields.empty() ? "" : ", *");
    for (const Field& f : shared->fields)
      signature += ", " + f.name + ": " + f.type + " = " + f.repr(defaults);
    signature += ") -> None";
    cls_.doc() = doc_;
    {
      py::options options;
      options.disable_function_signatures();
      cls_.def(py::init([shared, name](const py::kwargs& fields) {
                 S s{};
                 shared->assign(s, fields, name);
                 return s;
               }),
               (signature + "\n\nEvery field is keyword-only and defaults to the C++ default shown. Raises "
                            "TypeError naming a field of the wrong type or an unknown name, ValueError "
                            "(InvalidArgument) naming a field out of range.")
                   .c_str());
      cls_.def(
          "replace",
          [shared, name](const S& self, const py::kwargs& fields) {
            S s = self;
            shared->assign(s, fields, name);
            return s;
          },
          ("replace(self: " + name + ", **fields) -> " + name +
           "\n\nA copy with the given fields changed; checked like the constructor.")
              .c_str());
    }
    cls_.def(
        "to_dict",
        [shared](const S& self) {
          py::dict out;
          for (const Field& f : shared->fields) out[py::str(f.name)] = f.to_python(self);
          return out;
        },
        "The fields as a dict (nested parameters as dicts, vectors as lists), SI units as named.");
    cls_.def(
        "validate", [shared](const S& self) { shared->validate(self); },
        "Raises ValueError (InvalidArgument) naming the first field out of range.");
    cls_.def("__repr__", [shared, name](const S& self) {
      std::string text = name + "(";
      bool first = true;
      for (const Field& f : shared->fields) {
        text += (first ? "" : ", ") + f.name + "=" + f.repr(self);
        first = false;
      }
      return text + ")";
    });
    cls_.def(
        "__eq__",
        [shared](const S& self, const py::object& other) -> Comparison {
          if (!py::isinstance<S>(other)) return {py::reinterpret_borrow<py::object>(Py_NotImplemented)};
          const S& o = other.cast<const S&>();
          for (const Field& f : shared->fields) {
            if (!f.equal(self, o)) return {py::bool_(false)};
          }
          return {py::bool_(true)};
        },
        py::is_operator());
    cls_.attr("__hash__") = py::none();  // mutable: not hashable
    cls_.def(py::pickle(
        [shared](const S& self) {
          py::dict out;
          for (const Field& f : shared->fields) out[py::str(f.name)] = f.to_python(self);
          return out;
        },
        [shared, name](const py::dict& fields) {
          S s{};
          shared->assign(s, fields, name);
          return s;
        }));
    return cls_;
  }

  py::class_<S>& cls() { return cls_; }

 private:
  struct Field {
    std::string name;
    std::string type;
    std::function<void(S&, py::handle)> set;
    std::function<std::string(const S&)> repr;
    std::function<py::object(const S&)> to_python;
    std::function<bool(const S&, const S&)> equal;
  };
  struct Shared {
    std::vector<Field> fields;
    Validator validate;
    void assign(S& s, const py::dict& values, const std::string& name) const {
      for (const auto& item : values) {
        const std::string key = py::str(item.first);
        const Field* found = nullptr;
        for (const Field& f : fields) {
          if (f.name == key) found = &f;
        }
        if (found == nullptr) {
          std::string known;
          for (const Field& f : fields) known += (known.empty() ? "" : ", ") + f.name;
          throw py::type_error(name + ": unknown field '" + key + "'; fields: " + known);
        }
        found->set(s, item.second);
      }
      validate(s);
    }
  };

  template <typename V>
  static V vector_from(py::handle v, const std::string& name) {
    if constexpr (std::is_same_v<V, Vec2>) {
      return as_vec2(v, name);
    } else {
      return as_vec3(v, name);
    }
  }

  py::class_<S> cls_;
  std::string name_;
  std::string doc_;
  std::shared_ptr<Shared> shared_;
};

}  // namespace calligraphy::python
