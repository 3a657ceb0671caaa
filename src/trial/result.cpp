#include "calligraphy/trial/result.hpp"

namespace calligraphy {

const char* to_string(TrialEnd end) noexcept {
  switch (end) {
    case TrialEnd::completed:
      return "completed";
    case TrialEnd::time_limit:
      return "time_limit";
    case TrialEnd::device_fault:
      return "device_fault";
    case TrialEnd::watchdog:
      return "watchdog";
    case TrialEnd::interrupted:
      return "interrupted";
    case TrialEnd::writer_gave_up:
      return "writer_gave_up";
  }
  return "unknown";
}

}  // namespace calligraphy
