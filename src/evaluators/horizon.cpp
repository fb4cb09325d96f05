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
  // §4.2.2: log_gamma(x) = ln x / ln gamma; log1p keeps ln gamma accurate for gamma near 1. The logarithm
  // of the product is taken as a sum, so that a tiny epsilon (4.9e-324) cannot underflow it to ln 0.
  const double h = std::ceil((std::log(epsilon) + std::log1p(-gamma) - std::log(2.0) - std::log(rmax)) /
                             std::log1p(gamma - 1));
  constexpr double kMax = 9007199254740992.0;  // 2^53
  if (!(h <= kMax)) {
    throw InputError(
        fmt::format("gamma: {} with epsilon {} and rmax {}: expected an epsilon-horizon of at most 2^53 "
                    "steps, got {:.3g}",
                    gamma, epsilon, rmax, h));
  }
  return h < 1 ? 1 : static_cast<std::int64_t>(h);
}

}  // namespace pegasus
