#pragma once
// One laid-out scene per embedded character, made on first use and kept for the test binary's run (a test
// that writes many traces over a few characters lays each out once).
#include <map>
#include <string>
#include <vector>

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

/// The scene of the embedded characters of `text`, left to right, with the default layout. Throws what
/// CharacterLibrary::load throws for a character the embedded set lacks.
inline Scene scene_of_text(const std::u32string& text) {
  std::vector<Character> characters;
  for (const char32_t c : text) characters.push_back(CharacterLibrary::embedded().load(c));
  return Scene::lay_out(characters);
}

/// The scene of 十 alone, made once (thread-safe): the hostile cases' smallest character of two strokes.
inline const Scene& cross_scene() {
  static const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});
  return scene;
}

}  // namespace calligraphy::testing
