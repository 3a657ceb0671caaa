// A fault-injection shim, loaded with LD_PRELOAD into a program under test, as SQLite tests itself (its
// "I/O error" tests fail the Nth call of the file-system layer): it makes the Nth call of one kind of file
// system call on a path under a given folder fail with a given errno, or kills the process just before it.
//
//   CALLIGRAPHY_FAULT_UNDER   only calls on paths under this folder count (an absolute path); required
//   CALLIGRAPHY_FAULT_CALL    open | write | fsync | rename | link | mkdir | unlink | flock: the kind that fails
//   CALLIGRAPHY_FAULT_AT      N >= 1: the Nth call of that kind fails (0 or unset: none; the shim only counts)
//   CALLIGRAPHY_FAULT_ERRNO   ENOSPC | EIO | EROFS | ENOLCK | EPERM | EDQUOT (default EIO)
//   CALLIGRAPHY_FAULT_KILL    1: SIGKILL the process at that call instead of failing it; TERM, INT or HUP:
//                             raise that signal just before the call, which then goes on as it would
//   CALLIGRAPHY_FAULT_COUNTS  a file that receives, at exit, one line "kind count" per kind counted
//
// Calls on descriptors (write, fsync, flock) count when the descriptor's path (/proc/self/fd) is under the
// folder. The shim calls the C library's own functions through dlsym(RTLD_NEXT); it allocates nothing.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

enum kind { k_open, k_write, k_fsync, k_rename, k_link, k_mkdir, k_unlink, k_flock, k_count };
static const char* const kind_names[k_count] = {"open", "write", "fsync", "rename", "link", "mkdir", "unlink",
                                                "flock"};
static long counts[k_count];
static int configured = 0;
static char under[4096];
static size_t under_length = 0;
static int fault_kind = -1;
static long fault_at = 0;
static int fault_errno = EIO;
static int fault_kill = 0;  // the signal raised at the call (SIGKILL for "1"), or 0
static const char* counts_file = NULL;

static void configure(void) {
  if (configured) return;
  configured = 1;
  const char* folder = getenv("CALLIGRAPHY_FAULT_UNDER");
  if (folder != NULL && folder[0] == '/' && strlen(folder) < sizeof under - 2) {
    strcpy(under, folder);
    under_length = strlen(under);
    if (under[under_length - 1] != '/') under[under_length++] = '/', under[under_length] = '\0';
  }
  const char* call = getenv("CALLIGRAPHY_FAULT_CALL");
  for (int k = 0; call != NULL && k < k_count; ++k) {
    if (strcmp(call, kind_names[k]) == 0) fault_kind = k;
  }
  const char* at = getenv("CALLIGRAPHY_FAULT_AT");
  if (at != NULL) fault_at = strtol(at, NULL, 10);
  const char* name = getenv("CALLIGRAPHY_FAULT_ERRNO");
  if (name != NULL) {
    static const struct { const char* name; int value; } errnos[] = {
        {"ENOSPC", ENOSPC}, {"EIO", EIO}, {"EROFS", EROFS}, {"ENOLCK", ENOLCK}, {"EPERM", EPERM},
        {"EDQUOT", EDQUOT}};
    for (size_t i = 0; i < sizeof errnos / sizeof errnos[0]; ++i) {
      if (strcmp(name, errnos[i].name) == 0) fault_errno = errnos[i].value;
    }
  }
  const char* kill_it = getenv("CALLIGRAPHY_FAULT_KILL");
  if (kill_it != NULL && strcmp(kill_it, "1") == 0) fault_kill = SIGKILL;
  if (kill_it != NULL && strcmp(kill_it, "TERM") == 0) fault_kill = SIGTERM;
  if (kill_it != NULL && strcmp(kill_it, "INT") == 0) fault_kill = SIGINT;
  if (kill_it != NULL && strcmp(kill_it, "HUP") == 0) fault_kill = SIGHUP;
  counts_file = getenv("CALLIGRAPHY_FAULT_COUNTS");
}

// A path relative to the working folder is made absolute for the comparison.
static int path_is_under(const char* path) {
  if (under_length == 0 || path == NULL) return 0;
  if (path[0] == '/') return strncmp(path, under, under_length) == 0;
  char absolute[8192];
  if (getcwd(absolute, sizeof absolute - 1) == NULL) return 0;
  size_t length = strlen(absolute);
  if (length + 1 + strlen(path) >= sizeof absolute) return 0;
  absolute[length++] = '/';
  strcpy(absolute + length, path);
  return strncmp(absolute, under, under_length) == 0;
}

