#pragma once
/// \file device_survey_json.hpp
/// A device survey (device_registry.hpp) as JSON: what `calligraphy devices --json` prints.
#include <string>

#include "calligraphy/devices/device_registry.hpp"

namespace calligraphy {

/// A JSON object (2-space indent, newline-terminated): `devices`, an array with one object per listing
/// (`name`, `backend`, `hardware`, `details`, and `info` with the DeviceInfo in SI units: `model`,
/// `manufacturer`, `max_force_n`, `max_continuous_force_n`, `max_stiffness_n_per_m`,
/// `max_damping_n_s_per_m`, `intrinsic_damping_n_s_per_m`, `workspace_radius_m`, `workspace_size_m` [x, y,
/// z], every field as a study trial record's `device.info` names it); `notes`, the survey's notes as strings;
/// `any_hardware`, whether a physical device was found.
std::string device_survey_json(const DeviceSurvey& survey);

}  // namespace calligraphy
