#pragma once
/// \file sha256.hpp
/// SHA-256 (FIPS 180-4) names a file by its content: a trial record's scene and a replay's teacher recording
/// (trial/recorded_trial.hpp), a study's protocol, session manifest and traces. The digest is OpenSSL's
/// libcrypto (EVP interface), linked by the library.
#include <string>
#include <string_view>

namespace calligraphy {

/// Lower-case hex SHA-256 of `bytes` (FIPS 180-4).
[[nodiscard]] std::string sha256_hex(std::string_view bytes);

/// True when `text` is a digest as sha256_hex writes it: 64 lower-case hex digits.
[[nodiscard]] bool is_sha256_hex(std::string_view text) noexcept;

}  // namespace calligraphy
