// SHA-256 (FIPS 180-4) names a file by its content (sha256.hpp). The digest is OpenSSL's libcrypto (EVP
// interface), not our own.
#include "calligraphy/core/sha256.hpp"

#include <openssl/evp.h>

#include <array>
#include <span>
#include <string>
#include <string_view>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/printable_text.hpp"

namespace calligraphy {

std::string sha256_hex(std::string_view bytes) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr) != 1 ||
      length != 32) {
    throw Error("SHA-256: OpenSSL's EVP_Digest failed");
  }
  return lower_hex(std::span<const unsigned char>(digest.data(), length));
}

bool is_sha256_hex(std::string_view text) noexcept {
  return text.size() == 64 && text.find_first_not_of("0123456789abcdef") == std::string_view::npos;
}

}  // namespace calligraphy
