#include "devices/servo_loop_realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <array>
#include <cerrno>
#include <cstring>

namespace calligraphy::devices {

bool built_with_sanitizer() noexcept {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

std::string describe_errno(int error) {
  const char* name = nullptr;
  switch (error) {
    case EPERM:
      name = "EPERM";
      break;
    case EINVAL:
      name = "EINVAL";
      break;
    case ENOMEM:
      name = "ENOMEM";
      break;
    case EAGAIN:
      name = "EAGAIN";
      break;
    case ESRCH:
      name = "ESRCH";
      break;
    case EFAULT:
      name = "EFAULT";
      break;
    default:
      break;
  }
  std::array<char, 128> buffer{};
  // GNU strerror_r returns the message (possibly a static string) rather than filling the buffer.
  const char* text = strerror_r(error, buffer.data(), buffer.size());
  return std::string(text) + " (" + (name != nullptr ? name : "errno " + std::to_string(error)) + ")";
}

namespace {

void append_problem(std::string& problems, const std::string& problem) {
  if (!problems.empty()) problems += "; ";
  problems += problem;
}

}  // namespace

bool lock_process_memory(std::string& problems) {
  if (built_with_sanitizer()) {
    append_problem(problems, "mlockall: not available in a sanitizer build");
    return false;
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    const int error = errno;  // read before anything else can change it
    append_problem(problems, "mlockall(MCL_CURRENT | MCL_FUTURE): " + describe_errno(error));
    return false;
  }
  return true;
}

void apply_thread_realtime(const ServoLoopOptions& options, RealtimeStatus& status) {
  const pthread_t self = pthread_self();
  if (options.priority > 0) {
    sched_param parameter{};
    parameter.sched_priority = options.priority;
    const int error = pthread_setschedparam(self, SCHED_FIFO, &parameter);
    if (error == 0) {
      status.fifo_scheduling = true;
      status.priority = options.priority;
    } else {
      append_problem(status.problems, "SCHED_FIFO priority " + std::to_string(options.priority) + ": " +
                                          describe_errno(error));
    }
  }
  if (options.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<std::size_t>(options.cpu), &set);
    const int error = pthread_setaffinity_np(self, sizeof(set), &set);
    if (error == 0) {
      status.cpu = options.cpu;
    } else {
      append_problem(status.problems,
                     "pinning to CPU " + std::to_string(options.cpu) + ": " + describe_errno(error));
    }
  }
}

void prefault_stack() noexcept {
  // 64 KiB is far more than the loop and a renderer tick use; volatile keeps the writes.
  constexpr std::size_t kBytes = 64 * 1024;
  std::array<char, kBytes> block;
  volatile char* p = block.data();
  for (std::size_t i = 0; i < kBytes; i += 1024) p[i] = 0;
}

}  // namespace calligraphy::devices
