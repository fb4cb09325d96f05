#pragma once
// The bound on a task's reward weights, shaping rates and penalties, shared by every task's IsValid and by
// the CLI's option ranges.

namespace pegasus {

// The largest reward weight, shaping rate or fall penalty (in magnitude) a task takes: with errors inside any
// crash envelope, a rollout of 10^5 steps then keeps a finite return (at 1e308 the returns overflowed to inf
// or NaN and training ended as if it had worked).
inline constexpr double kMaxRewardWeight = 1e12;

}  // namespace pegasus
