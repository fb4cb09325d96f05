#include "pegasus/experiments/shaping_progress_bonus.hpp"

#include <fmt/format.h>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/learners.hpp"
#include "pegasus/mdp/policy_paths.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/random/block_stream.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

// The MDP that always takes policy[s]: one action per state.
FiniteMdp restrict_to_policy(const FiniteMdp& m, const std::vector<int>& policy) {
  FiniteMdpBuilder b(m.num_states, 1, m.gamma);
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) {
      b.set_absorbing(s);
      continue;
    }
    const std::size_t r = m.row(s, policy[static_cast<std::size_t>(s)]);
    for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
      b.add_transition(s, 0, m.next_state[k], m.probability[k], m.reward[k]);
  }
  for (int s = 0; s < m.num_states; ++s)
    if (m.initial[static_cast<std::size_t>(s)] > 0.0)
      b.set_initial(s, m.initial[static_cast<std::size_t>(s)]);
  return b.build();
}

template <TabularModel M>
GreedyPolicyOutcome learn_and_follow(const M& model, const GridWorld& world, const FiniteMdp& mdp,
                                     const ProgressBonusOptions& o, std::string name) {
  const TdOptions td{.episodes = o.episodes,
                     .alpha = o.alpha,
                     .epsilon = o.epsilon,
                     .gamma = o.gamma,
                     .max_steps_per_episode = o.max_steps_per_episode};
  // Both learners see the same random numbers (common random numbers): only the shaping differs.
  BlockUniformStream rng(o.seed, 0);
  QTable q(model.num_states(), model.num_actions(), 0.0);
  const LearningCurve curve = sarsa(model, td, rng, q);

  GreedyPolicyOutcome out;
  out.shaping = std::move(name);
  out.policy = q.greedy_policy();
  out.episode_steps = curve.steps;
  out.truncated_episodes = curve.truncated_episodes;
  const PolicyPath path = most_likely_path(mdp, out.policy, world.start());
  out.path = path.states;
  out.cycle = path.cycle();
  out.reaches_goal = path.reaches_absorbing;
  for (std::size_t i = 0; i < out.cycle.size(); ++i) {
    const int s = out.cycle[i], next = out.cycle[(i + 1) % out.cycle.size()];
    const int a = out.policy[static_cast<std::size_t>(s)];
    out.cycle_shaping += model.shaping(s, a, next);
    out.cycle_reward += model.reward(s, a, next);
  }
  // Judged in the unshaped, undiscounted MDP: does it reach the goal, and how fast?
  const FiniteMdp fixed = restrict_to_policy(mdp, out.policy);
  out.proper = !find_improper_state(fixed).has_value();
  if (out.proper)
    out.expected_steps = -evaluate_policy(mdp, out.policy)[static_cast<std::size_t>(world.start())];
  return out;
}

}  // namespace

bool ProgressBonusOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (size < 2 || size > 1000)
    return fail(fmt::format("size: expected a gridworld side in [2, 1000], got {}", size));
  if (!(bonus > 0.0 && bonus < 1e9))
    return fail(fmt::format("bonus: expected a number in (0, 1e9), got {}", bonus));
  if (episodes < 1 || episodes > 10'000'000)
    return fail(fmt::format("episodes: expected an integer in [1, 10000000], got {}", episodes));
  if (!(alpha > 0.0 && alpha <= 1.0))
    return fail(fmt::format("alpha: expected a number in (0, 1], got {}", alpha));
  if (!(epsilon >= 0.0 && epsilon <= 1.0))
    return fail(fmt::format("epsilon: expected a number in [0, 1], got {}", epsilon));
  if (!(gamma >= 0.0 && gamma <= 1.0))
    return fail(fmt::format("gamma: expected a number in [0, 1], got {}", gamma));
  if (max_steps_per_episode < 1)
    return fail(
        fmt::format("max_steps_per_episode: expected an integer >= 1, got {}", max_steps_per_episode));
  return true;
}

ProgressBonusResult run_progress_bonus_demo(const ProgressBonusOptions& o) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  const GridWorld world = corner_gridworld(o.size);
  const FiniteMdp mdp = to_finite_mdp(world, 1.0);
  std::vector<double> distance(static_cast<std::size_t>(world.num_states())), phi(distance.size());
  for (int s = 0; s < world.num_states(); ++s) {
    distance[static_cast<std::size_t>(s)] = world.distance_to_goal(s);
    phi[static_cast<std::size_t>(s)] = -o.bonus * world.distance_to_goal(s);
  }

  ProgressBonusResult result;
  result.optimal_expected_steps = -expected_under_initial(mdp, value_iteration(mdp).value);
  result.bonus = learn_and_follow(ProgressBonusModel(world, TablePotential{distance}, o.bonus), world, mdp, o,
                                  "progress-bonus");
  result.potential = learn_and_follow(shape(world, TablePotential{phi}, o.gamma), world, mdp, o, "potential");
  return result;
}

}  // namespace pegasus
