#include "devices/openhaptics/hd_library.hpp"

#include <dlfcn.h>

#include <cstdlib>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"
#include "devices/openhaptics/hd_probe.hpp"
#include "devices/shared_library_check.hpp"

namespace calligraphy::openhaptics {
namespace {

// dlsym returns void*; converting it to a function pointer is conditionally supported and is what
// POSIX guarantees to work.
template <typename Function>
bool bind(void* handle, const char* name, Function& out, std::string& missing) {
  void* symbol = dlsym(handle, name);
  if (symbol == nullptr) {
    missing += missing.empty() ? name : std::string(", ") + name;
    return false;
  }
  out = reinterpret_cast<Function>(symbol);
  return true;
}

}  // namespace

std::vector<std::string> HdLibrary::candidate_paths() {
  std::vector<std::string> paths;
  if (const char* explicit_path = std::getenv("CALLIGRAPHY_LIBHD");
      explicit_path != nullptr && *explicit_path) {
    paths.emplace_back(explicit_path);
  }
  // The bare names go through the dynamic loader's search path (LD_LIBRARY_PATH, ld.so.cache).
  for (const char* path :
       {"libHD.so", "libHD.so.3.4", "libHD.so.3", "/usr/lib/libHD.so", "/usr/lib64/libHD.so",
        "/usr/local/lib/libHD.so", "/opt/OpenHaptics/Developer/lib/libHD.so"}) {
    paths.emplace_back(path);
  }
  return paths;
}

std::shared_ptr<const HdLibrary> HdLibrary::load(const std::string& configuration) {
  std::string tried;
  const char* explicit_path = std::getenv("CALLIGRAPHY_LIBHD");
  for (const auto& path : candidate_paths()) {
    const bool named_by_user = explicit_path != nullptr && path == explicit_path;
    // A library the user named and that is refused is an error, never replaced by another libHD found
    // on the search path: the session would run on a driver nobody chose.
    // The path and the loader's words about it are quoted as printable text: a path from the environment
    // may hold a line break or an escape sequence, and the reason is printed as a line of `devices`.
    const auto refuse = [&](const std::string& problem) {
      if (named_by_user) {
        std::string message = "OpenHaptics: CALLIGRAPHY_LIBHD=";
        message.append(printable_one_line(path))
            .append(" cannot be used: ")
            .append(printable_one_line(problem));
        message.append("; set it to the full path of a working libHD.so, or unset it");
        throw DeviceUnavailable(message);
      }
      tried.append("\n  ").append(printable_one_line(path)).append(": ").append(printable_one_line(problem));
    };
    // A path is checked before any process maps it (a truncated file raises SIGBUS, a FIFO blocks), then
    // loaded and its device initialised in a probe process: only a driver that neither crashes, hangs nor
    // exits there is loaded into this process.
    const std::string problem =
        path.find('/') != std::string::npos ? devices::shared_library_problem(path) : "";
    if (!problem.empty()) {
      refuse(problem);
      continue;
    }
    const HdProbeResult probe = probe_hd_library(path, configuration);
    if (!probe.problem.empty()) {
      refuse(probe.problem);
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      refuse(why != nullptr ? why : "not loadable");
      continue;
    }
    std::shared_ptr<HdLibrary> library(new HdLibrary);
    library->handle_ = handle;
    library->path = path;
    std::string missing;
    bind(handle, "hdInitDevice", library->init_device, missing);
    bind(handle, "hdDisableDevice", library->disable_device, missing);
    bind(handle, "hdMakeCurrentDevice", library->make_current_device, missing);
    bind(handle, "hdBeginFrame", library->begin_frame, missing);
    bind(handle, "hdEndFrame", library->end_frame, missing);
    bind(handle, "hdGetDoublev", library->get_doublev, missing);
    bind(handle, "hdGetIntegerv", library->get_integerv, missing);
    bind(handle, "hdSetDoublev", library->set_doublev, missing);
    bind(handle, "hdGetString", library->get_string, missing);
    bind(handle, "hdEnable", library->enable, missing);
    bind(handle, "hdGetError", library->get_error, missing);
    bind(handle, "hdScheduleAsynchronous", library->schedule_asynchronous, missing);
    bind(handle, "hdScheduleSynchronous", library->schedule_synchronous, missing);
    bind(handle, "hdUnschedule", library->unschedule, missing);
    bind(handle, "hdStartScheduler", library->start_scheduler, missing);
    bind(handle, "hdStopScheduler", library->stop_scheduler, missing);
    bind(handle, "hdCheckCalibration", library->check_calibration, missing);
    bind(handle, "hdUpdateCalibration", library->update_calibration, missing);
    // Optional: without it the scheduler keeps its default rate, 1000 Hz (HDAPI reference).
    library->set_scheduler_rate =
        reinterpret_cast<hd::SetSchedulerRateFn>(dlsym(handle, "hdSetSchedulerRate"));
    if (missing.empty()) return library;
    library.reset();  // unloaded before the next candidate, or before the error
    refuse("loaded, but lacks " + missing);
  }
  throw DeviceNotFound("OpenHaptics not found: libHD.so could not be loaded; tried:" + tried +
                       "\n(set CALLIGRAPHY_LIBHD to the full path of libHD.so)");
}

HdLibrary::~HdLibrary() {
  if (handle_ != nullptr) dlclose(handle_);
}

}  // namespace calligraphy::openhaptics
