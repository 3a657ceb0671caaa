// hd_stand_in_environment.cpp - set-up from environment variables, read once when the library loads, for
// tests that run another process (the command line) against the stand-in and cannot call the control API:
//   HD_STAND_IN_FAIL_INIT=CODE   hdInitDevice fails with this HDerror (decimal or 0x hex), e.g. 0x303
//   HD_STAND_IN_PATH=FILE        the hand plays back FILE: one "t_s x_mm y_mm z_mm" line per point (HDAPI's
//                                frame), t non-decreasing, from the scheduler's first tick
//   HD_STAND_IN_LOADED_MARKER=FILE  FILE is created when the library is loaded (in any process): a test
//                                can tell that a command never loaded it
//   HD_STAND_IN_EXIT_ON_LOAD=STATUS  the library's constructor calls exit(STATUS)
//   HD_STAND_IN_INIT=crash|hang|exit:STATUS  hdInitDevice raises SIGSEGV, never returns, or calls exit
//   HD_STAND_IN_SCHEDULER_STALLED=1  hdStartScheduler succeeds but its thread never runs a tick
//   HD_STAND_IN_STOP=hang        hdStopScheduler never returns (a driver stuck stopping its servo thread)
// A value that cannot be read is reported on stderr and ignored.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "hd_stand_in_control.h"
#include "hd_stand_in_state.h"

namespace {

hdsi::EnvironmentFaults faults;

bool read_status(const char* text, int& status) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 0);
  if (end == text || *end != '\0' || value < 0 || value > 255) return false;
  status = static_cast<int>(value);
  return true;
}

void read_faults() {
  if (const char* exit_status = std::getenv("HD_STAND_IN_EXIT_ON_LOAD");
      exit_status != nullptr && *exit_status) {
    int status = 0;
    if (read_status(exit_status, status)) std::exit(status);
    std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_EXIT_ON_LOAD=%s is not a status 0..255; ignored\n",
                 exit_status);
  }
  if (const char* init = std::getenv("HD_STAND_IN_INIT"); init != nullptr && *init) {
    if (std::strcmp(init, "crash") == 0) {
      faults.init = hdsi::InitMisbehaviour::crash;
    } else if (std::strcmp(init, "hang") == 0) {
      faults.init = hdsi::InitMisbehaviour::hang;
    } else if (std::strncmp(init, "exit:", 5) == 0 && read_status(init + 5, faults.exit_status)) {
      faults.init = hdsi::InitMisbehaviour::exit;
    } else {
      std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_INIT=%s is not crash, hang or exit:STATUS; ignored\n",
                   init);
    }
  }
  if (const char* stalled = std::getenv("HD_STAND_IN_SCHEDULER_STALLED"); stalled != nullptr && *stalled) {
    faults.scheduler_stalled = std::strcmp(stalled, "0") != 0;
  }
  if (const char* stop = std::getenv("HD_STAND_IN_STOP"); stop != nullptr && *stop) {
    if (std::strcmp(stop, "hang") == 0) {
      faults.stop_hangs = true;
    } else {
      std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_STOP=%s is not hang; ignored\n", stop);
    }
  }
}

void load_path(const char* file_name) {
  std::FILE* file = std::fopen(file_name, "r");
  if (file == nullptr) {
    std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_PATH=%s cannot be opened; no path\n", file_name);
    return;
  }
  std::vector<double> t_s, xyz_mm;
  double t = 0, x = 0, y = 0, z = 0;
  while (std::fscanf(file, "%lf %lf %lf %lf", &t, &x, &y, &z) == 4) {
    t_s.push_back(t);
    xyz_mm.insert(xyz_mm.end(), {x, y, z});
  }
  const bool whole = std::feof(file) != 0;
  std::fclose(file);
  if (!whole || hd_stand_in_set_path(t_s.data(), xyz_mm.data(), t_s.size()) != 0)
    std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_PATH=%s is not a path of t x y z lines; no path\n",
                 file_name);
}

__attribute__((constructor)) void configure_from_environment() {
  if (const char* marker = std::getenv("HD_STAND_IN_LOADED_MARKER"); marker != nullptr && *marker != '\0') {
    if (std::FILE* file = std::fopen(marker, "a")) std::fclose(file);
  }
  read_faults();
  if (const char* code = std::getenv("HD_STAND_IN_FAIL_INIT"); code != nullptr && *code != '\0') {
    char* end = nullptr;
    const unsigned long value = std::strtoul(code, &end, 0);
    if (end != nullptr && *end == '\0') {
      hd_stand_in_fail_init(static_cast<unsigned int>(value));
    } else {
      std::fprintf(stderr, "hd_stand_in: HD_STAND_IN_FAIL_INIT=%s is not a number; ignored\n", code);
    }
  }
  if (const char* path = std::getenv("HD_STAND_IN_PATH"); path != nullptr && *path != '\0') load_path(path);
}

}  // namespace

const hdsi::EnvironmentFaults& hdsi::environment_faults() { return faults; }
