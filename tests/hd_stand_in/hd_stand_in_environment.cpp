// hd_stand_in_environment.cpp - set-up from environment variables, read once when the library loads, for
// tests that run another process (the command line) against the stand-in and cannot call the control API:
//   HD_STAND_IN_FAIL_INIT=CODE   hdInitDevice fails with this HDerror (decimal or 0x hex), e.g. 0x303
//   HD_STAND_IN_PATH=FILE        the hand plays back FILE: one "t_s x_mm y_mm z_mm" line per point (HDAPI's
//                                frame), t non-decreasing, from the scheduler's first tick
//   HD_STAND_IN_LOADED_MARKER=FILE  FILE is created when the library is loaded (in any process): a test
//                                can tell that a command never loaded it
// A value that cannot be read is reported on stderr and ignored.
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "hd_stand_in_control.h"

namespace {

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
