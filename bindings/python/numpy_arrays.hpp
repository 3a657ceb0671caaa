#pragma once
// numpy <-> Eigen for the bindings. Vectors are float64; an argument of shape (dim,) is one vector,
// (N, dim) are N of them. Shape errors raise InvalidArgument (ValueError) naming the argument.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "arguments.hpp"
#include "calligraphy/core/geometry.hpp"

namespace calligraphy::python {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// A new float64 array of this shape.
py::array_t<double> new_array(std::vector<py::ssize_t> shape);
/// (count, 2) from points.
py::array_t<double> points_to_array(const Vec2* points, std::size_t count);
py::array_t<double> points_to_array(const std::vector<Vec2>& points);
/// (2,) or (3,).
py::array_t<double> to_array(const Vec2& v);
py::array_t<double> to_array(const Vec3& v);
/// The same array, made read-only (for values copied out of a C++ object: writing to them would
/// change nothing, so it must not look as if it did; and for what an object holds that its other values
/// were made from, as a trial's trace its metrics: writing to it would part the two).
template <typename T>
py::array_t<T> read_only(py::array_t<T> array) {
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

/// InvalidArgument "<name> holds <dtype> values, not real numbers" for what numpy's forcecast to float64
/// would misread: complex numbers (their real part taken), text (parsed as numbers), as a numpy array of
/// strings or an object array (a pandas column of str) holding any, and times and dates (counts of their
/// unit: a pandas Timedelta column in nanoseconds), and a numpy.ma masked array with a value masked (read as
/// the number under its mask). Nothing for anything else: the
/// conversion itself says what else is wrong.
void check_real_numbers(py::handle object, const std::string& name);

/// Vectors of length `dim`: shape (dim,) is one vector, (N, dim) are N of them.
struct Vectors {
  Array array;
  bool single = false;
  py::ssize_t count = 0;
  [[nodiscard]] const double* row(py::ssize_t i) const {
    return array.data() + i * array.shape(array.ndim() - 1);
  }
  [[nodiscard]] Vec2 vec2(py::ssize_t i) const { return {row(i)[0], row(i)[1]}; }
  [[nodiscard]] Vec3 vec3(py::ssize_t i) const { return {row(i)[0], row(i)[1], row(i)[2]}; }
};
Vectors as_vectors(py::handle object, py::ssize_t dim, const std::string& name);

/// Scalars: shape () is one, (N,) are N of them.
struct Scalars {
  Array array;
  bool single = false;
  py::ssize_t count = 0;
};
Scalars as_scalars(py::handle object, const std::string& name);

/// Exactly one vector of shape (2,) / (3,).
Vec2 as_vec2(py::handle object, const std::string& name);
Vec3 as_vec3(py::handle object, const std::string& name);

/// Applies `f(i) -> Eigen vector of size Dim` to each of `in`'s rows: shape (Dim,) for a single input,
/// (N, Dim) otherwise.
template <int Dim, typename F>
py::array_t<double> map_rows(const Vectors& in, F&& f) {
  auto out = in.single ? new_array({Dim}) : new_array({in.count, Dim});
  double* o = out.mutable_data();
  for (py::ssize_t i = 0; i < in.count; ++i) {
    const Eigen::Matrix<double, Dim, 1> r = f(i);
    for (int k = 0; k < Dim; ++k) o[i * Dim + k] = r[k];
  }
  return out;
}

/// InvalidArgument unless `b` has as many rows as `a` or is a single vector.
void check_broadcast(const Vectors& a, const Vectors& b, const std::string& a_name,
                     const std::string& b_name);

}  // namespace calligraphy::python
