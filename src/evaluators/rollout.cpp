#include "pegasus/evaluators/rollout.hpp"

#include <fmt/format.h>

namespace pegasus {

void validate(const Discounting& d) {
  if (!(d.gamma >= 0.0 && d.gamma <= 1.0))
    throw InputError(fmt::format("gamma: expected a number in [0, 1], got {}", d.gamma));
  if (d.horizon < 1) throw InputError(fmt::format("horizon: expected an integer >= 1, got {}", d.horizon));
}

}  // namespace pegasus
