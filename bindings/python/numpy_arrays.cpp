#include "numpy_arrays.hpp"

#include "calligraphy/core/errors.hpp"

namespace calligraphy::python {

py::array_t<double> new_array(std::vector<py::ssize_t> shape) {
  return py::array_t<double>(std::move(shape));
}

py::array_t<double> points_to_array(const Vec2* points, std::size_t count) {
  auto out = new_array({static_cast<py::ssize_t>(count), 2});
  auto w = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < count; ++i) {
    w(static_cast<py::ssize_t>(i), 0) = points[i].x();
    w(static_cast<py::ssize_t>(i), 1) = points[i].y();
  }
  return out;
}

py::array_t<double> points_to_array(const std::vector<Vec2>& points) {
  return points_to_array(points.data(), points.size());
}

py::array_t<double> to_array(const Vec2& v) {
  auto out = new_array({2});
  out.mutable_at(0) = v.x();
  out.mutable_at(1) = v.y();
  return out;
}

py::array_t<double> to_array(const Vec3& v) {
  auto out = new_array({3});
  for (py::ssize_t i = 0; i < 3; ++i) out.mutable_at(i) = v[static_cast<Eigen::Index>(i)];
  return out;
}

void check_real_numbers(py::handle object, const std::string& name) {
  // numpy.ma: converted to float64, a masked array is its data, the values under the mask too.
  if (py::hasattr(object, "mask")) {
    const py::module_ ma = py::module_::import("numpy.ma");
    if (py::isinstance(object, ma.attr("MaskedArray"))) {
      const py::object mask = ma.attr("getmaskarray")(object);
      if (mask.attr("any")().cast<bool>()) {
        throw InvalidArgument(name + " holds " + std::to_string(mask.attr("sum")().cast<long long>()) +
                              " masked value(s) (numpy.ma), which would be read as the numbers under the "
                              "mask: fill them (.filled(numpy.nan)) or leave them out");
      }
    }
  }
  const py::array array = py::array::ensure(object);
  if (!array) return;
  const char kind = array.dtype().kind();
  if (kind == 'c' || kind == 'U' || kind == 'S') {
    throw InvalidArgument(name + " holds " + std::string(py::str(array.dtype())) +
                          " values, not real numbers");
  }
  if (kind == 'm' || kind == 'M') {  // cast to float64 as counts of their unit: nanoseconds for pandas' times
    throw InvalidArgument(
        name + " holds " + std::string(py::str(array.dtype())) +
        " values, not real numbers (give times in seconds, e.g. Series.dt.total_seconds())");
  }
  if (kind == 'O') {
    for (const py::handle item : array.attr("ravel")()) {
      if (PyUnicode_Check(item.ptr()) || PyBytes_Check(item.ptr()) || PyComplex_Check(item.ptr())) {
        throw InvalidArgument(name + " holds " + short_repr(item) + ", not a real number");
      }
    }
  }
}

namespace {

Array to_float_array(py::handle object, const std::string& name) {
  if (py::isinstance<py::str>(object) || py::isinstance<py::bytes>(object) || object.is_none()) {
    throw_type_error(name, "an array of numbers", object);
  }
  check_real_numbers(object, name);
  Array array = Array::ensure(object);
  if (!array) {
    PyErr_Clear();
    throw_type_error(name, "an array of numbers", object);
  }
  return array;
}

}  // namespace

Vectors as_vectors(py::handle object, py::ssize_t dim, const std::string& name) {
  Vectors v{to_float_array(object, name)};
  const py::ssize_t ndim = v.array.ndim();
  if (ndim == 1 && v.array.shape(0) == dim) {
    v.single = true;
    v.count = 1;
  } else if (ndim == 2 && v.array.shape(1) == dim) {
    v.count = v.array.shape(0);
  } else {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < ndim; ++i) shape += (i ? ", " : "") + std::to_string(v.array.shape(i));
    shape += ndim == 1 ? ",)" : ")";
    throw InvalidArgument(name + ": expected shape (" + std::to_string(dim) + ",) or (N, " +
                          std::to_string(dim) + "), got " + shape);
  }
  return v;
}

Scalars as_scalars(py::handle object, const std::string& name) {
  Scalars s{to_float_array(object, name)};
  if (s.array.ndim() == 0) {
    s.single = true;
    s.count = 1;
  } else if (s.array.ndim() == 1) {
    s.count = s.array.shape(0);
  } else {
    throw InvalidArgument(name + ": expected a number or shape (N,), got " + std::to_string(s.array.ndim()) +
                          " dimensions");
  }
  return s;
}

Vec2 as_vec2(py::handle object, const std::string& name) {
  const Vectors v = as_vectors(object, 2, name);
  if (!v.single) throw InvalidArgument(name + ": expected shape (2,)");
  return v.vec2(0);
}

Vec3 as_vec3(py::handle object, const std::string& name) {
  const Vectors v = as_vectors(object, 3, name);
  if (!v.single) throw InvalidArgument(name + ": expected shape (3,)");
  return v.vec3(0);
}

void check_broadcast(const Vectors& a, const Vectors& b, const std::string& a_name,
                     const std::string& b_name) {
  if (b.count != a.count && !b.single) {
    throw InvalidArgument(b_name + ": expected one vector or as many as " + a_name + " (" +
                          std::to_string(a.count) + "), got " + std::to_string(b.count));
  }
}

}  // namespace calligraphy::python
