#pragma once
// Following a deterministic policy along its most likely transitions: the path a greedy agent "intends"
// to take. Used to show the progress-bonus bug of §3.1 (a policy that cycles instead of reaching the
// goal) and to print learned routes.
#include <span>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"

namespace pegasus {

struct PolicyPath {
  std::vector<int> states;  // start, then each most likely successor, without the repeated state
  int cycle_start = -1;     // index in `states` where the path starts repeating (-1: no cycle)
  bool reaches_absorbing = false;
  // The states of the cycle, in order (empty when there is none).
  std::vector<int> cycle() const {
    return cycle_start < 0 ? std::vector<int>{}
                           : std::vector<int>(states.begin() + cycle_start, states.end());
  }
};

// From `start`, repeatedly takes policy[s] and moves to its most probable successor (lowest state on ties)
// until an absorbing state, a repeated state, or max_length states. Throws InputError on bad input.
PolicyPath most_likely_path(const FiniteMdp& mdp, std::span<const int> policy, int start,
                            int max_length = 1 << 20);

}  // namespace pegasus
