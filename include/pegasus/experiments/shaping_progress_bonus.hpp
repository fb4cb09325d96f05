#pragma once
// The progress-bonus bug of thesis §3.1/§3.3, shown by learning. On the §3.4 gridworld, Sarsa learns once
// with the "progress bonus" (+bonus for every step that ends closer to the goal, nothing for a step away)
// and once with the potential-based version of the same hint, Phi(s) = -bonus * manhattan(s, goal), which
// pays +bonus for a step closer and charges bonus for a step away. Each learned greedy policy is then
// followed along its most likely transitions from the start: with the bonus it goes round a cycle, with
// the potential it walks to the goal. (A step away and a step back earn bonus - 2 in all, so with
// gamma = 1 any bonus above 2 makes shuttling pay forever; the potential's F sums to 0 around any cycle.)
// Both policies are also judged exactly in the unshaped MDP: whether they reach the goal with probability 1
// from every state, and their expected steps from the start when they do.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace pegasus {

struct ProgressBonusOptions {
  // Gridworld side n >= 2 (start (0, 0), goal (n-1, n-1), 80/20 moves, -1 per step).
  int size = 10;
  // The bonus for a step that ends closer to the goal. Must be > 0.
  double bonus = 3.0;
  // Sarsa episodes per learner, learning rate, exploration (§3.4: 0.02, 0.1) and discount in [0, 1].
  int episodes = 10000;
  double alpha = 0.02;
  double epsilon = 0.1;
  double gamma = 1.0;
  // Episodes are cut off after this many steps (the bonus learner may never reach the goal). Must be >= 1.
  std::int64_t max_steps_per_episode = 10'000;
  std::uint64_t seed = 1;

  bool IsValid(std::string* error) const;
};

// What one learner ended with.
struct GreedyPolicyOutcome {
  std::string shaping{};       // "progress-bonus" | "potential"
  std::vector<int> path{};     // most likely path of the greedy policy from the start (states)
  std::vector<int> cycle{};    // its cycle, if the path repeats a state instead of reaching the goal
  bool reaches_goal = false;   // the most likely path ends at the goal
  double cycle_shaping = 0.0;  // sum of the learner's shaping reward F around the cycle
  double cycle_reward = 0.0;   // sum of R + F around the cycle (what the learner believes it earns)
  bool proper = false;         // the greedy policy reaches the goal with probability 1 from every state
  std::optional<double> expected_steps{};     // its exact expected steps from the start (when proper)
  std::vector<std::int64_t> episode_steps{};  // learning curve: steps per episode
  int truncated_episodes = 0;
  std::vector<int> policy{};  // the greedy action of every state
};

struct ProgressBonusResult {
  double optimal_expected_steps = 0.0;  // of the unshaped gridworld, exact
  GreedyPolicyOutcome bonus;            // learned with the progress bonus
  GreedyPolicyOutcome potential;        // learned with the potential-based version
};

ProgressBonusResult run_progress_bonus_demo(const ProgressBonusOptions& options);

}  // namespace pegasus
