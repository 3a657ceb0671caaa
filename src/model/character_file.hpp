#pragma once
// Reads one character file with a size bound, refusing anything but a regular file. Internal.
#include <cstddef>
#include <filesystem>
#include <string>

namespace calligraphy::detail {

/// The bytes of `path`. Opens without blocking (O_NONBLOCK), so that a FIFO or a device named like a
/// character file is refused at once. Throws CharacterNotFound when there is no such file (naming the
/// character and the path), DataError naming the path when it is not a regular file, is larger than
/// `max_bytes` or cannot be read.
std::string read_character_file(const std::filesystem::path& path, char32_t code_point,
                                std::size_t max_bytes);

}  // namespace calligraphy::detail
