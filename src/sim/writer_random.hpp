#pragma once
// The simulated writer's random draws (private to the sim module): uniform and Gaussian draws made from
// the raw 64-bit stream, so that a seed gives the same writer whatever the standard library, and the
// seeds of its independent streams.
#include <cstdint>
#include <random>

#include "calligraphy/core/geometry.hpp"

namespace calligraphy::writer_detail {

/// A uniform draw in [0, 1) from the top 53 bits of one number of `rng`.
[[nodiscard]] double uniform(std::mt19937_64& rng);

/// Two independent standard normal draws: Box-Muller on two numbers of `rng`.
[[nodiscard]] Vec2 gaussian_pair(std::mt19937_64& rng);

/// The next seed of a SplitMix64 sequence (Steele, Lea & Flood 2014) whose state is `state`: independent
/// seeds for the plan's stream and the hand's noise from one seed.
[[nodiscard]] std::uint64_t split_seed(std::uint64_t& state);

}  // namespace calligraphy::writer_detail
