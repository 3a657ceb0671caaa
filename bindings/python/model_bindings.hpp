#pragma once
// Conversions of model types shared by several binding files.
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "arguments.hpp"
#include "calligraphy/model/character.hpp"
#include "calligraphy/model/element.hpp"
#include "calligraphy/model/scene.hpp"
#include "character_source.hpp"

namespace calligraphy::python {

namespace py = pybind11;

/// A StrokeElement from control points of shape (n, 2), n in 2..5; InvalidArgument naming `name`.
StrokeElement element_from_points(py::handle object, const std::string& name);

/// Characters from a str of one or more characters (loaded from `library`), a Character or a sequence of
/// Characters; TypeError or InvalidArgument naming `name` otherwise or when there are none.
std::vector<Character> characters_from(py::handle object, const CharacterSource& library,
                                       const std::string& name);

/// Stroke `stroke_index` of character `character_index` of `scene`. Indices name a stroke by its place in
/// the writing order, so negative ones (Python's counting from the end) are refused with the others out of
/// range: IndexError naming the argument; TypeError when `scene` is not a Scene. The scene must outlive it.
struct StrokeOfScene {
  const PlacedCharacter& character;
  std::size_t stroke;
};
StrokeOfScene stroke_of_scene(const PyArgument<Scene>& scene, const PyArgument<long long>& character_index,
                              const PyArgument<long long>& stroke_index);

}  // namespace calligraphy::python
