#include "trainer/screenshot.hpp"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "calligraphy/core/atomic_file.hpp"
#include "calligraphy/core/errors.hpp"

namespace calligraphy::trainer {
namespace {

void append(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

void write_framebuffer_png(const std::string& path, int width_px, int height_px) {
  const std::size_t row = static_cast<std::size_t>(width_px) * 4;
  std::vector<std::uint8_t> pixels(row * static_cast<std::size_t>(height_px));
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width_px, height_px, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  for (std::size_t i = 3; i < pixels.size(); i += 4) pixels[i] = 255;  // an opaque picture
  // OpenGL's rows run bottom-up, PNG's top-down.
  std::vector<std::uint8_t> flipped(pixels.size());
  for (std::size_t y = 0; y < static_cast<std::size_t>(height_px); ++y) {
    std::copy_n(pixels.data() + (static_cast<std::size_t>(height_px) - 1 - y) * row, row,
                flipped.data() + y * row);
  }
  std::vector<std::uint8_t> png;
  const int ok =
      stbi_write_png_to_func(append, &png, width_px, height_px, 4, flipped.data(), static_cast<int>(row));
  if (ok == 0 || png.empty()) throw DataError(path + ": cannot encode the screenshot as PNG");
  write_file_atomically(path, std::span<const std::uint8_t>(png));
}

}  // namespace calligraphy::trainer
