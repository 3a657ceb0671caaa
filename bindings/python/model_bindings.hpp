#pragma once
// Conversions of model types shared by several binding files.
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "calligraphy/model/character.hpp"
#include "calligraphy/model/element.hpp"
#include "character_source.hpp"

namespace calligraphy::python {

namespace py = pybind11;

/// A StrokeElement from control points of shape (n, 2), n in 2..5; InvalidArgument naming `name`.
StrokeElement element_from_points(py::handle object, const std::string& name);

/// Characters from a str of one or more characters (loaded from `library`), a Character or a sequence of
/// Characters; TypeError or InvalidArgument naming `name` otherwise or when there are none.
std::vector<Character> characters_from(py::handle object, const CharacterSource& library,
                                       const std::string& name);

}  // namespace calligraphy::python
