// The extension module `calligraphy._calligraphy` (pybind11 + numpy), re-exported by the package's
// __init__.py. Everything is SI: lengths in m, forces in N, time in s, stiffness in N/m, damping in
// N s/m; character data stays in its own units (hanzi-writer-data's 1024 box, y up). One file per
// library module binds that module's types (bindings.hpp).
#include <unordered_set>

#include "bindings.hpp"

namespace {

namespace py = pybind11;

// pickle's protocols 0 and 1 reduce an object through copyreg._reduce_ex, which calls the first base class
// that is not a Python class with the object, pybind11_object(obj): pybind11 throws from that constructor
// and the process aborts ("instance allocation failed: new instance has no pybind11-registered base
// types"). Every class of the module reduces as protocol 2 does instead, whatever the protocol: a class
// that pickles (the parameter classes, the enums) through its __getstate__, any other with Python's
// TypeError "cannot pickle '<class>' object", as copy.copy and pickle's default protocol already do.
void reduce_as_protocol_2(const py::handle& scope, PyTypeObject* pybind11_base,
                          std::unordered_set<PyObject*>& done) {
  const py::dict names(scope.attr("__dict__"));  // a copy of a class's mappingproxy
  for (const auto& item : names) {
    const py::handle value = item.second;
    if (!PyType_Check(value.ptr()) || done.count(value.ptr()) > 0 ||
        PyType_IsSubtype(reinterpret_cast<PyTypeObject*>(value.ptr()), pybind11_base) == 0) {
      continue;
    }
    done.insert(value.ptr());
    py::setattr(value, "__reduce_ex__",
                py::cpp_function(
                    [](const py::handle& self, const py::object& protocol) -> py::object {
                      const py::object object_reduce_ex =
                          py::module_::import("builtins").attr("object").attr("__reduce_ex__");
                      return object_reduce_ex(self, protocol < py::int_(2) ? py::int_(2) : protocol);
                    },
                    py::name("__reduce_ex__"), py::is_method(value), py::arg("protocol"),
                    "Reduces for pickle and copy as protocol 2 does, for every protocol."));
    reduce_as_protocol_2(value, pybind11_base, done);  // classes nested in it
  }
}

}  // namespace

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
  std::unordered_set<PyObject*> done;
  reduce_as_protocol_2(m, reinterpret_cast<PyTypeObject*>(py::detail::get_internals().instance_base), done);
}
