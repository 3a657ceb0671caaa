#pragma once
// Reading the Markdown document into which `calligraphy bench nearest --markdown FILE` and `bench jumps
// --markdown FILE` splice their generated sections (docs/nearest-point.md).
#include <cstdint>
#include <string>

namespace calligraphy::cli {

/// The largest document `read_generated_document` accepts: 4 MiB, some hundred times the size of
/// docs/nearest-point.md with its tables.
inline constexpr std::uintmax_t kMaxGeneratedDocumentBytes = std::uintmax_t{4} << 20;

/// The bytes of the Markdown file at `path`, or "" when nothing exists there (a new document).
/// Throws InvalidArgument naming `path` when it exists but is not a regular file (a directory, a
/// device such as /dev/zero, a FIFO) or holds more than `max_bytes` bytes (also when it grows past
/// that while being read), and Error naming `path` when it cannot be opened or read. Never reads more
/// than `max_bytes` + 1 bytes, so an endless or huge file cannot exhaust memory.
std::string read_generated_document(const std::string& path,
                                    std::uintmax_t max_bytes = kMaxGeneratedDocumentBytes);

}  // namespace calligraphy::cli
