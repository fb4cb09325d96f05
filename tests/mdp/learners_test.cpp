#include "pegasus/mdp/learners.hpp"

#include <Random123/philox.h>
#include <gtest/gtest.h>

#include <cmath>

#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/block_stream.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/scenarios/counter_rng.hpp"

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

TEST(BlockUniformStream, IsAPureFunctionOfSeedStreamAndPosition) {
  BlockUniformStream a(42, 3);
  std::vector<double> xs(1000);
  for (auto& x : xs) x = a.next();
  EXPECT_EQ(a.position(), 1000u);
  for (std::uint64_t start : {0u, 1u, 63u, 64u, 65u, 517u}) {
    BlockUniformStream b(42, 3, start);
    for (std::uint64_t i = start; i < 1000; ++i) ASSERT_EQ(b.next(), xs[i]) << start;
  }
  BlockUniformStream other_stream(42, 4), other_seed(43, 3);
  EXPECT_NE(other_stream.next(), xs[0]);
  EXPECT_NE(other_seed.next(), xs[0]);
  double mean = 0.0;
  for (double x : xs) {
    EXPECT_GT(x, 0.0);
    EXPECT_LT(x, 1.0);
    mean += x / 1000.0;
  }
  EXPECT_NEAR(mean, 0.5, 0.03);
}

// The vector Philox paths must give Random123's scalar numbers bit for bit: BlockUniformStream's numbers,
// and so every learner's results, may not depend on the CPU.
TEST(BlockUniformStream, VectorPhiloxPathsMatchScalarPhiloxBitForBit) {
  const r123::Philox4x32 philox;
  for (const std::uint64_t seed : {0ull, 42ull, 0xfedcba9876543210ull}) {
    for (const std::uint64_t first : {0ull, 5ull, 0xffffffe0ull, 0x1234567890ull}) {
      // Counters crossing 2^32 exercise the second counter word; odd counts exercise the tails.
      for (const int calls : {1, 3, 4, 7, 8, 15, 16, 31, 32, 33, 64, 67}) {
        std::vector<double> want(static_cast<std::size_t>(4 * calls));
        const r123::Philox4x32::key_type key = {
            {static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}};
        for (int j = 0; j < calls; ++j) {
          const std::uint64_t c = first + static_cast<std::uint64_t>(j);
          const auto r = philox(
              {{static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(c >> 32), 9u, kBlockStreamDomain}},
              key);
          for (int w = 0; w < 4; ++w)
            want[static_cast<std::size_t>(4 * j + w)] =
                (static_cast<double>(r[static_cast<std::size_t>(w)]) + 0.5) * 0x1.0p-32;
        }
        for (const InstructionSet path : supported_instruction_sets()) {
          std::vector<double> got(want.size(), -1.0);
          detail::philox_uniforms(path, key[0], key[1], first, 9u, kBlockStreamDomain, calls, got.data());
          for (std::size_t i = 0; i < want.size(); ++i)
            ASSERT_EQ(got[i], want[i]) << "path " << instruction_set_name(path) << " seed " << seed
                                       << " first " << first << " calls " << calls << " index " << i;
        }
      }
    }
  }
  // And the stream itself (whatever path this CPU picks) is the scalar Philox stream.
  BlockUniformStream s(77, 5, 3);
  const auto r = philox({{0u, 0u, 5u, kBlockStreamDomain}}, r123::Philox4x32::key_type{{77u, 0u}});
  EXPECT_EQ(s.next(), (static_cast<double>(r[3]) + 0.5) * 0x1.0p-32);
  const auto r1 = philox({{1u, 0u, 5u, kBlockStreamDomain}}, r123::Philox4x32::key_type{{77u, 0u}});
  EXPECT_EQ(s.next(), (static_cast<double>(r1[0]) + 0.5) * 0x1.0p-32);
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
