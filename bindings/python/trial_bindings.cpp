// trial: a whole simulated trial (include/calligraphy/trial/trial.hpp, run_simulated_trial) and its
// result. Every binding of the trial runner is in this file.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "arguments.hpp"
#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/trial/trial.hpp"
#include "character_source.hpp"
#include "core/unicode.hpp"
#include "numpy_arrays.hpp"
#include "report_bindings.hpp"

namespace calligraphy::python {
namespace {

struct CharactersTag {
  static constexpr auto name = py::detail::const_name("str | Character | Sequence[Character]");
};
struct WriterTag {
  static constexpr auto name = py::detail::const_name("str | WriterProfile");
};

// A trial's trace as numpy arrays (one row per servo tick) and its metrics.
struct PyTrialResult {
  py::array time_s, position_m, force_n, state, stroke, element;
  py::dict metrics;
};

// Characters: a str of one or more characters (loaded from `library`), a Character, or a sequence of them.
std::vector<Character> characters_from(const py::object& object, const CharacterSource& library) {
  std::vector<Character> characters;
  if (py::isinstance<py::str>(object)) {
    for (char32_t c : decode_utf8(object.cast<std::string>())) characters.push_back(library.load(c));
  } else if (py::isinstance<Character>(object)) {
    characters.push_back(object.cast<Character>());
  } else if (py::isinstance<py::sequence>(object) && !py::isinstance<py::bytes>(object)) {
    for (const py::handle item : object) {
      if (!py::isinstance<Character>(item)) {
        throw_type_error("characters", "a str, a Character or a sequence of Characters", item);
      }
      characters.push_back(item.cast<Character>());
    }
  } else {
    throw_type_error("characters", "a str, a Character or a sequence of Characters", object);
  }
  if (characters.empty()) throw InvalidArgument("characters: no character given");
  return characters;
}

WriterProfile writer_from(const py::object& object) {
  if (py::isinstance<WriterProfile>(object)) return object.cast<WriterProfile>();
  if (!py::isinstance<py::str>(object))
    throw_type_error("writer", "'novice', 'skilled' or a WriterProfile", object);
  const std::string name = object.cast<std::string>();
  if (name == "novice") return WriterProfile::novice();
  if (name == "skilled") return WriterProfile::skilled();
  throw InvalidArgument("writer: expected 'novice', 'skilled' or a WriterProfile, got '" + name + "'");
}

PyTrialResult to_python(const TrialResult& result, py::dict metrics) {
  const auto n = static_cast<py::ssize_t>(result.trace.size());
  auto time = new_array({n});
  auto position = new_array({n, 3});
  auto force = new_array({n, 3});
  py::array_t<std::uint8_t> state({n});
  py::array_t<std::int64_t> stroke({n});
  py::array_t<std::int64_t> element({n});
  auto tw = time.mutable_unchecked<1>();
  auto pw = position.mutable_unchecked<2>();
  auto fw = force.mutable_unchecked<2>();
  auto sw = state.mutable_unchecked<1>();
  auto aw = stroke.mutable_unchecked<1>();
  auto ew = element.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const TrialSample& s = result.trace[static_cast<std::size_t>(i)];
    tw(i) = s.time_s;
    for (py::ssize_t k = 0; k < 3; ++k) {
      pw(i, k) = s.position_m[static_cast<Eigen::Index>(k)];
      fw(i, k) = s.force_n[static_cast<Eigen::Index>(k)];
    }
    sw(i) = static_cast<std::uint8_t>(s.state);
    aw(i) = static_cast<std::int64_t>(s.stroke);
    ew(i) = static_cast<std::int64_t>(s.element);
  }
  return PyTrialResult{time, position, force, state, stroke, element, std::move(metrics)};
}

PyTrialResult simulate_trial_py(const Annotated<CharactersTag>& characters_object,
                                const Annotated<WriterTag>& writer_object, const Checked<bool>& guidance,
                                const Checked<double>& rate_hz, const Checked<std::uint64_t>& seed,
                                const std::optional<Checked<CharacterSource>>& library,
                                const std::optional<Checked<ForceLawParameters>>& force_law,
                                const Checked<double>& max_duration_s, const Checked<bool>& keep_trace) {
  TrialOptions options;
  if (force_law) options.force = take(*force_law, "force_law");
  options.force.guidance = take(guidance, "guidance");
  options.writer = writer_from(writer_object.object);
  options.rate_hz = take(rate_hz, "rate_hz");
  options.seed = take(seed, "seed");
  options.max_duration_s = take(max_duration_s, "max_duration_s");
  options.keep_trace = take(keep_trace, "keep_trace");
  const CharacterSource source = library ? take(*library, "library") : CharacterSource::embedded();
  const std::vector<Character> characters = characters_from(characters_object.object, source);
  std::string label;
  for (const Character& c : characters) label += encode_utf8(c.code_point);

  TrialResult result;
  {
    py::gil_scoped_release release;
    const Scene scene = Scene::lay_out(characters);
    result = run_simulated_trial(scene, options);
  }
  cli::TrialDescription description;
  description.characters = label;
  description.guidance = options.force.guidance;
  description.writer = options.writer.name.empty() ? "custom" : options.writer.name;
  description.seed = options.seed;
  description.rate_hz = options.rate_hz;
  return to_python(result, trial_metrics(description, result));
}

}  // namespace

