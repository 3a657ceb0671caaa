#pragma once
// Applying the servo loop's realtime settings (SCHED_FIFO, CPU pinning, mlockall) and saying why one
// failed. Called at start, never from the loop body.
#include <string>

#include "calligraphy/devices/servo_loop.hpp"

namespace calligraphy::devices {

/// True when this build runs under a sanitizer (memory cannot be locked there).
[[nodiscard]] bool built_with_sanitizer() noexcept;

/// mlockall(MCL_CURRENT | MCL_FUTURE). Returns true on success; otherwise appends the reason to `problems`.
bool lock_process_memory(std::string& problems);

/// Applies the requested priority and CPU to the calling thread and fills `status` with what was
/// obtained; appends each failure with its reason to `status.problems`.
void apply_thread_realtime(const ServoLoopOptions& options, RealtimeStatus& status);

/// "Operation not permitted (EPERM)" for an errno value.
[[nodiscard]] std::string describe_errno(int error);

/// Touches 64 KiB of the calling thread's stack so that the loop does not fault on it later.
void prefault_stack() noexcept;

}  // namespace calligraphy::devices
