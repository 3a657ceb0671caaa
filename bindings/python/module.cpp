// The extension module `calligraphy._calligraphy` (pybind11 + numpy), re-exported by the package's
// __init__.py. Everything is SI: lengths in m, forces in N, time in s, stiffness in N/m, damping in
// N s/m; character data stays in its own units (hanzi-writer-data's 1024 box, y up). One file per
// library module binds that module's types (bindings.hpp).
#include "bindings.hpp"

PYBIND11_MODULE(_calligraphy, m) {
  m.doc() = "Haptic training of Chinese handwriting (Wang, Zhang & Yao 2006), SI units throughout.";
  using namespace calligraphy::python;
  bind_core(m);
  bind_logging(m);
  bind_model(m);
  bind_collision(m);
  bind_render(m);
  bind_sim(m);
  bind_writer_learning(m);
  bind_report(m);
  bind_trial(m);
  bind_score(m);
}
