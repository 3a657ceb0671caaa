#include "calligraphy/report/device_survey_json.hpp"

#include <nlohmann/json.hpp>

#include "calligraphy/core/json_text.hpp"
#include "report/device_info_object.hpp"

namespace calligraphy {

nlohmann::json report_detail::device_info_object(const DeviceInfo& info) {
  return {{"model", info.model},
          {"manufacturer", info.manufacturer},
          {"max_force_n", info.max_force_n},
          {"max_continuous_force_n", info.max_continuous_force_n},
          {"max_stiffness_n_per_m", info.max_stiffness_n_per_m},
          {"max_damping_n_s_per_m", info.max_damping_n_s_per_m},
          {"intrinsic_damping_n_s_per_m", info.intrinsic_damping_n_s_per_m},
          {"workspace_radius_m", info.workspace_radius_m},
          {"workspace_size_m",
           {info.workspace_size_m.x(), info.workspace_size_m.y(), info.workspace_size_m.z()}}};
}

std::string device_survey_json(const DeviceSurvey& survey) {
  nlohmann::json devices = nlohmann::json::array();
  for (const DeviceListing& listing : survey.devices) {
    devices.push_back({{"name", listing.name},
                       {"backend", listing.backend},
                       {"hardware", listing.capabilities.hardware},
                       {"moved_by_simulated_hand", listing.capabilities.moved_by_simulated_hand},
                       {"needs_calibration", listing.capabilities.needs_calibration},
                       {"details", listing.details},
                       {"limits_known", listing.limits_known},
                       {"info", report_detail::device_info_object(listing.info)}});
  }
  const nlohmann::json doc = {
      {"devices", devices}, {"notes", survey.notes}, {"any_hardware", survey.any_hardware()}};
  return json_text(doc, 2) + "\n";
}

}  // namespace calligraphy
