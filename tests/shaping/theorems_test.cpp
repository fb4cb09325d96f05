// Chapter 3's results as property tests over kSuiteSize random MDPs (sizes 2-34 states, 2-4 actions,
// sparse to dense rows, gamma in {0, 0.5, 0.9, 0.99} continuing or episodic, and proper undiscounted).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pegasus/mdp/solvers.hpp"
#include "pegasus/shaping/audit.hpp"
#include "pegasus/shaping/potential_shaping.hpp"
#include "random_suite.hpp"

namespace pegasus {
namespace {

using test_support::kSuiteSize;
using test_support::max_abs;
using test_support::optimal_action_sets;
using test_support::random_potential;
using test_support::suite_mdp;

// §3.3, Theorem 1 (sufficiency): with F = gamma Phi(s') - Phi(s), every optimal policy of M' is optimal
// in M and vice versa: the sets of optimal actions coincide in every state.
TEST(PotentialShaping, PreservesOptimalPolicyOnRandomMdps) {
  int undiscounted = 0;
  for (int i = 0; i < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    undiscounted += m.gamma == 1.0;
    UniformStream rng(1, static_cast<std::uint32_t>(i));
    const FiniteMdp shaped = shape_with_potential(m, random_potential(m, rng));
    const auto sm = policy_iteration(m), ss = policy_iteration(shaped);
    ASSERT_TRUE(sm.converged() && ss.converged()) << i;
    const auto om = optimal_action_sets(m, q_from_values(m, sm.value));
    const auto os = optimal_action_sets(shaped, q_from_values(shaped, ss.value));
    ASSERT_EQ(om, os) << "MDP " << i;
    // In particular the policy found on M' is optimal in M, state by state.
    const auto v = evaluate_policy(m, ss.policy);
    for (int s = 0; s < m.num_states; ++s)
      ASSERT_GE(v[static_cast<std::size_t>(s)], sm.value[static_cast<std::size_t>(s)] - 1e-9) << "MDP " << i;
  }
  EXPECT_GE(undiscounted, 200);
}

// §3.3, Lemma 2: Q*_M' = Q*_M - Phi(s) and V*_M' = V*_M - Phi, to 1e-9.
TEST(PotentialShaping, ShiftsOptimalValuesByMinusPhi) {
  for (int i = 0; i < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    UniformStream rng(2, static_cast<std::uint32_t>(i));
    const auto phi = random_potential(m, rng);
    const FiniteMdp shaped = shape_with_potential(m, phi);
    const auto vm = policy_iteration(m).value, vs = policy_iteration(shaped).value;
    const auto qm = q_from_values(m, vm), qs = q_from_values(shaped, vs);
    for (int s = 0; s < m.num_states; ++s) {
      if (m.is_absorbing(s)) continue;
      const auto us = static_cast<std::size_t>(s);
      ASSERT_NEAR(vs[us], vm[us] - phi[us], 1e-9) << "MDP " << i << " state " << s;
      for (int a = 0; a < m.num_actions; ++a) ASSERT_NEAR(qs[m.row(s, a)], qm[m.row(s, a)] - phi[us], 1e-9);
    }
  }
}

// §3.3, Remark 1: V^pi_M' = V^pi_M - Phi for arbitrary (here random stochastic) policies, and so are Q^pi.
TEST(PotentialShaping, ShiftsTheValueOfEveryPolicyByMinusPhi) {
  for (int i = 0; i < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    UniformStream rng(3, static_cast<std::uint32_t>(i));
    const auto phi = random_potential(m, rng);
    const FiniteMdp shaped = shape_with_potential(m, phi);
    StochasticPolicy pi{m.num_states, m.num_actions, std::vector<double>(m.num_rows())};
    for (int s = 0; s < m.num_states; ++s) {
      double z = 0.0;
      for (int a = 0; a < m.num_actions; ++a) z += (pi.probs[m.row(s, a)] = rng.next());
      for (int a = 0; a < m.num_actions; ++a) pi.probs[m.row(s, a)] /= z;
    }
    const auto vm = evaluate_policy(m, pi), vs = evaluate_policy(shaped, pi);
    const auto qm = q_from_values(m, vm), qs = q_from_values(shaped, vs);
    for (int s = 0; s < m.num_states; ++s) {
      if (m.is_absorbing(s)) continue;
      const auto us = static_cast<std::size_t>(s);
      ASSERT_NEAR(vs[us], vm[us] - phi[us], 1e-9) << "MDP " << i;
      for (int a = 0; a < m.num_actions; ++a) ASSERT_NEAR(qs[m.row(s, a)], qm[m.row(s, a)] - phi[us], 1e-9);
    }
  }
}

// §3.3 (after Remark 2): for gamma < 1, R + c is potential shaping with Phi = -c/(1-gamma), so the optimal
// policies stay and V* rises by c/(1-gamma). Continuing MDPs only (see the next test).
TEST(ConstantRewardOffset, LeavesOptimalPolicyUnchangedForDiscountedMdps) {
  int tested = 0;
  for (int i = 0; i < 4 * kSuiteSize && tested < kSuiteSize; ++i) {
    auto o = test_support::suite_options(i);
    if (o.gamma == 1.0) continue;
    o.episodic = false;
    UniformStream rng(4, static_cast<std::uint32_t>(i));
    const FiniteMdp m = random_mdp(o, rng);
    const double c = 10.0 * (2.0 * rng.next() - 1.0);
    const FiniteMdp offset = add_constant_reward(m, c);
    const auto sm = policy_iteration(m), so = policy_iteration(offset);
    ASSERT_EQ(optimal_action_sets(m, q_from_values(m, sm.value)),
              optimal_action_sets(offset, q_from_values(offset, so.value)))
        << "MDP " << i;
    for (int s = 0; s < m.num_states; ++s)
      ASSERT_NEAR(so.value[static_cast<std::size_t>(s)],
                  sm.value[static_cast<std::size_t>(s)] + c / (1.0 - m.gamma),
                  1e-8 * (1.0 + std::abs(c) / (1.0 - m.gamma)));
    ++tested;
  }
  EXPECT_EQ(tested, kSuiteSize);
}

// The flip side: in an episodic task an offset is not potential-based (Phi(absorbing) would have to be
// -c/(1-gamma) != 0), and +2 per step in the gridworld makes reaching the goal a loss.
TEST(ConstantRewardOffset, CanChangeTheOptimalPolicyOfAnEpisodicTask) {
  FiniteMdpBuilder b(3, 2, 0.9);  // state 0: action 0 ends the episode at once, action 1 waits in 1
  b.set_absorbing(2);
  b.add_transition(0, 0, 2, 1.0, 0.0);
  b.add_transition(0, 1, 1, 1.0, -0.1);
  for (int a = 0; a < 2; ++a) b.add_transition(1, a, 2, 1.0, -0.1);
  const FiniteMdp m = b.build();
  EXPECT_EQ(policy_iteration(m).policy[0], 0);
  EXPECT_EQ(policy_iteration(add_constant_reward(m, 1.0)).policy[0], 1);
}

// Appendix 3.B, Theorem 5: with |Phi - V*| <= eps and gamma' < gamma, the gamma'-optimal policy of the
// shaped MDP loses at most 2 (gamma - gamma') eps / ((1 - gamma') (1 - gamma)) in M, measured exactly.
// Also reports how tight the bound is (largest observed loss / bound).
TEST(Theorem5, ShapedPolicyWithSmallerDiscountIsNearOptimal) {
  double worst_ratio = 0.0, sum_ratio = 0.0;
  int cases = 0, lossy = 0;
  for (int i = 0; i < 4 * kSuiteSize && cases < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    if (!(m.gamma > 0.0 && m.gamma < 1.0)) continue;
    UniformStream rng(5, static_cast<std::uint32_t>(i));
    const auto exact = policy_iteration(m);
    const double eps = std::pow(10.0, -2.0 + 2.5 * rng.next());  // 0.01 .. 3
    std::vector<double> phi(exact.value);
    for (int s = 0; s < m.num_states; ++s)
      if (!m.is_absorbing(s)) phi[static_cast<std::size_t>(s)] += eps * (2.0 * rng.next() - 1.0);
    const double gamma2 = m.gamma * rng.next();
    const FiniteMdp shaped_small = with_gamma(shape_with_potential(m, phi), gamma2);
    const auto pi = policy_iteration(shaped_small).policy;
    const auto v_pi = evaluate_policy(m, pi);
    const double bound = 2.0 * (m.gamma - gamma2) * eps / ((1.0 - gamma2) * (1.0 - m.gamma));
    double loss = 0.0;
    for (int s = 0; s < m.num_states; ++s)
      loss = std::max(loss, exact.value[static_cast<std::size_t>(s)] - v_pi[static_cast<std::size_t>(s)]);
    ASSERT_LE(loss, bound + 1e-9) << "MDP " << i << " gamma " << m.gamma << " gamma' " << gamma2 << " eps "
                                  << eps;
    worst_ratio = std::max(worst_ratio, loss / bound);
    sum_ratio += loss / bound;
    lossy += loss > 1e-9;
    ++cases;
  }
  EXPECT_EQ(cases, kSuiteSize);
  std::printf("[ Theorem 5 ] %d MDPs, %d with a positive loss; loss/bound: max %.3g, mean %.3g\n", cases,
              lossy, worst_ratio, sum_ratio / cases);
  RecordProperty("worst_loss_over_bound", std::to_string(worst_ratio));
  RecordProperty("mean_loss_over_bound", std::to_string(sum_ratio / cases));
}

// A random non-potential F on M's transitions: either action-dependent (Lemma 4) or a function of (s, s')
// alone that no potential explains (Appendix 3.A).
ShapingTable random_non_potential(const FiniteMdp& m, UniformStream& rng, bool action_dependent) {
  std::vector<ShapingEntry> e;
  std::vector<double> pair_value(static_cast<std::size_t>(m.num_states) *
                                 static_cast<std::size_t>(m.num_states));
  for (auto& x : pair_value) x = 2.0 * rng.next() - 1.0;
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    for (int a = 0; a < m.num_actions; ++a) {
      const std::size_t r = m.row(s, a);
      for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) {
        const int n = m.next_state[k];
        const double v =
            action_dependent
                ? 2.0 * rng.next() - 1.0
                : pair_value[static_cast<std::size_t>(s) * static_cast<std::size_t>(m.num_states) +
                             static_cast<std::size_t>(n)];
        e.push_back({s, a, n, v});
      }
    }
  }
  return ShapingTable(m.num_states, m.num_actions, std::move(e));
}

