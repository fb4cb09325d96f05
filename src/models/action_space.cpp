#include "pegasus/models/action_space.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "pegasus/core/error.hpp"

namespace pegasus {

ActionSpace ActionSpace::finite(int count) {
  if (count < 1) throw InputError(fmt::format("action space: expected at least 1 action, got {}", count));
  ActionSpace s;
  s.count_ = count;
  return s;
}

ActionSpace ActionSpace::box(std::vector<double> low, std::vector<double> high) {
  if (low.empty() || low.size() != high.size())
    throw InputError("action space: expected box bounds of equal, non-zero length");
  for (std::size_t i = 0; i < low.size(); ++i)
    if (!(low[i] <= high[i]))
      throw InputError(fmt::format("action space: expected low[{0}] <= high[{0}]", i));
  ActionSpace s;
  s.low_ = std::move(low);
  s.high_ = std::move(high);
  return s;
}

std::string ActionSpace::describe() const {
  if (is_finite()) return fmt::format("{} discrete actions", count_);
  return fmt::format("box [{}] x [{}]", fmt::join(low_, ", "), fmt::join(high_, ", "));
}

}  // namespace pegasus
