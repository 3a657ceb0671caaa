#include "devices/openhaptics/hd_probe.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <vector>

extern char** environ;

namespace calligraphy::openhaptics {

extern const unsigned char kHdProbeProgram[];  // generated from probe/hd_probe_main.cpp
extern const std::size_t kHdProbeProgramSize;

namespace {

std::string errno_text(int error) { return std::strerror(error); }

// Closes a file descriptor on every way out.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd = -1) : fd_(fd) {}
  ~FileDescriptor() { reset(); }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  [[nodiscard]] int get() const { return fd_; }
  void reset(int fd = -1) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
  }

 private:
  int fd_;
};

// The probe program in an anonymous memory file: nothing to install or find, nothing left behind.
int program_in_memory(std::string& problem) {
  const int fd = static_cast<int>(::syscall(SYS_memfd_create, "calligraphy-hd-probe", MFD_CLOEXEC));
  if (fd < 0) {
    problem = "cannot probe it: memfd_create: " + errno_text(errno);
    return -1;
  }
  std::size_t done = 0;
  while (done < kHdProbeProgramSize) {
    const ssize_t wrote = ::write(fd, kHdProbeProgram + done, kHdProbeProgramSize - done);
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) {
      problem = "cannot probe it: writing the probe program: " + errno_text(errno);
      ::close(fd);
      return -1;
    }
    done += static_cast<std::size_t>(wrote);
  }
  return fd;
}

// A descriptor above 3, so that the child's dup2 onto 3 (the report) cannot close it.
int above_report(int fd) {
  if (fd < 0 || fd > 3) return fd;
  const int moved = ::fcntl(fd, F_DUPFD_CLOEXEC, 4);
  ::close(fd);
  return moved;
}

const char* step_words(const std::string& step) {
  if (step == "initialising") return "while initialising the device (in hdInitDevice)";
  if (step == "disabling") return "while releasing the device (in hdDisableDevice)";
  return "while loading";
}

std::string signal_text(int signal_number) {
  const char* name = ::sigabbrev_np(signal_number);
  return name != nullptr ? std::string("SIG") + name : "signal " + std::to_string(signal_number);
}

}  // namespace

HdProbeResult probe_hd_library(const std::string& path, const std::string& configuration, double timeout_s) {
  HdProbeResult result;
  const FileDescriptor program(above_report(program_in_memory(result.problem)));
  if (program.get() < 0) {
    if (result.problem.empty()) result.problem = "cannot probe it: fcntl: " + errno_text(errno);
    return result;
  }
  std::array<int, 2> pipe_ends{};
  if (::pipe2(pipe_ends.data(), O_CLOEXEC) != 0) {
    result.problem = "cannot probe it: pipe: " + errno_text(errno);
    return result;
  }
  FileDescriptor reader(pipe_ends[0]);
  FileDescriptor writer(above_report(pipe_ends[1]));
  if (writer.get() < 0) {
    result.problem = "cannot probe it: fcntl: " + errno_text(errno);
    return result;
  }
  // Everything the child needs is made before fork: after it, a process with threads may only make
  // async-signal-safe calls until exec (dup2, execveat and _exit are).
  std::string program_name = "calligraphy-hd-probe";
  std::string library_path = path;
  std::string configuration_name = configuration;
  std::array<char*, 4> arguments{program_name.data(), library_path.data(), configuration_name.data(),
                                 nullptr};
  char empty_path[] = "";
  const pid_t child = ::fork();
  if (child < 0) {
    result.problem = "cannot probe it: fork: " + errno_text(errno);
    return result;
  }
  if (child == 0) {
    // The report on descriptor 3 (dup2 clears close-on-exec); the driver's chatter on standard error,
    // never in standard output (`devices` prints its listing there).
    if (::dup2(writer.get(), 3) < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0) ::_exit(126);
    ::syscall(SYS_execveat, program.get(), empty_path, arguments.data(), environ, AT_EMPTY_PATH);
    ::_exit(127);
  }
  writer.reset();
  std::string report;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  bool timed_out = false;
  bool reaped = false;
  int status = 0;
  while (true) {  // read the report until the child closes its end (it ended) or time is up
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(give_up - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd waiting{reader.get(), POLLIN, 0};
    const int ready = ::poll(&waiting, 1, static_cast<int>(std::min<long long>(left.count(), 100)));
    if (ready < 0 && errno != EINTR) break;
    if (ready == 0 && ::waitpid(child, &status, WNOHANG) == child) {
      reaped = true;  // ended, though something it started may still hold the pipe: read what is there
      const int flags = ::fcntl(reader.get(), F_GETFL);
      ::fcntl(reader.get(), F_SETFL, flags | O_NONBLOCK);
    }
    if (ready <= 0 && !reaped) continue;
    std::array<char, 512> buffer{};
    const ssize_t got = ::read(reader.get(), buffer.data(), buffer.size());
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // end of file (the child ended), or nothing more after it was reaped
    report.append(buffer.data(), static_cast<std::size_t>(got));
  }
  if (timed_out) ::kill(child, SIGKILL);
  while (!reaped && ::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  // The last step begun, and the lines that carry details.
  std::string step = "loading", detail_kind, detail;
  std::size_t at = 0;
  while (at < report.size()) {
    const std::size_t end = report.find('\n', at);
    if (end == std::string::npos) break;  // a line cut short by a death: not a step
    const std::string line = report.substr(at, end - at);
    at = end + 1;
    const std::size_t space = line.find(' ');
    if (space == std::string::npos) {
      step = line;
    } else {
      detail_kind = line.substr(0, space);
      detail = line.substr(space + 1);
    }
  }
  const int seconds = static_cast<int>(std::lround(timeout_s));
  if (timed_out) {
    result.problem = step == "initialising" ? "did not return from hdInitDevice within " +
                                                  std::to_string(seconds) + " s (the probe was killed)"
                     : step == "disabling" ? "did not return from hdDisableDevice within " +
                                                 std::to_string(seconds) + " s (the probe was killed)"
                                           : "did not finish loading within " + std::to_string(seconds) +
                                                 " s (the probe was killed)";
    return result;
  }
  if (WIFSIGNALED(status)) {
    result.problem = "the driver crashed with " + signal_text(WTERMSIG(status)) + " " + step_words(step);
    return result;
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (step == "done" && code == 0) return result;
  if (detail_kind == "loader" && code == 1) {
    result.problem = detail.empty() ? "not loadable" : detail;
  } else if (detail_kind == "missing" && code == 2) {
    result.problem = "loaded, but lacks " + detail;
  } else if (detail_kind == "init_error" && code == 3) {
    unsigned int error = 0;
    int internal = 0;
    if (std::sscanf(detail.c_str(), "%u %d", &error, &internal) == 2) {
      result.init_error = hd::HDErrorInfo{error, internal, hd::HD_INVALID_HANDLE};
    }
  } else if (code == 126 || code == 127) {
    result.problem = "cannot probe it: the probe program could not be started";
  } else {
    // The driver ended the process itself (exit() in a constructor or in hdInitDevice).
    result.problem =
        "the driver library exited the process (status " + std::to_string(code) + ") " + step_words(step);
  }
  return result;
}

}  // namespace calligraphy::openhaptics
