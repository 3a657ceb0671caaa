#pragma once
// The special doubles the hostile cases give the library: NaN, infinity and the smallest denormal.
#include <limits>

namespace calligraphy::testing {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kDenormal = std::numeric_limits<double>::denorm_min();

}  // namespace calligraphy::testing
