#pragma once
// The small helpers of the library's validators, which answer bool and say why through an optional
// out-parameter (`std::string* error`). Internal: not installed.
#include <cmath>
#include <string>
#include <utility>

#include "pegasus/core/reward_limits.hpp"

namespace pegasus::detail {

// Stores `message` where the caller asked for it (error may be nullptr) and returns false.
inline bool fail(std::string* error, std::string message) {
  if (error != nullptr) *error = std::move(message);
  return false;
}

inline bool positive_finite(double x) { return x > 0 && std::isfinite(x); }
inline bool nonnegative_finite(double x) { return x >= 0 && std::isfinite(x); }
// A reward weight, shaping rate or penalty magnitude: in [0, kMaxRewardWeight].
inline bool reward_weight(double x) { return x >= 0 && x <= kMaxRewardWeight; }

}  // namespace pegasus::detail
