#pragma once
// Random finite MDPs for property tests and benchmarks, drawn from an explicitly passed stream.
#include <string>

#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

struct RandomMdpOptions {
  // Number of states, including the absorbing one when `episodic`. Must be >= 2.
  int num_states = 10;
  // Number of actions. Must be >= 1.
  int num_actions = 3;
  // Successors per (s, a), drawn without replacement (num_states: dense rows). Must be in [1, num_states].
  int successors = 3;
  // Discount in [0, 1]. gamma = 1 forces `episodic`.
  double gamma = 0.9;
  // Make the last state absorbing and every other state reach it with probability 1 under every policy:
  // a row either leaks to it with probability >= 0.05 or moves only to higher-numbered states, so no
  // policy can loop forever (the MDP is proper, §2.1).
  bool episodic = false;
  // Rewards R(s, a, s') uniform in [reward_min, reward_max].
  double reward_min = -1.0;
  double reward_max = 1.0;

  bool IsValid(std::string* error) const;
};

FiniteMdp random_mdp(const RandomMdpOptions& options, UniformStream& rng);

}  // namespace pegasus
