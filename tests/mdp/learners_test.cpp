#include "pegasus/mdp/learners.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/random/block_stream.hpp"

namespace pegasus {
namespace {

// Expected steps to the goal of a deterministic policy, exactly (V = -steps with -1 per step).
double expected_steps(const GridWorld& w, const std::vector<int>& policy) {
  const FiniteMdp m = to_finite_mdp(w);
  return -evaluate_policy(m, policy)[static_cast<std::size_t>(w.start())];
}

double optimal_steps(const GridWorld& w) {
  const FiniteMdp m = to_finite_mdp(w);
  return -policy_iteration(m).value[static_cast<std::size_t>(w.start())];
}

TEST(EpsilonGreedy, BreaksTiesUniformlyAndExploresWithProbabilityEpsilon) {
  BlockUniformStream rng(1, 0);
  const double q[4] = {1.0, 3.0, 3.0, 0.0};
  std::array<int, 4> count{};
  const int n = 200000;
  for (int i = 0; i < n; ++i) ++count[static_cast<std::size_t>(epsilon_greedy(q, 4, 0.2, rng))];
  // Greedy actions 1 and 2 share 0.8; exploration adds 0.05 to each action.
  EXPECT_NEAR(count[0] / double(n), 0.05, 0.005);
  EXPECT_NEAR(count[1] / double(n), 0.45, 0.005);
  EXPECT_NEAR(count[2] / double(n), 0.45, 0.005);
  EXPECT_NEAR(count[3] / double(n), 0.05, 0.005);
}

TEST(Learners, SarsaLearnsANearOptimalGridworldPolicy) {
  const GridWorld w = corner_gridworld(5);
  BlockUniformStream rng(5, 0);
  QTable q(w.num_states(), w.num_actions());
  TdOptions o;
  o.episodes = 3000;
  o.alpha = 0.1;
  const auto curve = sarsa(w, o, rng, q);
  EXPECT_EQ(curve.steps.size(), 3000u);
  EXPECT_EQ(curve.truncated_episodes, 0);
  EXPECT_LT(expected_steps(w, q.greedy_policy()), 1.05 * optimal_steps(w));
  // Later episodes are shorter than the first ones.
  EXPECT_LT(curve.steps.back() + curve.steps[curve.steps.size() - 2], curve.steps[0] + curve.steps[1]);
}

TEST(Learners, QLearningLearnsANearOptimalGridworldPolicy) {
  const GridWorld w = corner_gridworld(5);
  UniformStream rng(6, 0);  // any UniformSource works
  QTable q(w.num_states(), w.num_actions());
  TdOptions o;
  o.episodes = 3000;
  o.alpha = 0.1;
  q_learning(w, o, rng, q);
  EXPECT_LT(expected_steps(w, q.greedy_policy()), 1.05 * optimal_steps(w));
}

TEST(Learners, SarsaLambdaWithReplacingTracesLearnsANearOptimalGridworldPolicy) {
  const GridWorld w = corner_gridworld(5);
  BlockUniformStream rng(7, 0);
  QTable q(w.num_states(), w.num_actions());
  TdOptions o;
  o.episodes = 1500;
  o.alpha = 0.05;
  o.lambda = 0.8;
  sarsa_lambda(w, o, rng, q);
  EXPECT_LT(expected_steps(w, q.greedy_policy()), 1.05 * optimal_steps(w));
}

TEST(Learners, SarsaLambdaWithZeroLambdaIsSarsa) {
  const GridWorld w = corner_gridworld(4);
  TdOptions o;
  o.episodes = 50;
  o.alpha = 0.1;
  o.lambda = 0.0;
  o.trace_cutoff = 0.0;
  BlockUniformStream r1(8, 0), r2(8, 0);
  QTable q1(w.num_states(), 4), q2(w.num_states(), 4);
  const auto c1 = sarsa(w, o, r1, q1);
  const auto c2 = sarsa_lambda(w, o, r2, q2);
  EXPECT_EQ(c1.steps, c2.steps);
  for (std::size_t i = 0; i < q1.q.size(); ++i) EXPECT_NEAR(q1.q[i], q2.q[i], 1e-12);
}

TEST(Learners, RunsAreReproducibleFromTheSeed) {
  const GridWorld w = corner_gridworld(6);
  TdOptions o;
  o.episodes = 20;
  BlockUniformStream r1(9, 2), r2(9, 2);
  QTable q1(w.num_states(), 4), q2(w.num_states(), 4);
  EXPECT_EQ(sarsa(w, o, r1, q1).steps, sarsa(w, o, r2, q2).steps);
  EXPECT_EQ(q1.q, q2.q);
}

TEST(Learners, InterleavedSarsaRunsMatchSeparateRuns) {
  const GridWorld w = corner_gridworld(8);
  TdOptions o;
  o.episodes = 30;
  o.max_steps_per_episode = 500;  // some episodes are truncated, exercising that path too
  std::vector<BlockUniformStream> rngs;
  std::vector<QTable> qs;
  for (std::uint32_t i = 0; i < 6; ++i) {  // one full group of four and a partial one
    rngs.emplace_back(13, i);
    qs.emplace_back(w.num_states(), 4);
  }
  const auto curves = sarsa_runs(w, o, std::span(rngs), std::span(qs));
  for (std::uint32_t i = 0; i < 6; ++i) {
    BlockUniformStream rng(13, i);
    QTable q(w.num_states(), 4);
    const auto c = sarsa(w, o, rng, q);
    EXPECT_EQ(curves[i].steps, c.steps);
    EXPECT_EQ(curves[i].returns, c.returns);
    EXPECT_EQ(curves[i].truncated_episodes, c.truncated_episodes);
    EXPECT_EQ(qs[i].q, q.q);
    EXPECT_EQ(rngs[i].position(), rng.position());
  }
}

TEST(Learners, EpisodeCapTruncatesAndIsCounted) {
  const GridWorld w = corner_gridworld(20);
  TdOptions o;
  o.episodes = 3;
  o.max_steps_per_episode = 10;
  BlockUniformStream rng(10, 0);
  QTable q(w.num_states(), 4);
  const auto c = sarsa(w, o, rng, q);
  EXPECT_EQ(c.truncated_episodes, 3);
  EXPECT_EQ(c.total_steps, 30);
  o.alpha = 0.0;
  EXPECT_THROW(sarsa(w, o, rng, q), InputError);
  QTable wrong(3, 4);
  o.alpha = 0.1;
  EXPECT_THROW(sarsa(w, o, rng, wrong), InputError);
}

// The single-step MDP of §2.3: from s0 pick one of three actions, get R(s0, a_i), end.
FiniteMdp bandit() {
  FiniteMdpBuilder b(2, 3, 1.0);
  b.set_absorbing(1);
  for (int a = 0; a < 3; ++a) b.add_transition(0, a, 1, 1.0, 1.0 + a);
  b.set_initial(0, 1.0);
  return b.build();
}

TEST(Learners, ReinforceClimbsTowardsTheBestActionOfTheSection23Bandit) {
  const FiniteMdp m = bandit();
  const MdpModel model(m);
  BlockUniformStream rng(11, 0);
  SoftmaxPolicy pi(2, 3);
  ReinforceOptions o;
  o.episodes = 2000;
  o.alpha = 0.1;
  const auto curve = reinforce(model, o, rng, pi);
  double p[3];
  pi.probabilities(0, p);
  EXPECT_GT(p[2], 0.9);
  double late = 0.0;
  for (int i = 1900; i < 2000; ++i) late += curve.returns[static_cast<std::size_t>(i)] / 100.0;
  EXPECT_GT(late, 2.8);
}

TEST(Learners, ReinforceImprovesAGridworldPolicy) {
  const GridWorld w = corner_gridworld(3);
  BlockUniformStream rng(12, 0);
  SoftmaxPolicy pi(w.num_states(), 4);
  ReinforceOptions o;
  o.episodes = 3000;
  o.alpha = 0.02;
  const auto curve = reinforce(w, o, rng, pi);
  double early = 0.0, late = 0.0;
  for (int i = 0; i < 200; ++i) early += curve.steps[static_cast<std::size_t>(i)] / 200.0;
  for (int i = 2800; i < 3000; ++i) late += curve.steps[static_cast<std::size_t>(i)] / 200.0;
  EXPECT_LT(late, 0.75 * early);
  EXPECT_LT(late, 1.3 * optimal_steps(w));
}

}  // namespace
}  // namespace pegasus
