#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/interval_mdp.hpp"
#include "pegasus/envs/pomdp_gridworld.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/evaluators/table_policy_values.hpp"
#include "pegasus/evaluators/trajectory_tree.hpp"
#include "pegasus/models/hashed_model.hpp"
#include "pegasus/policies/policies.hpp"

namespace pegasus {
namespace {

const Discounting kGrid{.gamma = 0.99, .horizon = 100};

ScenarioSet grid_scenarios(std::uint64_t seed, int m, int horizon = 100) {
  return ScenarioSet({.seed = seed, .count = m, .horizon = horizon, .noise_dim = 1, .initial_noise_dim = 0});
}

// Up-and-right policy for the 5x5 grid: go right along the bottom, then up.
Theta sensible_policy(const PomdpGridworld& g) {
  Theta theta(static_cast<std::size_t>(g.observations()), PomdpGridworld::kUp);
  for (int o = 0; o < g.observations(); ++o) {
    const unsigned mask = g.mask_of_observation(o);
    const bool wall_east = mask & (1u << 2), wall_north = mask & (1u << 0);
    theta[static_cast<std::size_t>(o)] =
        (!wall_east && wall_north) ? PomdpGridworld::kRight : PomdpGridworld::kUp;
    if (wall_north && wall_east) theta[static_cast<std::size_t>(o)] = PomdpGridworld::kUp;
  }
  return theta;
}

TEST(PomdpGridworld, OpenFiveByFiveGridHasEightObservationsOffTheGoal) {
  PomdpGridworld g;
  EXPECT_EQ(g.observations(), 8);
  EXPECT_EQ(g.observe(g.goal()), 8);
  EXPECT_EQ(g.start(), 0);
  EXPECT_EQ(g.goal(), 24);
}

TEST(PomdpGridworld, TransitionProbabilitiesSumToOneAndMatchSampledFrequencies) {
  PomdpGridworld g;
  const int s = 12, a = PomdpGridworld::kRight;
  double total = 0;
  std::vector<double> exact(25, 0.0), sampled(25, 0.0);
  for (auto [s2, p] : g.transitions(s, a)) {
    total += p;
    exact[static_cast<std::size_t>(s2)] += p;
  }
  EXPECT_NEAR(total, 1.0, 1e-15);
  EXPECT_NEAR(exact[13], 0.85, 1e-12);  // intended move 80% plus its 5% slip
  UniformStream rng(3, 0);
  const int n = 200000;
  for (int k = 0; k < n; ++k) {
    const double p = rng.next();
    sampled[static_cast<std::size_t>(g.step(s, a, std::span<const double>(&p, 1)))] += 1.0 / n;
  }
  for (int c = 0; c < 25; ++c)
    EXPECT_NEAR(sampled[static_cast<std::size_t>(c)], exact[static_cast<std::size_t>(c)], 0.005);
}

TEST(PomdpGridworld, PegasusEstimatesAverageToTheExactValue) {
  // U-hat is an unbiased estimate of the H-step value: its mean over independent scenario sets converges.
  PomdpGridworld g;
  TablePolicy pi(g.observations(), 4);
  const Theta theta = sensible_policy(g);
  const double exact = g.exact_value(theta, kGrid);
  double sum = 0, sum2 = 0;
  const int sets = 400;
  for (int k = 0; k < sets; ++k) {
    PegasusEvaluator ev(g, pi, grid_scenarios(100 + static_cast<std::uint64_t>(k), 8), kGrid);
    const double u = ev.evaluate(theta);
    sum += u;
    sum2 += u * u;
  }
  const double mean = sum / sets, sd = std::sqrt(sum2 / sets - mean * mean);
  EXPECT_NEAR(mean, exact, 4 * sd / std::sqrt(sets));
  EXPECT_LT(exact, -7.0);  // at least 8 moves to the goal
  EXPECT_GT(exact, -15.0);
}

TEST(PegasusEvaluator, ResultIsBitIdenticalForAnyThreadCountAndInBatches) {
  PomdpGridworld g;
  TablePolicy pi(g.observations(), 4);
  PegasusEvaluator ev(g, pi, grid_scenarios(5, 33), kGrid);
  std::vector<Theta> thetas;
  for (std::uint64_t k = 0; k < 50; ++k) thetas.push_back(pi.theta_of_index(k * 1311));
  std::vector<double> serial(thetas.size());
  for (std::size_t k = 0; k < thetas.size(); ++k) serial[k] = ev.evaluate(thetas[k]);
  for (int threads : {1, 2, 3}) {
    ThreadPool pool(threads);
    std::vector<double> batch(thetas.size());
    ev.evaluate_batch(thetas, batch, &pool);
    for (std::size_t k = 0; k < thetas.size(); ++k) {
      EXPECT_EQ(batch[k], serial[k]);
      EXPECT_EQ(ev.evaluate(thetas[k], &pool), serial[k]);
    }
  }
}

template <class Model>
void expect_table_values_match_plain_evaluation(const Model& model, int m, std::uint64_t seed) {
  const int observations = 8;
  TablePolicy pi(observations, 4);
  const ScenarioSet scenarios = grid_scenarios(seed, m);
  PegasusEvaluator ev(model, pi, scenarios, kGrid);
  TablePolicyValues fast(model, observations, scenarios, kGrid);
  std::vector<double> values(fast.policy_count());
  ThreadPool pool(2);
  const auto leaves = fast.compute(values, &pool);
  EXPECT_LT(leaves, fast.policy_count());  // trajectories really were shared
  for (std::uint64_t k = 0; k < fast.policy_count(); k += 7)
    ASSERT_EQ(values[k], ev.evaluate(pi.theta_of_index(k))) << k;
}

TEST(TablePolicyValues, EveryValueIsBitIdenticalToPlainPegasusEvaluation) {
  PomdpGridworld g;
  expect_table_values_match_plain_evaluation(g, 4, 21);
  expect_table_values_match_plain_evaluation(HashedModel<PomdpGridworld>(g, 77), 3, 22);
}

TEST(TablePolicyValues, ResultDoesNotDependOnThreadCount) {
  PomdpGridworld g;
  const ScenarioSet scenarios = grid_scenarios(8, 16);
  TablePolicyValues fast(g, 8, scenarios, kGrid);
  std::vector<double> one(fast.policy_count()), two(fast.policy_count());
  fast.compute(one);
  ThreadPool pool(2);
  fast.compute(two, &pool);
  EXPECT_EQ(one, two);
}

TEST(HashedModel, KeepsEachTransitionDistributionButChangesTheMapFromNoise) {
  PomdpGridworld g;
  HashedModel<PomdpGridworld> h(g, 5);
  UniformStream rng(1, 0);
  const int n = 100000;
  std::vector<double> freq(25, 0.0);
  int differ = 0;
  for (int k = 0; k < n; ++k) {
    const double p = rng.next();
    const int s2 = h.step(6, PomdpGridworld::kUp, std::span<const double>(&p, 1));
    freq[static_cast<std::size_t>(s2)] += 1.0 / n;
    differ += s2 != g.step(6, PomdpGridworld::kUp, std::span<const double>(&p, 1));
  }
  for (auto [s2, prob] : g.transitions(6, PomdpGridworld::kUp)) {
    double total = 0;
    for (auto [s3, p3] : g.transitions(6, PomdpGridworld::kUp))
      if (s3 == s2) total += p3;
    EXPECT_NEAR(freq[static_cast<std::size_t>(s2)], total, 0.006);
    (void)prob;
  }
  EXPECT_GT(differ, n / 10);
  const auto k = h.multiplier(6, 0, 0);
  EXPECT_GE(k, 1u);
  EXPECT_LE(k, 1000u);
}

TEST(MonteCarloEvaluator, DrawsFreshRandomnessPerEvaluationYetIsReproducible) {
  PomdpGridworld g;
  TablePolicy pi(g.observations(), 4);
  const Theta theta = sensible_policy(g);
  MonteCarloEvaluator a(g, pi, 4, kGrid, 9), b(g, pi, 4, kGrid, 9);
  std::vector<double> first;
  for (int k = 0; k < 20; ++k) first.push_back(a.evaluate(theta));
  int distinct = 0;
  for (int k = 1; k < 20; ++k) distinct += first[static_cast<std::size_t>(k)] != first[0];
  EXPECT_GT(distinct, 5);
  ThreadPool pool(2);
  std::vector<Theta> thetas(20, theta);
  std::vector<double> batch(20);
  b.evaluate_batch(thetas, batch, &pool);
  EXPECT_EQ(batch, first);
}

// A simulative model that draws more scenario numbers than fit on the stack (NoiseBuffer): its start sums
// 100 of them and each step adds 80 more, times the action; the reward is the state being left.
struct WideNoise {
  using State = double;
  using Action = double;
  using Observation = double;
  int state_dim() const { return 1; }
  int noise_dim() const { return 80; }
  int initial_noise_dim() const { return 100; }
  ActionSpace action_space() const { return ActionSpace::box({-1}, {1}); }
  bool terminal(double) const { return false; }
  double observe(double s) const { return s; }
  double reward(double s) const { return s; }
  static double sum(std::span<const double> p) {
    double total = 0.0;
    for (const double u : p) total += u;
    return total;
  }
  double initial_state(std::span<const double> p0) const { return sum(p0); }
  double step(double s, double a, std::span<const double> p) const { return s + a * sum(p); }
};

TEST(PegasusEvaluator, AModelMayDrawMoreScenarioNumbersThanTheStackBufferHolds) {
  static_assert(SimulativeModel<WideNoise>);
  ASSERT_GT(WideNoise{}.initial_noise_dim(), static_cast<int>(NoiseBuffer::kInlineNoiseDim));
  const Discounting d{.gamma = 1.0, .horizon = 5};
  const ScenarioSet scenarios(
      {.seed = 4, .count = 3, .horizon = 5, .noise_dim = 80, .initial_noise_dim = 100});
  auto policy = make_program_policy<double>(ParameterSpec({{.name = "gain", .initial = 0.5}}),
                                            [](std::span<const double> k, double) { return k[0]; });
  const PegasusEvaluator evaluator(WideNoise{}, policy, scenarios, d);
  const Theta theta = {0.5};
  // The same sums by hand, from every number of every scenario.
  std::vector<double> returns;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> p0(100), p(80);
    scenarios.initial_noise(i, p0);
    double s = WideNoise::sum(p0), ret = 0.0;
    for (int t = 0; t < 5; ++t) {
      ret += s;
      scenarios.step_noise(i, t, p);
      s = s + 0.5 * WideNoise::sum(p);
    }
    returns.push_back(ret);
  }
  EXPECT_EQ(evaluator.evaluate(theta), ordered_mean(returns));
  // The generative path (fresh numbers from a stream) takes the same sizes: its mean is 5 x 50 (the start's
  // 100 numbers) plus 0.5 x 40 x (1 + 2 + 3 + 4), where 64 numbers would give 360.
  MonteCarloEvaluator monte_carlo(WideNoise{}, policy, 4, d, 7);
  const double estimate = monte_carlo.evaluate(theta);
  EXPECT_NEAR(estimate, 5 * 50.0 + 0.5 * 40.0 * (1 + 2 + 3 + 4), 40.0);
}

// A model that only samples internally (a generative model): a walk on {0..4} that drifts right.
struct DriftWalk {
  using State = int;
  using Action = int;
  using Observation = int;
  int state_dim() const { return 1; }
  ActionSpace action_space() const { return ActionSpace::finite(2); }
  bool terminal(int s) const { return s >= 4; }
  int observe(int s) const { return s; }
  double reward(int s, int a) const { return -1.0 - 0.1 * a + 0.0 * s; }
  int sample_initial(UniformStream&) const { return 0; }
  int sample_step(int s, int a, UniformStream& rng) const {
    const double stay = a == 1 ? 0.2 : 0.7;
    return rng.next() < stay ? s : s + 1;
  }
};

TEST(TrajectoryTrees, WorkWithAGenerativeModelAndAverageToTheTrueValue) {
  static_assert(GenerativeModel<DriftWalk> && !SimulativeModel<DriftWalk>);
  const Discounting d{.gamma = 0.9, .horizon = 6};
  // Always-action-1 policy; exact 6-step value by enumeration of the chain.
  TablePolicy pi(5, 2, 1);
  const Theta always1 = pi.parameters().initial();
  std::vector<double> v(5, 0.0);
  for (int k = 0; k < d.horizon; ++k) {
    std::vector<double> next(5, 0.0);
    for (int s = 0; s < 4; ++s)
      next[static_cast<std::size_t>(s)] =
          -1.1 + d.gamma * (0.2 * v[static_cast<std::size_t>(s)] + 0.8 * v[static_cast<std::size_t>(s + 1)]);
    v = next;
  }
  ThreadPool pool(2);
  TrajectoryTrees trees(DriftWalk{}, 4000, d, 17, &pool);
  EXPECT_EQ(trees.nodes_per_tree(), 127u);
  EXPECT_NEAR(trees.evaluate(pi, always1), v[0], 0.05);
  // Trees built from the same seed are identical whatever the thread count.
  TrajectoryTrees serial(DriftWalk{}, 200, d, 17), parallel(DriftWalk{}, 200, d, 17, &pool);
  EXPECT_EQ(serial.evaluate(pi, always1), parallel.evaluate(pi, always1));
  MonteCarloEvaluator mc(DriftWalk{}, pi, 4000, d, 3);
  EXPECT_NEAR(mc.evaluate(always1), v[0], 0.05);
}

TEST(TrajectoryTrees, RefuseExponentiallyLargeTrees) {
  EXPECT_THROW(TrajectoryTrees(PomdpGridworld{}, 10, Discounting{.gamma = 0.99, .horizon = 40}, 1),
               InputError);
}

// Continuous-time discounting (footnote 9): a point moving at speed 0.3 per step enters the goal x >= 1
// during the fourth step, at fraction tau = (1 - 0.9) / 0.3 of it; the reward 1 is discounted by gamma^(3 +
// tau).
struct Glide {
  using State = double;
  using Action = int;
  using Observation = double;
  int state_dim() const { return 1; }
  int noise_dim() const { return 0; }
  int initial_noise_dim() const { return 0; }
  ActionSpace action_space() const { return ActionSpace::finite(1); }
  double initial_state(std::span<const double>) const { return 0.0; }
  double step(double x, int, std::span<const double>) const { return x + 0.3; }
  bool terminal(double x) const { return x >= 1.0; }
  double observe(double x) const { return x; }
  double reward(double, int, double next) const { return next >= 1.0 ? 1.0 : 0.0; }
  double event_fraction(double x, int, double next) const { return next >= 1.0 ? (1.0 - x) / 0.3 : 0.0; }
};

TEST(Rollout, ContinuousTimeDiscountingUsesTheFractionOfTheStep) {
  auto pi =
      make_program_policy<double>(ParameterSpec{}, [](std::span<const double>, const double&) { return 0; });
  ScenarioSet one({.seed = 1, .count = 1, .horizon = 10, .noise_dim = 0, .initial_noise_dim = 0});
  PegasusEvaluator ev(Glide{}, pi, one, Discounting{.gamma = 0.9, .horizon = 10});
  const double x3 = 0.3 + 0.3 + 0.3;
  EXPECT_NEAR(ev.evaluate(Theta{}), std::pow(0.9, 3.0 + (1.0 - x3) / 0.3), 1e-12);
}

TEST(Policies, SigmoidPolicyStaysInsideTheActionBoxAndProgramPoliciesTakeAFewLines) {
  struct TwoFeatures {
    int size() const { return 2; }
    void operator()(const std::array<double, 2>& o, std::span<double> phi) const {
      phi[0] = o[0];
      phi[1] = 1.0;
    }
  };
  SigmoidPolicy<2, TwoFeatures> sig(TwoFeatures{}, ActionSpace::box({-2, -0.02}, {2, 0.02}));
  EXPECT_EQ(sig.parameters().size(), 4u);
  const Theta w = {50, 0, -50, 1};
  for (double x : {-10.0, 0.0, 10.0}) {
    const auto a = sig.act(w, std::array<double, 2>{x, 0});
    EXPECT_GE(a[0], -2);
    EXPECT_LE(a[0], 2);
    EXPECT_GE(a[1], -0.02);
    EXPECT_LE(a[1], 0.02);
  }
  EXPECT_NEAR(sig.act(w, std::array<double, 2>{0, 0})[0], 0.0, 1e-12);
  LinearPolicy<2, TwoFeatures> lin(TwoFeatures{}, ActionSpace::box({-1, -1}, {1, 1}));
  EXPECT_EQ(lin.act(Theta{0.5, 0.1, 9, 9}, std::array<double, 2>{1, 0})[1], 1.0);  // clipped
  auto pd = make_program_policy<std::array<double, 2>>(
      ParameterSpec({{.name = "kp", .initial = 1.0}, {.name = "kd", .initial = 0.5}}),
      [](std::span<const double> k, const std::array<double, 2>& o) { return -k[0] * o[0] - k[1] * o[1]; });
  EXPECT_DOUBLE_EQ(pd.act(pd.parameters().initial(), {2.0, 2.0}), -3.0);
}

TEST(Policies, ATableKeepsItsActionsInRangeAndTheSpecNamesEntriesOutsideThem) {
  const TablePolicy table(3, 4);
  for (const double a : {0.0, 1.0, 3.0}) EXPECT_EQ(table.act(Theta{0, a, 0}, 1), static_cast<int>(a));
  // Out of range, a table entry never indexes past the actions (1e10 is also beyond an int).
  EXPECT_EQ(table.act(Theta{0, 7, 0}, 1), 3);
  EXPECT_EQ(table.act(Theta{0, 1e10, 0}, 1), 3);
  EXPECT_EQ(table.act(Theta{0, -1e10, 0}, 1), 0);
  EXPECT_EQ(table.parameters().integer_violation(Theta{0, 3, 2}), "");
  EXPECT_EQ(table.parameters().integer_violation(Theta{0, 4, 0}),
            "action[1]: expected an integer in [0, 3], got 4");
  EXPECT_EQ(table.parameters().integer_violation(Theta{0.5, 0, 0}),
            "action[0]: expected an integer in [0, 3], got 0.5");
  EXPECT_EQ(table.parameters().first_integer(), 0u);
  EXPECT_EQ(ParameterSpec({{.name = "w"}}).first_integer(), 1u);
  EXPECT_THROW(ParameterSpec({{.name = "w", .initial = INFINITY}}), InputError);
  EXPECT_THROW(ParameterSpec({{.name = "t", .initial = 0.5, .lower = 0, .upper = 1, .integer = true}}),
               InputError);
}

// Theorem 11 (§4.5.2): with the interval-enumerating g, some constant policy always has U-hat = 1 on any
// finite set of scenarios although U = 0 for every policy; the simple g of footnote 10 has no such policy.
TEST(Theorem11, IntervalModelKeepsTheBestEstimateStuckAtOneWhileEveryTrueValueIsZero) {
  const std::uint64_t actions = IntervalMdp::action_count(4);
  EXPECT_EQ(actions, 2u + 6u + 70u + 12870u);
  for (std::uint64_t i = 0; i < actions; i += 97) EXPECT_EQ(IntervalMdp::measure(i), 0.5);
  const Discounting d{.gamma = 1.0, .horizon = 2};
  auto constant = make_program_policy<int>(
      ParameterSpec({{.name = "i",
                      .initial = 0,
                      .lower = 0,
                      .upper = static_cast<double>(actions - 1),
                      .integer = true}}),
      [](std::span<const double> w, const int&) { return static_cast<IntervalMdp::Action>(w[0]); });
  for (int m : {1, 2, 4, 8}) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const ScenarioSet scenarios(
          {.seed = seed, .count = m, .horizon = 2, .noise_dim = 1, .initial_noise_dim = 0});
      PegasusEvaluator complex(IntervalMdp(false), constant, scenarios, d);
      PegasusEvaluator simple(IntervalMdp(true), constant, scenarios, d);
      double best = -2.0;
      for (std::uint64_t i = 0; i < actions && best < 1.0; ++i)
        best = std::max(best, complex.evaluate(Theta{static_cast<double>(i)}));
      EXPECT_EQ(best, 1.0) << "m=" << m;
      // The simple model gives every action the same estimate, so none looks better than the others.
      const double first = simple.evaluate(Theta{0.0});
      for (std::uint64_t i = 1; i < actions; i += 1001)
        EXPECT_EQ(simple.evaluate(Theta{static_cast<double>(i)}), first);
    }
  }
  // Exact U of every policy is 0: R(s0) + (1/2)(-1) + (1/2)(+1).
  for (std::uint64_t i = 0; i < actions; i += 131)
    EXPECT_EQ(0.0 + IntervalMdp::measure(i) * -1.0 + (1 - IntervalMdp::measure(i)) * 1.0, 0.0);
}

}  // namespace
}  // namespace pegasus
