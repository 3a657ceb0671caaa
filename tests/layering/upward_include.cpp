// Compiled with only the model module's include folders by the `layering_build_refuses_upward_include`
// test, which expects the compilation to FAIL: the model sits below render, so render's public headers
// are not visible to it.
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/renderer.hpp"

int main() { return 0; }
