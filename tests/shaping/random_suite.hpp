#pragma once
// The random MDPs the shaping property tests run over: several sizes, action counts, sparsities and
// discounts, continuing and episodic, including proper undiscounted ones (gamma = 1).
#include <algorithm>
#include <cmath>
#include <vector>

#include "pegasus/mdp/random_mdp.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus::test_support {

inline RandomMdpOptions suite_options(int i) {
  static constexpr int kStates[] = {2, 3, 5, 8, 13, 21, 34};
  static constexpr double kGammas[] = {0.0, 0.5, 0.9, 0.99, 1.0};
  RandomMdpOptions o;
  o.num_states = kStates[i % 7];
  o.num_actions = 2 + (i / 7) % 3;
  const int k = (i / 3) % 4;
  o.successors = k == 3 ? o.num_states : std::min(o.num_states, 1 + k);
  o.gamma = kGammas[(i / 2) % 5];
  o.episodic = o.gamma == 1.0 || i % 2 == 1;
  o.reward_min = -1.0;
  o.reward_max = 1.0;
  return o;
}

// The i-th MDP of the suite; the same for every test.
inline FiniteMdp suite_mdp(int i) {
  UniformStream rng(20260, static_cast<std::uint32_t>(i));
  return random_mdp(suite_options(i), rng);
}

// A random potential in [-scale, scale], 0 at absorbing states.
inline std::vector<double> random_potential(const FiniteMdp& m, UniformStream& rng, double scale = 5.0) {
  std::vector<double> phi(static_cast<std::size_t>(m.num_states));
  for (int s = 0; s < m.num_states; ++s)
    phi[static_cast<std::size_t>(s)] = m.is_absorbing(s) ? 0.0 : scale * (2.0 * rng.next() - 1.0);
  return phi;
}

inline double max_abs(const std::vector<double>& v) {
  double x = 0.0;
  for (double y : v) x = std::max(x, std::abs(y));
  return x;
}

// Bitmask of the optimal actions per state, with a tie tolerance relative to the Q scale.
inline std::vector<std::uint64_t> optimal_action_sets(const FiniteMdp& m, const std::vector<double>& q) {
  return near_optimal_actions(m, q, 1e-7 * (1.0 + max_abs(q)));
}

inline constexpr int kSuiteSize = 1050;

}  // namespace pegasus::test_support
