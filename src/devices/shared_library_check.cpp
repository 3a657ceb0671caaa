#include "devices/shared_library_check.hpp"

#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "core/whole_file.hpp"

namespace calligraphy::devices {
namespace {

#if defined(__x86_64__)
constexpr int kHostMachine = EM_X86_64;
#elif defined(__aarch64__)
constexpr int kHostMachine = EM_AARCH64;
#else
constexpr int kHostMachine = -1;  // not checked
#endif

// Closes a file descriptor on every way out.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

bool read_exactly(int fd, void* out, std::size_t bytes, off_t offset) {
  auto* at = static_cast<char*>(out);
  while (bytes > 0) {
    const ssize_t got = ::pread(fd, at, bytes, offset);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    at += got;
    offset += got;
    bytes -= static_cast<std::size_t>(got);
  }
  return true;
}

std::string errno_text(int error) { return std::strerror(error); }

}  // namespace

std::string shared_library_problem(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return errno_text(errno);
  if (!S_ISREG(info.st_mode)) return std::string(file_kind(info.st_mode)) + ", not a shared library";
  if (info.st_size == 0) return "an empty file, not a shared library";
  const auto size = static_cast<std::uint64_t>(info.st_size);
  // O_NONBLOCK: the file was regular a moment ago, but it must not block if it was swapped for a FIFO.
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) return "cannot be read: " + errno_text(errno);
  Elf64_Ehdr header{};
  if (size < sizeof header || !read_exactly(fd.get(), &header, sizeof header, 0))
    return "too short for an ELF header (" + std::to_string(size) + " bytes): truncated or not a library";
  if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0) return "not an ELF file (no ELF magic number)";
  if (header.e_ident[EI_CLASS] != ELFCLASS64) return "not a 64-bit ELF file";
  if (header.e_ident[EI_DATA] != ELFDATA2LSB) return "not a little-endian ELF file";
  if (header.e_type != ET_DYN) return "an ELF file, but not a shared object";
  if (kHostMachine >= 0 && header.e_machine != kHostMachine)
    return "a shared object for another processor (ELF machine " + std::to_string(header.e_machine) + ")";
  if (header.e_phentsize != sizeof(Elf64_Phdr) || header.e_phnum == 0)
    return "damaged: no valid program header table";
  const std::uint64_t table_end = header.e_phoff + std::uint64_t{header.e_phnum} * sizeof(Elf64_Phdr);
  if (header.e_phoff > size || table_end > size)
    return "truncated: its program header table ends at byte " + std::to_string(table_end) + " of a " +
           std::to_string(size) + "-byte file";
  std::vector<Elf64_Phdr> segments(header.e_phnum);
  if (!read_exactly(fd.get(), segments.data(), segments.size() * sizeof(Elf64_Phdr),
                    static_cast<off_t>(header.e_phoff)))
    return "cannot read its program header table";
  bool dynamic = false;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Elf64_Phdr& segment = segments[i];
    dynamic = dynamic || segment.p_type == PT_DYNAMIC;
    if (segment.p_type != PT_LOAD && segment.p_type != PT_DYNAMIC) continue;
    const std::uint64_t end = segment.p_offset + segment.p_filesz;
    if (end < segment.p_offset || end > size)
      return "truncated: segment " + std::to_string(i) + " ends at byte " + std::to_string(end) + " of a " +
             std::to_string(size) + "-byte file";
  }
  if (!dynamic) return "damaged: a shared object without a dynamic segment";
  if (header.e_shoff != 0) {
    const std::uint64_t sections_end = header.e_shoff + std::uint64_t{header.e_shnum} * header.e_shentsize;
    if (sections_end > size)
      return "truncated: its section header table ends at byte " + std::to_string(sections_end) + " of a " +
             std::to_string(size) + "-byte file";
  }
  return {};
}

std::string probe_shared_library(const std::string& path, const char* required_symbol, double timeout_s) {
  std::array<int, 2> pipe_ends{};
  if (::pipe2(pipe_ends.data(), O_CLOEXEC) != 0) return "cannot probe: pipe: " + errno_text(errno);
  const pid_t child = ::fork();
  if (child < 0) {
    const int error = errno;
    ::close(pipe_ends[0]);
    ::close(pipe_ends[1]);
    return "cannot probe: fork: " + errno_text(error);
  }
  if (child == 0) {  // only async-signal-safe calls and dlopen itself from here; _exit, never exit
    ::close(pipe_ends[0]);
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = ::dlerror();
      if (why != nullptr) static_cast<void>(::write(pipe_ends[1], why, std::strlen(why)));
      ::_exit(1);
    }
    ::_exit(required_symbol != nullptr && ::dlsym(handle, required_symbol) == nullptr ? 2 : 0);
  }
  ::close(pipe_ends[1]);
  const FileDescriptor reader(pipe_ends[0]);
  std::string loader_message;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (true) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0 && errno != EINTR) return "cannot probe: waitpid: " + errno_text(errno);
    if (std::chrono::steady_clock::now() > give_up) {
      ::kill(child, SIGKILL);
      while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return "loading it did not finish within " + std::to_string(static_cast<int>(timeout_s)) +
             " s in a test process (killed)";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::array<char, 512> buffer{};
  ssize_t got = 0;
  while ((got = ::read(reader.get(), buffer.data(), buffer.size())) > 0)
    loader_message.append(buffer.data(), static_cast<std::size_t>(got));
  if (WIFSIGNALED(status)) {
    const int signal_number = WTERMSIG(status);
    const char* name = ::sigabbrev_np(signal_number);
    return std::string("loading it killed a test process with SIG") + (name != nullptr ? name : "?") + " (" +
           std::to_string(signal_number) + "): the file is damaged";
  }
  if (WIFEXITED(status)) {
    switch (WEXITSTATUS(status)) {
      case 0:
        return {};
      case 1:
        return loader_message.empty() ? std::string("not loadable") : loader_message;
      case 2:
        return std::string("loaded, but lacks ") + required_symbol;
      default:
        break;
    }
  }
  return "a test process loading it ended with status " + std::to_string(status);
}

}  // namespace calligraphy::devices
