#pragma once
// Conversions of model types shared by several binding files.
#include <pybind11/pybind11.h>

#include <string>

#include "calligraphy/model/element.hpp"

namespace calligraphy::python {

namespace py = pybind11;

/// A StrokeElement from control points of shape (n, 2), n in 2..5; InvalidArgument naming `name`.
StrokeElement element_from_points(py::handle object, const std::string& name);

}  // namespace calligraphy::python