// §3.3, Theorem 1 (necessity), through the audit: for non-potential F it builds an MDP whose optimal
// action flips under F, and solving both confirms the flip.
TEST(PotentialShaping, NonPotentialShapingFlipsTheAuditCounterexample) {
  int flipped = 0, lemma4 = 0, appendix = 0, in_scope = 0, potential_by_chance = 0;
  for (int i = 0; i < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    UniformStream rng(6, static_cast<std::uint32_t>(i));
    const bool action_dependent = i % 2 == 0;
    const ShapingTable f = random_non_potential(m, rng, action_dependent);
    const ShapingAudit audit = audit_shaping(m, f);
    if (audit.potential_based) {  // e.g. a 2-state MDP whose transitions leave a random F unconstrained
      ++potential_by_chance;
      EXPECT_FALSE(audit.policy_change.changes) << "MDP " << i;
      continue;
    }
    ASSERT_TRUE(audit.counterexample.has_value()) << "MDP " << i << ": " << audit.counterexample_note;
    const Counterexample& cx = *audit.counterexample;
    EXPECT_TRUE(cx.verified) << "MDP " << i << ": " << cx.description;
    flipped += cx.verified;
    (audit.action_dependence ? lemma4 : appendix) += 1;
    in_scope += cx.uses_only_scope;
  }
  std::printf(
      "[ necessity ] %d flipped (%d Lemma 4, %d Appendix 3.A, %d within the scope), %d potential by chance\n",
      flipped, lemma4, appendix, in_scope, potential_by_chance);
  EXPECT_GE(flipped, kSuiteSize * 9 / 10);
  EXPECT_GT(appendix, kSuiteSize / 4);
}

// The audit recognises potential-based F and recovers a Phi that reproduces it.
TEST(ShapingAudit, RecognisesPotentialShapingOnRandomMdps) {
  for (int i = 0; i < kSuiteSize; ++i) {
    const FiniteMdp m = suite_mdp(i);
    UniformStream rng(7, static_cast<std::uint32_t>(i));
    const auto phi = random_potential(m, rng);
    const ShapingTable f = ShapingTable::from_potential(m, phi);
    const ShapingAudit audit = audit_shaping(m, f);
    ASSERT_TRUE(audit.potential_based) << "MDP " << i << " residual " << audit.max_residual;
    EXPECT_LT(audit.max_residual, 1e-9);
    EXPECT_FALSE(audit.policy_change.changes);
    EXPECT_FALSE(audit.counterexample.has_value());
  }
}

}  // namespace
}  // namespace pegasus
