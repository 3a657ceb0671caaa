#include "calligraphy/devices/phantom_models.hpp"

namespace calligraphy {
namespace {

DeviceInfo make_info(const char* model, const char* manufacturer, double max_force_n, double continuous_n,
                     double stiffness_n_per_m, double damping_n_s_per_m, double radius_m, Vec3 box_m) {
  DeviceInfo info;
  info.model = model;
  info.manufacturer = manufacturer;
  info.max_force_n = max_force_n;
  info.max_continuous_force_n = continuous_n;
  info.max_stiffness_n_per_m = stiffness_n_per_m;
  info.max_damping_n_s_per_m = damping_n_s_per_m;
  info.workspace_radius_m = radius_m;
  info.workspace_size_m = box_m;
  return info;
}

}  // namespace

DeviceInfo phantom_omni_info() {
  return make_info("Phantom Omni", "SensAble Technologies", 3.3, 0.88, 700.0, 5.0, 0.10, {0.16, 0.12, 0.07});
}

DeviceInfo phantom_desktop_info() {
  return make_info("Phantom Desktop", "SensAble Technologies", 7.9, 1.75, 1000.0, 5.0, 0.10,
                   {0.16, 0.12, 0.12});
}

DeviceInfo touch_info() {
  return make_info("Touch", "3D Systems (Geomagic)", 3.3, 0.88, 400.0, 4.0, 0.075, {0.16, 0.12, 0.07});
}

}  // namespace calligraphy
