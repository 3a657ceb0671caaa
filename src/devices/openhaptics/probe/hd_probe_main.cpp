// calligraphy-hd-probe: loads a libHD and initialises its device once, in a process of its own, for
// HdLibrary::load (hd_probe.cpp), so that a driver that crashes, hangs or exits cannot take the caller with
// it. The caller embeds this program and runs it from memory (fork + exec, which is safe in a process with
// threads, unlike dlopen after fork). Usage: calligraphy-hd-probe LIBRARY [CONFIGURATION]; it reports on
// file descriptor 3, one line per step, so that the caller can tell where it stopped:
//   loading / initialising / disabling / done      the step begun (done: all went well)
//   loader MESSAGE                                  dlopen failed (exit 1)
//   missing NAME[, NAME...]                         required symbols absent (exit 2)
//   init_error CODE INTERNAL                        hdInitDevice failed with an HD error (exit 3)
// Plain C library calls only: it is linked without the project.
#include <dlfcn.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <csignal>
#include <initializer_list>
#include <cstdio>
#include <cstring>

namespace {

constexpr int kReport = 3;

struct HdErrorInfo {
  unsigned int errorCode;
  int internalErrorCode;
  unsigned int hHD;
};

void report(const char* line) {
  const std::size_t size = std::strlen(line);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t wrote = ::write(kReport, line + done, size - done);
    if (wrote <= 0) return;
    done += static_cast<std::size_t>(wrote);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // The caller may die while a driver hangs here: this process must not outlive it.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  // A driver's crash must end this process by its signal, which the caller names: a sanitizer's runtime
  // (in a sanitizer build) would catch it and exit with a status instead.
  for (const int fatal : {SIGSEGV, SIGBUS, SIGFPE, SIGILL}) std::signal(fatal, SIG_DFL);
  if (argc < 2) return 64;
  report("loading\n");
  void* library = ::dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = ::dlerror();
    report("loader ");
    report(why != nullptr ? why : "not loadable");
    report("\n");
    return 1;
  }
  static const char* const required[] = {"hdInitDevice",
                                         "hdDisableDevice",
                                         "hdMakeCurrentDevice",
                                         "hdBeginFrame",
                                         "hdEndFrame",
                                         "hdGetDoublev",
                                         "hdGetIntegerv",
                                         "hdSetDoublev",
                                         "hdGetString",
                                         "hdEnable",
                                         "hdGetError",
                                         "hdScheduleAsynchronous",
                                         "hdScheduleSynchronous",
                                         "hdUnschedule",
                                         "hdStartScheduler",
                                         "hdStopScheduler",
                                         "hdCheckCalibration",
                                         "hdUpdateCalibration"};
  char missing[1024] = "";
  for (const char* name : required) {
    if (::dlsym(library, name) != nullptr) continue;
    if (missing[0] != '\0') std::strncat(missing, ", ", sizeof missing - std::strlen(missing) - 1);
    std::strncat(missing, name, sizeof missing - std::strlen(missing) - 1);
  }
  if (missing[0] != '\0') {
    report("missing ");
    report(missing);
    report("\n");
    return 2;
  }
  using InitDevice = unsigned int (*)(const char*);
  using DisableDevice = void (*)(unsigned int);
  using GetError = HdErrorInfo (*)();
  const auto init_device = reinterpret_cast<InitDevice>(::dlsym(library, "hdInitDevice"));
  const auto disable_device = reinterpret_cast<DisableDevice>(::dlsym(library, "hdDisableDevice"));
  const auto get_error = reinterpret_cast<GetError>(::dlsym(library, "hdGetError"));
  report("initialising\n");
  const unsigned int handle = init_device(argc > 2 && argv[2][0] != '\0' ? argv[2] : nullptr);
  if (const HdErrorInfo error = get_error(); error.errorCode != 0) {
    char line[64];
    std::snprintf(line, sizeof line, "init_error %u %d\n", error.errorCode, error.internalErrorCode);
    report(line);
    return 3;
  }
  report("disabling\n");
  disable_device(handle);
  report("done\n");
  // _exit: a driver's exit handlers and destructors are not part of the probe.
  ::_exit(0);
}
