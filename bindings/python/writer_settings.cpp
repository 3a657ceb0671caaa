#include "writer_settings.hpp"

#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy::python {

WriterProfile writer_with_settings(const py::object& writer, const py::object& params,
                                   std::vector<WriterSetting>* given) {
  WriterProfile profile;
  if (py::isinstance<WriterProfile>(writer)) {
    profile = writer.cast<WriterProfile>();
  } else if (py::isinstance<py::str>(writer)) {
    const std::string name = convert_named<std::string>(writer, "writer");  // a lone surrogate: a wrong value
    try {
      profile = writer_profile(name);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("writer: ") + e.what());
    }
  } else {
    throw_type_error("writer", "'novice', 'skilled', 'foreign' or a WriterProfile", writer);
  }
  if (params.is_none()) return profile;
  if (!py::isinstance<py::dict>(params) && !py::hasattr(params, "items"))
    throw_type_error("writer_params", "a dict {'key': value}", params);
  for (const py::handle item : params.attr("items")()) {
    const py::tuple pair = py::reinterpret_borrow<py::tuple>(item);
    if (!py::isinstance<py::str>(pair[0])) throw_type_error("writer_params key", "str", pair[0]);
    const std::string key = convert_named<std::string>(pair[0], "writer_params key");
    const std::string name = "writer_params['" + key + "']";
    const double value = convert_named<double>(pair[1], name);
    try {
      set_writer_parameter(profile, key, value);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(name + ": " + e.what());
    }
    if (given != nullptr) given->push_back({key, value});
  }
  return profile;
}

}  // namespace calligraphy::python
