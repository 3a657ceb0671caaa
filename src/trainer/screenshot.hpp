#pragma once
// Reads the frame just rendered (the back buffer, before the swap) and writes it as PNG (stb_image_write,
// by Sean Barrett, public domain) through write_file_atomically.
#include <string>

namespace calligraphy::trainer {

/// Throws DataError naming the path when the PNG cannot be encoded or written.
void write_framebuffer_png(const std::string& path, int width_px, int height_px);

}  // namespace calligraphy::trainer
