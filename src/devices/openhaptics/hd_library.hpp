#pragma once
// libHD.so loaded at run time with dlopen: no build dependency on OpenHaptics.
#include <memory>
#include <string>
#include <vector>

#include "devices/openhaptics/hd_api.hpp"

namespace calligraphy::openhaptics {

/// The HDAPI entry points of one loaded libHD. Unloaded (dlclose) on destruction.
class HdLibrary {
 public:
  /// Where load() looks, in order: $CALLIGRAPHY_LIBHD when set, then the loader's search path and the
  /// usual install locations.
  [[nodiscard]] static std::vector<std::string> candidate_paths();
  /// Loads the first candidate that opens and has every symbol. A candidate that is a path is checked
  /// first (shared_library_check.hpp), and every candidate is loaded and its device (`configuration`,
  /// empty: the default) initialised and released in a probe process (hd_probe.hpp) before this process
  /// maps it, so a damaged file or a driver that crashes, hangs or exits cannot take the caller down.
  /// Throws DeviceUnavailable naming $CALLIGRAPHY_LIBHD and why when that library is refused (then no
  /// other is tried), else DeviceNotFound "OpenHaptics not found" listing each path tried and why it
  /// failed. An HD error of hdInitDevice in the probe is not a refusal: the caller meets it again.
  [[nodiscard]] static std::shared_ptr<const HdLibrary> load(const std::string& configuration = {});

  ~HdLibrary();
  HdLibrary(const HdLibrary&) = delete;
  HdLibrary& operator=(const HdLibrary&) = delete;

  std::string path;
  hd::InitDeviceFn init_device = nullptr;
  hd::DisableDeviceFn disable_device = nullptr;
  hd::MakeCurrentDeviceFn make_current_device = nullptr;
  hd::BeginFrameFn begin_frame = nullptr;
  hd::EndFrameFn end_frame = nullptr;
  hd::GetDoublevFn get_doublev = nullptr;
  hd::GetIntegervFn get_integerv = nullptr;
  hd::SetDoublevFn set_doublev = nullptr;
  hd::GetStringFn get_string = nullptr;
  hd::EnableFn enable = nullptr;
  hd::GetErrorFn get_error = nullptr;
  hd::ScheduleAsynchronousFn schedule_asynchronous = nullptr;
  hd::ScheduleSynchronousFn schedule_synchronous = nullptr;
  hd::UnscheduleFn unschedule = nullptr;
  hd::StartSchedulerFn start_scheduler = nullptr;
  hd::StopSchedulerFn stop_scheduler = nullptr;
  hd::CheckCalibrationFn check_calibration = nullptr;
  hd::UpdateCalibrationFn update_calibration = nullptr;
  hd::SetSchedulerRateFn set_scheduler_rate = nullptr;  ///< may be null: the scheduler then runs at 1000 Hz

 private:
  HdLibrary() = default;
  void* handle_ = nullptr;
};

}  // namespace calligraphy::openhaptics
