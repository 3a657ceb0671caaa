#include "sim/writer_random.hpp"

#include <cmath>
#include <numbers>

namespace calligraphy::writer_detail {

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

// Our own Box-Muller rather than std::normal_distribution, whose draws differ between libraries.
Vec2 gaussian_pair(std::mt19937_64& rng) {
  const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53;  // in (0, 1): the log stays finite
  const double u2 = uniform(rng);
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  return radius * Vec2(std::cos(angle), std::sin(angle));
}

std::uint64_t split_seed(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace calligraphy::writer_detail
