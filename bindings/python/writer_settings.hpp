#pragma once
// A simulated writer from Python arguments: a profile name or a WriterProfile, and a dict of settings.
// Shared by simulate_trial / run_trial and writer_profile().
#include <pybind11/pybind11.h>

#include <vector>

#include "arguments.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "calligraphy/trial/writer_setting.hpp"

namespace calligraphy::python {

struct WriterTag {
  static constexpr auto name = py::detail::const_name("Union[str, WriterProfile]");
};
struct WriterParamsTag {
  static constexpr auto name = py::detail::const_name("Optional[Mapping[str, float]]");
};

/// `writer`: "novice", "skilled", "foreign" (writer_profile) or a WriterProfile (copied); then each
/// key of the mapping `params` (None: none) set with set_writer_parameter. Raises InvalidArgument
/// naming an unknown profile or key ("writer_params['key']: ...") or a value out of range, TypeError
/// for a writer or params of the wrong type or a value that is not a number. `given`, when not null,
/// receives the settings of `params` in the order they were applied, as `--writer-param` states them.
WriterProfile writer_with_settings(const py::object& writer, const py::object& params,
                                   std::vector<WriterSetting>* given = nullptr);

}  // namespace calligraphy::python
