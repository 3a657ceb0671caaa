#pragma once
// Reading a whole input file of bounded size: a trace, a recording. Internal.
#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "calligraphy/core/errors.hpp"

namespace calligraphy {

/// The error for an input file that is not there: "NAME: no such file", then `expected` ("a study
/// protocol") in brackets when given. An input named `-` is a file of that name, never standard input, and
/// its error says so: every reader of a file a command is given says it the same way.
[[nodiscard]] DataError no_such_file(const std::filesystem::path& path, const std::string& expected = "");

/// The error for an input whose std::filesystem::status found nothing (`error`, as status set it): a
/// symbolic link that leads back to itself exists and is named as a loop, anything else as no_such_file.
[[nodiscard]] DataError missing_input(const std::filesystem::path& path, const std::error_code& error,
                                      const std::string& expected = "");

/// The size of the regular file `path`, for a reader that streams it. Throws DataError naming the path when
/// it does not exist, is not a regular file, or is larger than `max_bytes`.
[[nodiscard]] std::uintmax_t regular_file_size(const std::filesystem::path& path, std::uintmax_t max_bytes);

/// The bytes of the regular file `path`, read to its end (a /proc file, whose size stat(2) gives as 0, too).
/// Throws DataError naming the path when it does not exist, is not a regular file (a device or FIFO is never
/// read), is larger than `max_bytes` (or grows past it while read), or cannot be read whole.
[[nodiscard]] std::string read_regular_file(const std::filesystem::path& path, std::uintmax_t max_bytes);

/// What a file that is not regular is, for messages: "a directory", "a FIFO", "a character device", ...
/// (`mode` as stat(2) gives it). Static storage.
[[nodiscard]] const char* file_kind(mode_t mode) noexcept;

}  // namespace calligraphy
