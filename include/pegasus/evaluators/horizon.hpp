#pragma once
// How far to roll out so that truncating the discounted sum costs at most epsilon / 2 (thesis §4.2.2):
//   H_eps = ceil( log_gamma( eps (1 - gamma) / (2 Rmax) ) ),
// since the rewards after step H add up to at most gamma^H Rmax / (1 - gamma).
#include <cstdint>

namespace pegasus {

// gamma in (0, 1), epsilon > 0, rmax > 0 (largest |reward|), else InputError naming the parameter.
// At least 1 (a rollout has one step even when epsilon / 2 exceeds every possible return); InputError when
// the horizon would exceed 2^53 (gamma too close to 1 for a finite rollout).
std::int64_t epsilon_horizon(double gamma, double epsilon, double rmax);

}  // namespace pegasus
