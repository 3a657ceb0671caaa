#pragma once
// The whole hanzi-writer-data package for tests that draw characters the engine was not tuned on:
// CALLIGRAPHY_CORPUS_DIR (scripts/test.sh sets it from scripts/fetch-hanzi-writer-data.sh), else the
// fetch script's default cache folder, else (said on standard output) the 121-character sample in tests/data.
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace calligraphy::testing {

inline std::filesystem::path corpus_folder() {
  if (const char* set = std::getenv("CALLIGRAPHY_CORPUS_DIR"); set != nullptr && *set != '\0') return set;
  if (const char* home = std::getenv("HOME"); home != nullptr) {
    const std::filesystem::path cached =
        std::filesystem::path(home) / ".cache/calligraphy/hanzi-writer-data-2.0.1";
    if (std::filesystem::is_directory(cached)) return cached;
  }
  std::cout << "no hanzi-writer-data package (run scripts/fetch-hanzi-writer-data.sh and set "
               "CALLIGRAPHY_CORPUS_DIR): using the sample in tests/data\n";
  return std::filesystem::path(CALLIGRAPHY_SOURCE_DIR) / "tests/data/hanzi-writer-sample";
}

}  // namespace calligraphy::testing
