#pragma once
// One laid-out scene per embedded character, made on first use and kept for the test binary's run (a test
// that writes many traces over a few characters lays each out once).
#include <map>

#include "calligraphy/model/character_library.hpp"
#include "calligraphy/model/scene.hpp"

namespace calligraphy::testing {

/// The scene of embedded character `c` alone, with the default layout. Throws what
/// CharacterLibrary::load throws for a character the embedded set lacks. Not thread-safe.
inline const Scene& embedded_scene(char32_t c) {
  static std::map<char32_t, Scene> scenes;
  auto it = scenes.find(c);
  if (it == scenes.end())
    it = scenes.emplace(c, Scene::lay_out({CharacterLibrary::embedded().load(c)})).first;
  return it->second;
}

}  // namespace calligraphy::testing
