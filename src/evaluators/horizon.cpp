#include "pegasus/evaluators/horizon.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"

namespace pegasus {

std::int64_t epsilon_horizon(double gamma, double epsilon, double rmax) {
  if (!(gamma > 0 && gamma < 1))
    throw InputError(fmt::format("gamma: expected a number in (0, 1), got {}", gamma));
  if (!(epsilon > 0) || std::isinf(epsilon)) {
    throw InputError(fmt::format("epsilon: expected a finite number > 0, got {}", epsilon));
  }
  if (!(rmax > 0) || std::isinf(rmax))
    throw InputError(fmt::format("rmax: expected a finite number > 0, got {}", rmax));
  // §4.2.2: log_gamma(x) = ln x / ln gamma; log1p keeps ln gamma accurate for gamma near 1.
  const double h = std::ceil(std::log(epsilon * (1 - gamma) / (2 * rmax)) / std::log1p(gamma - 1));
  constexpr double kMax = 9007199254740992.0;  // 2^53
  if (!(h <= kMax)) {
    throw InputError(
        fmt::format("gamma: {} is too close to 1: the epsilon-horizon exceeds 2^53 steps", gamma));
  }
  return h < 1 ? 1 : static_cast<std::int64_t>(h);
}

}  // namespace pegasus
