#pragma once
// A libHD tried in a process of its own before this one loads it: dlopen, the symbols, hdInitDevice and
// hdDisableDevice, under a time bound. A vendor driver runs code when it is loaded and when the device is
// initialised; one that crashes, hangs or calls exit() there would otherwise take the caller with it (the
// command line, a Python session, a trial).
#include <string>

#include "devices/openhaptics/hd_api.hpp"

namespace calligraphy::openhaptics {

struct HdProbeResult {
  /// Empty when the library loaded, has every required symbol and hdInitDevice returned (with or without
  /// an HD error) and hdDisableDevice too; otherwise why not, for people, without the path: "the driver
  /// crashed with SIGSEGV while initialising the device", "did not return from hdInitDevice within 5 s",
  /// "the driver library exited the process (status 0) while loading", "lacks hdEndFrame", the loader's
  /// message.
  std::string problem;
  /// The HD error hdInitDevice reported in the probe (HD_SUCCESS: none). Not a problem of the library:
  /// the caller initialises again in its own process and words that error as it always does.
  hd::HDErrorInfo init_error{hd::HD_SUCCESS, 0, hd::HD_INVALID_HANDLE};
};

/// Runs the probe program (probe/hd_probe_main.cpp, embedded in the library) on `path` with fork + exec,
/// safe in a process with threads; kills it after `timeout_s` [s]. `configuration`: the device's
/// configuration name, empty for the default device. Never throws for the library's behaviour (only
/// std::bad_alloc).
[[nodiscard]] HdProbeResult probe_hd_library(const std::string& path, const std::string& configuration,
                                             double timeout_s = 5.0);

}  // namespace calligraphy::openhaptics
