#include "pegasus/mdp/solvers.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/policy_paths.hpp"
#include "pegasus/mdp/random_mdp.hpp"
#include "support/input_error.hpp"

namespace pegasus {
namespace {

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

// State 0: action 0 stays with reward 1, action 1 moves to state 1 with reward 0; state 1 loops with
// reward 2. With gamma = 0.9: V(1) = 20, Q(0, 1) = 18, Q(0, 0) = 1 + 0.9 * 18 = 17.2, so V(0) = 18.
FiniteMdp stay_or_go() {
  FiniteMdpBuilder b(2, 2, 0.9);
  b.add_transition(0, 0, 0, 1.0, 1.0);
  b.add_transition(0, 1, 1, 1.0, 0.0);
  for (int a = 0; a < 2; ++a) b.add_transition(1, a, 1, 1.0, 2.0);
  return b.build();
}

TEST(Solvers, EverySolverMatchesTheHandSolvedDiscountedMdp) {
  const FiniteMdp m = stay_or_go();
  ValueIterationOptions gs;
  gs.gauss_seidel = true;
  for (const SolveSummary& s :
       {value_iteration(m), value_iteration(m, gs), policy_iteration(m), modified_policy_iteration(m)}) {
    ASSERT_TRUE(s.converged()) << s.message;
    EXPECT_NEAR(s.value[0], 18.0, 1e-6) << s.message;
    EXPECT_NEAR(s.value[1], 20.0, 1e-6) << s.message;
    EXPECT_EQ(s.policy[0], 1) << s.message;
  }
  EXPECT_NEAR(policy_iteration(m).value[0], 18.0, 1e-12);  // exact evaluation
}

TEST(Solvers, EverySolverMatchesTheHandSolvedTwoByTwoGridworld) {
  // Neighbours of the goal: 0.9 x = -1 + 0.05 y; start: 0.9 y = -1 + 0.9 x, so x = -190/153, y = -40/17.
  const FiniteMdp m = to_finite_mdp(corner_gridworld(2));
  ValueIterationOptions gs;
  gs.gauss_seidel = true;
  for (const SolveSummary& s :
       {value_iteration(m), value_iteration(m, gs), policy_iteration(m), modified_policy_iteration(m)}) {
    ASSERT_TRUE(s.converged()) << s.message;
    EXPECT_NEAR(s.value[0], -40.0 / 17.0, 1e-9) << s.message;
    EXPECT_NEAR(s.value[1], -190.0 / 153.0, 1e-9) << s.message;
    EXPECT_NEAR(s.value[2], -190.0 / 153.0, 1e-9) << s.message;
    EXPECT_EQ(s.value[3], 0.0);
    EXPECT_EQ(s.policy[1], kNorth);
    EXPECT_EQ(s.policy[2], kEast);
  }
}

TEST(Solvers, AgreeWithEachOtherOnRandomMdps) {
  UniformStream rng(11, 0);
  for (int i = 0; i < 60; ++i) {
    RandomMdpOptions o;
    o.num_states = 3 + (i * 7) % 40;
    o.num_actions = 2 + i % 3;
    o.successors = 1 + i % 5;
    o.gamma = i % 3 == 0 ? 1.0 : 0.95;
    o.episodic = i % 2 == 0;
    const FiniteMdp m = random_mdp(o, rng);
    const auto pi = policy_iteration(m);
    ValueIterationOptions vo;
    vo.epsilon = 1e-9;
    const auto vi = value_iteration(m, vo);
    vo.gauss_seidel = true;
    const auto gs = value_iteration(m, vo);
    ModifiedPolicyIterationOptions mo;
    mo.epsilon = 1e-9;
    const auto mpi = modified_policy_iteration(m, mo);
    ASSERT_TRUE(pi.converged() && vi.converged() && gs.converged() && mpi.converged());
    // V from VI is within gamma r/(1-gamma) <= epsilon/2 of V*.
    EXPECT_LT(max_abs_diff(vi.value, pi.value), 1e-8) << i;
    EXPECT_LT(max_abs_diff(gs.value, pi.value), 1e-8) << i;
    EXPECT_LT(max_abs_diff(mpi.value, pi.value), 1e-8) << i;
    // Policy iteration's fixed point satisfies the Bellman optimality equation (2.7).
    std::vector<double> tv(pi.value.size());
    EXPECT_LT(bellman_backup(m, pi.value, tv), 1e-9);
  }
}

TEST(Solvers, ValueIterationPolicyIsEpsilonOptimalAsCertified) {
  // Loose epsilons so that the returned greedy policy is genuinely approximate; its exact value must
  // still be within the certified bound (and epsilon) of V*.
  UniformStream rng(12, 0);
  for (int i = 0; i < 40; ++i) {
    RandomMdpOptions o;
    o.num_states = 5 + i % 30;
    o.num_actions = 3;
    o.gamma = 0.9 + 0.002 * i;
    const FiniteMdp m = random_mdp(o, rng);
    const auto exact = policy_iteration(m);
    for (double eps : {1.0, 1e-2, 1e-4}) {
      for (bool gauss_seidel : {false, true}) {
        ValueIterationOptions vo;
        vo.epsilon = eps;
        vo.gauss_seidel = gauss_seidel;
        const auto vi = value_iteration(m, vo);
        ASSERT_TRUE(vi.converged());
        EXPECT_LE(vi.policy_loss_bound, eps);
        const auto v_pi = evaluate_policy(m, vi.policy);
        for (int s = 0; s < m.num_states; ++s)
          EXPECT_LE(exact.value[static_cast<std::size_t>(s)] - v_pi[static_cast<std::size_t>(s)],
                    vi.policy_loss_bound + 1e-12);
      }
    }
  }
}

TEST(Solvers, GaussSeidelNeedsNoMoreSweepsThanJacobi) {
  const FiniteMdp m = to_finite_mdp(corner_gridworld(10), 0.95);
  ValueIterationOptions vo;
  vo.epsilon = 1e-6;
  const auto jacobi = value_iteration(m, vo);
  vo.gauss_seidel = true;
  const auto gs = value_iteration(m, vo);
  EXPECT_LE(gs.iterations, jacobi.iterations);
  EXPECT_LT(max_abs_diff(gs.value, jacobi.value), 1e-6);
}

TEST(Solvers, ResidualStopRuleStopsWhenASweepChangesLessThanTheTolerance) {
  const FiniteMdp m = to_finite_mdp(corner_gridworld(5), 0.95);
  ValueIterationOptions vo;
  vo.stop = StopRule::kResidual;
  vo.tolerance = 1e-5;
  const auto vi = value_iteration(m, vo);
  ASSERT_TRUE(vi.converged());
  EXPECT_LT(vi.residual, 1e-5);
  EXPECT_LT(max_abs_diff(vi.value, policy_iteration(m).value), 1e-5 * 0.95 / 0.05 + 1e-12);
}

TEST(Solvers, EvaluatesStochasticPoliciesExactly) {
  // In stay_or_go, mixing 50/50 in state 0: V0 = 0.5 (1 + 0.9 V0) + 0.5 (0.9 * 20), so V0 = 9.5 / 0.55.
  const FiniteMdp m = stay_or_go();
  StochasticPolicy pi{2, 2, {0.5, 0.5, 1.0, 0.0}};
  const auto v = evaluate_policy(m, pi);
  EXPECT_NEAR(v[0], 9.5 / 0.55, 1e-12);
  EXPECT_NEAR(v[1], 20.0, 1e-12);
  // Q from V: Q(0, 1) = 0 + 0.9 * 20.
  const auto q = q_from_values(m, v);
  EXPECT_NEAR(q[m.row(0, 1)], 18.0, 1e-12);
}

// The same MDP with state s renamed perm[s].
FiniteMdp renumbered(const FiniteMdp& m, const std::vector<int>& perm) {
  FiniteMdpBuilder b(m.num_states, m.num_actions, m.gamma);
  for (int s = 0; s < m.num_states; ++s) {
    const int t = perm[static_cast<std::size_t>(s)];
    b.set_initial(t, m.initial[static_cast<std::size_t>(s)]);
    if (m.is_absorbing(s)) {
      b.set_absorbing(t);
      continue;
    }
    for (int a = 0; a < m.num_actions; ++a)
      for (std::uint32_t k = m.row_start[m.row(s, a)]; k < m.row_start[m.row(s, a) + 1]; ++k)
        b.add_transition(t, a, perm[static_cast<std::size_t>(m.next_state[k])], m.probability[k],
                         m.reward[k]);
  }
  return b.build();
}

// Exact evaluation picks a band LU for a gridworld numbered row by row and a sparse LU for the same
// gridworld with its states shuffled (bandwidth ~ n): both must solve V = R_pi + gamma P_pi V.
TEST(Solvers, BandAndSparseExactEvaluationAgree) {
  for (const double gamma : {1.0, 0.95}) {
    const FiniteMdp m = to_finite_mdp(corner_gridworld(30), gamma);
    std::vector<int> perm(static_cast<std::size_t>(m.num_states));
    for (std::size_t s = 0; s < perm.size(); ++s) perm[s] = static_cast<int>(s);
    UniformStream rng(5, 0);
    for (std::size_t i = perm.size() - 1; i > 0; --i) std::swap(perm[i], perm[rng.next_below(i + 1)]);
    const FiniteMdp shuffled = renumbered(m, perm);
    // A stochastic policy: 0.7 on one action, 0.1 on the others.
    StochasticPolicy pi{m.num_states, 4, std::vector<double>(m.num_rows(), 0.1)};
    for (int s = 0; s < m.num_states; ++s) pi.probs[m.row(s, s % 4)] = 0.7;
    StochasticPolicy pi_shuffled{m.num_states, 4, std::vector<double>(m.num_rows())};
    for (int s = 0; s < m.num_states; ++s)
      for (int a = 0; a < 4; ++a)
        pi_shuffled.probs[m.row(perm[static_cast<std::size_t>(s)], a)] = pi.probs[m.row(s, a)];
    const auto v = evaluate_policy(m, pi), w = evaluate_policy(shuffled, pi_shuffled);
    double scale = 0.0, residual = 0.0, disagreement = 0.0;
    const auto q = q_from_values(m, v);
    for (int s = 0; s < m.num_states; ++s) {
      double backup = 0.0;
      for (int a = 0; a < 4; ++a) backup += pi.probs[m.row(s, a)] * q[m.row(s, a)];
      if (m.is_absorbing(s)) backup = 0.0;
      scale = std::max(scale, std::abs(v[static_cast<std::size_t>(s)]));
      residual = std::max(residual, std::abs(backup - v[static_cast<std::size_t>(s)]));
      disagreement =
          std::max(disagreement, std::abs(v[static_cast<std::size_t>(s)] -
                                          w[static_cast<std::size_t>(perm[static_cast<std::size_t>(s)])]));
    }
    EXPECT_GT(scale, 10.0) << gamma;
    EXPECT_LT(residual, 1e-12 * scale) << gamma;
    EXPECT_LT(disagreement, 1e-12 * scale) << gamma;
  }
}

TEST(Solvers, ExactEvaluationRejectsAnImproperPolicy) {
  // A corridor 0 - 1 - ... - n-1 (absorbing): action 0 moves right, action 1 stays. With gamma = 1,
  // staying in state 4 forever makes I - P_pi singular. (The builder refuses such an MDP with gamma = 1,
  // so gamma is set afterwards, as a hand-made FiniteMdp could have it.) n = 3 takes the dense LU, n = 12
  // the band LU.
  for (const int n : {3, 12}) {
    FiniteMdpBuilder b(n, 2, 0.5);
    b.set_absorbing(n - 1);
    for (int s = 0; s + 1 < n; ++s) {
      b.add_transition(s, 0, s + 1, 1.0, -1.0);
      b.add_transition(s, 1, s, 1.0, -1.0);
    }
    FiniteMdp m = b.build();
    m.gamma = 1.0;
    std::vector<int> policy(static_cast<std::size_t>(n), 0);
    EXPECT_NEAR(evaluate_policy(m, policy)[0], -(n - 1.0), 1e-12);
    policy[static_cast<std::size_t>(n / 3)] = 1;
    EXPECT_THAT(test_support::input_error_message([&] { evaluate_policy(m, policy); }),
                ::testing::HasSubstr("singular"))
        << n;
  }
}

// Every instruction-set path of the dense sweep kernel computes the same dot products up to round-off
// (they sum in different orders, and FMA rounds once), and the solvers' dense sweeps agree with the
// row-by-row Q values.
TEST(Solvers, DenseKernelPathsAgreeWithPlainDotProducts) {
  UniformStream rng(21, 0);
  for (const int n : {1, 7, 8, 16, 17, 31, 500, 503}) {
    std::vector<double> p(static_cast<std::size_t>(4 * n)), v(static_cast<std::size_t>(n));
    for (double& x : p) x = rng.next();
    for (double& x : v) x = 10.0 * rng.next() - 5.0;
    for (const InstructionSet path : supported_instruction_sets()) {
      double out[4], again[4];
      detail::dense_dot4(path, p.data(), static_cast<std::size_t>(n), v.data(), n, out);
      detail::dense_dot4(path, p.data(), static_cast<std::size_t>(n), v.data(), n, again);
      for (int a = 0; a < 4; ++a) {
        long double exact = 0.0L, magnitude = 0.0L;
        for (int k = 0; k < n; ++k) {
          const long double t = static_cast<long double>(p[static_cast<std::size_t>(a * n + k)]) *
                                v[static_cast<std::size_t>(k)];
          exact += t;
          magnitude += t < 0 ? -t : t;
        }
        EXPECT_NEAR(out[a], static_cast<double>(exact), 1e-15 * n * static_cast<double>(magnitude))
            << "path " << instruction_set_name(path) << " n " << n << " row " << a;
        EXPECT_EQ(out[a], again[a]);  // deterministic
      }
    }
  }
  RandomMdpOptions o{.num_states = 40, .num_actions = 6, .successors = 40, .gamma = 0.9};
  const FiniteMdp m = random_mdp(o, rng);  // dense: every row lists every state
  std::vector<double> v(40), tv(40);
  for (double& x : v) x = rng.next();
  bellman_backup(m, v, tv);
  const auto q = q_from_values(m, v);
  for (int s = 0; s < m.num_states; ++s) {
    double best = q[m.row(s, 0)];
    for (int a = 1; a < m.num_actions; ++a) best = std::max(best, q[m.row(s, a)]);
    EXPECT_NEAR(tv[static_cast<std::size_t>(s)], best, 1e-14) << s;
  }
}

TEST(Solvers, GridworldOptimalValueIsCloseToTheThesisDistanceEstimate) {
  // §3.4: about 0.8 cells of progress per step, so V*(start) ~ -manhattan/0.8 = -22.5 on the 10x10 grid
  // (walls help a little near the edges).
  const GridWorld w = corner_gridworld(10);
  const FiniteMdp m = to_finite_mdp(w);
  const auto pi = policy_iteration(m);
  EXPECT_NEAR(pi.value[static_cast<std::size_t>(w.start())], -18.0 / 0.8, 1.5);
  EXPECT_LT(pi.value[static_cast<std::size_t>(w.start())], -18.0);  // never faster than one cell per step
}

TEST(PolicyPaths, FollowsMostLikelyTransitionsAndDetectsCycles) {
  const GridWorld w = corner_gridworld(4);
  const FiniteMdp m = to_finite_mdp(w);
  const auto optimal = most_likely_path(m, policy_iteration(m).policy, w.start());
  EXPECT_TRUE(optimal.reaches_absorbing);
  EXPECT_EQ(optimal.states.front(), w.start());
  EXPECT_EQ(optimal.states.back(), w.goal());
  EXPECT_EQ(optimal.states.size(), 7u);
  // Pushing south from the bottom row mostly stays put: a cycle of one state.
  const auto stuck = most_likely_path(m, std::vector<int>(16, kSouth), w.start());
  EXPECT_FALSE(stuck.reaches_absorbing);
  EXPECT_EQ(stuck.cycle(), std::vector<int>{w.start()});
  EXPECT_THROW(most_likely_path(m, std::vector<int>(3, 0), 0), InputError);
}

TEST(Solvers, OptionsAreValidatedBeforeAnyWork) {
  const FiniteMdp m = stay_or_go();
  ValueIterationOptions vo;
  vo.epsilon = 0.0;
  std::string err;
  EXPECT_FALSE(vo.IsValid(m, &err));
  EXPECT_THAT(err, ::testing::HasSubstr("epsilon must be > 0"));
  EXPECT_THROW(value_iteration(m, vo), InputError);
  PolicyIterationOptions po;
  po.initial_policy = {0, 5};
  EXPECT_THROW(policy_iteration(m, po), InputError);
  ModifiedPolicyIterationOptions mo;
  mo.evaluation_sweeps = 0;
  EXPECT_THROW(modified_policy_iteration(m, mo), InputError);
  EXPECT_THROW(evaluate_policy(m, std::vector<int>{0}), InputError);
}

}  // namespace
}  // namespace pegasus