static int fd_is_under(int fd) {
  char link[64];
  char path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t length = readlink(link, path, sizeof path - 1);
  if (length <= 0) return 0;
  path[length] = '\0';
  return path_is_under(path);
}

// Counts a call of `kind` that is under the folder; returns -1 with errno set when it is the one to fail.
static int fault(enum kind kind, int under_folder) {
  configure();
  if (!under_folder) return 0;
  const long n = __atomic_add_fetch(&counts[kind], 1, __ATOMIC_SEQ_CST);
  if ((int)kind != fault_kind || n != fault_at) return 0;
  if (fault_kill == SIGKILL) raise(SIGKILL);
  if (fault_kill != 0) {  // the program's own handler decides what comes of it; the call goes on
    raise(fault_kill);
    return 0;
  }
  errno = fault_errno;
  return -1;
}

__attribute__((destructor)) static void write_counts(void) {
  configure();
  if (counts_file == NULL) return;
  FILE* file = fopen(counts_file, "w");
  if (file == NULL) return;
  for (int k = 0; k < k_count; ++k) fprintf(file, "%s %ld\n", kind_names[k], counts[k]);
  fclose(file);
}

#define NEXT(name) ((__typeof__(&name))dlsym(RTLD_NEXT, #name))

static int open_flags_create_or_write(int flags) { return (flags & (O_WRONLY | O_RDWR | O_CREAT)) != 0; }

// The mode argument an open that creates a file passes after its flags (a GNU statement expression).
#define MODE_AFTER(flags)                         \
  __extension__({                                 \
    mode_t mode_ = 0;                             \
    if ((flags) & (O_CREAT | O_TMPFILE)) {        \
      va_list arguments_;                         \
      va_start(arguments_, flags);                \
      mode_ = va_arg(arguments_, mode_t);         \
      va_end(arguments_);                         \
    }                                             \
    mode_;                                        \
  })

int open(const char* path, int flags, ...) {
  const mode_t mode = MODE_AFTER(flags);
  if (open_flags_create_or_write(flags) && fault(k_open, path_is_under(path)) != 0) return -1;
  return NEXT(open)(path, flags, mode);
}

int open64(const char* path, int flags, ...) {
  const mode_t mode = MODE_AFTER(flags);
  if (open_flags_create_or_write(flags) && fault(k_open, path_is_under(path)) != 0) return -1;
  return NEXT(open64)(path, flags, mode);
}

int openat(int folder, const char* path, int flags, ...) {
  const mode_t mode = MODE_AFTER(flags);
  const int counted = folder == AT_FDCWD || (path[0] == '/') ? path_is_under(path) : fd_is_under(folder);
  if (open_flags_create_or_write(flags) && fault(k_open, counted) != 0) return -1;
  return NEXT(openat)(folder, path, flags, mode);
}

ssize_t write(int fd, const void* buffer, size_t size) {
  if (fd > 2 && fault(k_write, fd_is_under(fd)) != 0) return -1;
  return NEXT(write)(fd, buffer, size);
}

int fsync(int fd) {
  if (fault(k_fsync, fd_is_under(fd)) != 0) return -1;
  return NEXT(fsync)(fd);
}

int fdatasync(int fd) {
  if (fault(k_fsync, fd_is_under(fd)) != 0) return -1;
  return NEXT(fdatasync)(fd);
}

int rename(const char* from, const char* to) {
  if (fault(k_rename, path_is_under(to)) != 0) return -1;
  return NEXT(rename)(from, to);
}

int renameat(int from_folder, const char* from, int to_folder, const char* to) {
  const int counted = to_folder == AT_FDCWD || (to[0] == '/') ? path_is_under(to) : fd_is_under(to_folder);
  if (fault(k_rename, counted) != 0) return -1;
  return NEXT(renameat)(from_folder, from, to_folder, to);
}

int link(const char* from, const char* to) {
  if (fault(k_link, path_is_under(to)) != 0) return -1;
  return NEXT(link)(from, to);
}

int mkdir(const char* path, mode_t mode) {
  if (fault(k_mkdir, path_is_under(path)) != 0) return -1;
  return NEXT(mkdir)(path, mode);
}

int unlink(const char* path) {
  if (fault(k_unlink, path_is_under(path)) != 0) return -1;
  return NEXT(unlink)(path);
}

int flock(int fd, int operation) {
  if (fault(k_flock, fd_is_under(fd)) != 0) return -1;
  return NEXT(flock)(fd, operation);
}