void bind_trial(py::module_& m) {
  py::class_<PyTrialResult>(m, "TrialResult",
                            "A simulated trial: the trace, one row per servo tick (N ticks, empty when "
                            "keep_trace=False), and the metrics.")
      .def_readonly("time_s", &PyTrialResult::time_s, "(N,) float64, time [s]")
      .def_readonly("position_m", &PyTrialResult::position_m,
                    "(N, 3) float64, pen tip as read from the device [m]")
      .def_readonly("force_n", &PyTrialResult::force_n, "(N, 3) float64, commanded force [N]")
      .def_readonly("state", &PyTrialResult::state, "(N,) uint8, the InteractionState's int value")
      .def_readonly("stroke", &PyTrialResult::stroke, "(N,) int64, active stroke over the scene, 0-based")
      .def_readonly("element", &PyTrialResult::element,
                    "(N,) int64, active element within the stroke, 0-based")
      .def_readonly("metrics", &PyTrialResult::metrics,
                    "dict with exactly the keys of `calligraphy trial --json` (deviations in mm, times in s, "
                    "forces in N)");

  m.def("simulate_trial", &simulate_trial_py, py::arg("characters"), py::arg("writer") = "novice",
        py::arg("guidance") = true, py::arg("rate_hz") = 1000.0, py::arg("seed") = 0,
        py::arg("library") = py::none(), py::arg("force_law") = py::none(), py::arg("max_duration_s") = 300.0,
        py::arg("keep_trace") = true,
        R"(Runs a whole guided writing trial lock-step on the simulated device with a simulated writer,
as `calligraphy trial` does. Deterministic for a seed; the GIL is released while it runs.

characters: a str of one or more characters (loaded from `library`, default the embedded set),
            a Character, or a sequence of Characters (written left to right).
writer: 'novice', 'skilled' or a WriterProfile. guidance: in-plane guidance on or off (the paper
force stays). rate_hz: servo rate [Hz], 100..100000. seed: int >= 0. max_duration_s: simulated
time limit [s]. force_law: ForceLawParameters (its `guidance` is replaced by `guidance`).
keep_trace: False leaves the arrays empty (faster, metrics only).
Returns a TrialResult. Raises CharacterNotFound (a KeyError), InvalidArgument (a ValueError) for
values out of range, TypeError naming the argument for a value of the wrong type.)");
}

}  // namespace calligraphy::python
