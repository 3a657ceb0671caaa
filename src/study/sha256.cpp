// SHA-256 (FIPS 180-4) names a protocol file and a teacher's recording by their content. The digest is
// OpenSSL's libcrypto (EVP interface), not our own.
#include <openssl/evp.h>

#include <array>
#include <string>
#include <string_view>

#include "calligraphy/core/errors.hpp"
#include "calligraphy/study/protocol.hpp"

namespace calligraphy {

std::string sha256_hex(std::string_view bytes) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr) != 1 ||
      length != 32) {
    throw Error("SHA-256: OpenSSL's EVP_Digest failed");
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    out.push_back(kHex[digest[i] >> 4]);
    out.push_back(kHex[digest[i] & 0xf]);
  }
  return out;
}

}  // namespace calligraphy
