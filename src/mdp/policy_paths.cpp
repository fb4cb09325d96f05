#include "pegasus/mdp/policy_paths.hpp"

#include <fmt/format.h>

#include "pegasus/core/error.hpp"

namespace pegasus {

PolicyPath most_likely_path(const FiniteMdp& m, std::span<const int> policy, int start, int max_length) {
  if (policy.size() != static_cast<std::size_t>(m.num_states))
    throw InputError(fmt::format("policy path: expected {} actions, got {}", m.num_states, policy.size()));
  if (start < 0 || start >= m.num_states)
    throw InputError(fmt::format("policy path: start state {} outside [0, {})", start, m.num_states));
  PolicyPath path;
  std::vector<int> seen_at(static_cast<std::size_t>(m.num_states), -1);
  int s = start;
  while (static_cast<int>(path.states.size()) < max_length) {
    if (seen_at[static_cast<std::size_t>(s)] >= 0) {
      path.cycle_start = seen_at[static_cast<std::size_t>(s)];
      break;
    }
    seen_at[static_cast<std::size_t>(s)] = static_cast<int>(path.states.size());
    path.states.push_back(s);
    if (m.is_absorbing(s)) {
      path.reaches_absorbing = true;
      break;
    }
    const int a = policy[static_cast<std::size_t>(s)];
    if (a < 0 || a >= m.num_actions)
      throw InputError(
          fmt::format("policy path: action {} of state {} outside [0, {})", a, s, m.num_actions));
    const std::size_t r = m.row(s, a);
    std::uint32_t best = m.row_start[r];
    for (std::uint32_t k = m.row_start[r] + 1; k < m.row_start[r + 1]; ++k)
      if (m.probability[k] > m.probability[best]) best = k;
    s = m.next_state[best];
  }
  return path;
}

}  // namespace pegasus
