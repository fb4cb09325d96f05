#include "pegasus/shaping/audit.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/policy_paths.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/shaping/potential_shaping.hpp"
#include "support/input_error.hpp"

namespace pegasus {

using test_support::input_error_message;
namespace {

using ::testing::HasSubstr;

// 0 --(both actions)--> 1 --> 2 (absorbing), gamma = 1.
FiniteMdp line() {
  FiniteMdpBuilder b(3, 2, 1.0);
  b.set_absorbing(2);
  for (int a = 0; a < 2; ++a) {
    b.add_transition(0, a, 1, 1.0, -1.0);
    b.add_transition(1, a, 2, 1.0, -1.0);
  }
  return b.build();
}

std::vector<double> manhattan_distances(const GridWorld& w) {
  std::vector<double> d(static_cast<std::size_t>(w.num_states()));
  for (int s = 0; s < w.num_states(); ++s) d[static_cast<std::size_t>(s)] = w.distance_to_goal(s);
  return d;
}

TEST(ShapingAudit, FindsTheActionDependenceOfLemma4AndFlipsItsCounterexample) {
  const FiniteMdp m = line();
  const ShapingTable f(3, 2, {{0, 0, 1, 1.0}, {0, 1, 1, 0.0}});
  const ShapingAudit audit = audit_shaping(m, f);
  EXPECT_FALSE(audit.potential_based);
  ASSERT_TRUE(audit.action_dependence.has_value());
  EXPECT_EQ(audit.action_dependence->state, 0);
  EXPECT_EQ(audit.action_dependence->next_state, 1);
  EXPECT_EQ(audit.action_dependence->action_high, 0);
  EXPECT_EQ(audit.action_dependence->action_low, 1);
  ASSERT_TRUE(audit.counterexample.has_value());
  const Counterexample& cx = *audit.counterexample;
  EXPECT_TRUE(cx.verified);
  EXPECT_EQ(cx.decision_state, 0);
  EXPECT_EQ(cx.optimal_actions, 0b10u);         // M prefers the action F rewards less ...
  EXPECT_EQ(cx.shaped_optimal_actions, 0b01u);  // ... M + F the one it rewards more
  EXPECT_THAT(cx.description, HasSubstr("Lemma 4"));
  // On the given MDP both actions do the same thing, so its optimal policy does not change here.
  EXPECT_FALSE(audit.policy_change.changes);
  EXPECT_THAT(audit.BriefReport(), HasSubstr("NOT potential-based"));
}

TEST(ShapingAudit, RecognisesTheGridworldPotentialAndRecoversPhi) {
  const GridWorld w = corner_gridworld(6);
  const FiniteMdp m = to_finite_mdp(w);
  const auto phi0 = manhattan_potential(w);
  const ShapingAudit audit = audit_shaping(m, ShapingTable::from_potential(m, phi0));
  ASSERT_TRUE(audit.potential_based);
  EXPECT_LT(audit.max_residual, 1e-9);
  // gamma = 1 and every state connects to the goal, where Phi = 0: Phi is unique.
  for (int s = 0; s < m.num_states; ++s)
    EXPECT_NEAR(audit.potential[static_cast<std::size_t>(s)], phi0[static_cast<std::size_t>(s)], 1e-8);
  EXPECT_FALSE(audit.policy_change.changes);
  EXPECT_THAT(audit.BriefReport(), HasSubstr("potential-based"));
}

// §3.1: reward for moving closer and nothing for moving away. A step back and a step forward collect the
// bonus net, so with a bonus above the two steps' cost the agent prefers shuttling to reaching the goal.
TEST(ShapingAudit, ProgressBonusHasAPositiveCycleAndChangesTheGridworldPolicy) {
  const GridWorld w = corner_gridworld(5);
  const FiniteMdp m = to_finite_mdp(w);
  const ShapingTable bonus = ShapingTable::progress_bonus(m, manhattan_distances(w), 3.0);
  const ShapingAudit audit = audit_shaping(m, bonus);
  EXPECT_FALSE(audit.potential_based);
  EXPECT_FALSE(audit.action_dependence.has_value());  // it depends on (s, s') only
  ASSERT_TRUE(audit.cycle.has_value());
  EXPECT_GT(audit.cycle->net_shaping, 0.0);
  const auto& c = *audit.cycle;
  // Each step of the cycle is a possible transition of the gridworld.
  for (std::size_t i = 0; i < c.states.size(); ++i) {
    const int u = c.states[i], v = c.states[(i + 1) % c.states.size()];
    bool possible = false;
    const std::size_t r = m.row(u, c.actions[i]);
    for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) possible |= m.next_state[k] == v;
    EXPECT_TRUE(possible);
  }
  ASSERT_TRUE(audit.counterexample.has_value());
  EXPECT_TRUE(audit.counterexample->verified);
  EXPECT_THAT(audit.counterexample->description, HasSubstr("Appendix 3.A"));
  EXPECT_TRUE(audit.policy_change.changes);
  EXPECT_GT(audit.policy_change.loss_under_initial, 1.0);  // the shaped optimum dawdles
  // A small bonus still is not potential-based (the audit does not care about the size).
  EXPECT_FALSE(
      audit_shaping(m, ShapingTable::progress_bonus(m, manhattan_distances(w), 0.1)).potential_based);
}

// The bug itself: the optimal policy of the gridworld with the progress bonus, followed along its most
// likely transitions, goes round a cycle instead of reaching the goal; with the potential-based version
// of the same hint (Phi = -bonus * manhattan) it walks straight to the goal.
TEST(ProgressBonus, OptimalPolicyCyclesWhereThePotentialVersionReachesTheGoal) {
  const GridWorld w = corner_gridworld(5);
  const FiniteMdp m = to_finite_mdp(w);
  const auto d = manhattan_distances(w);
  const FiniteMdp bonus = add_shaping(m, ShapingTable::progress_bonus(m, d, 3.0));
  const auto bad = most_likely_path(m, policy_iteration(bonus).policy, w.start());
  EXPECT_FALSE(bad.reaches_absorbing);
  EXPECT_GE(bad.cycle().size(), 2u);
  std::vector<double> phi(d.size());
  for (std::size_t s = 0; s < d.size(); ++s) phi[s] = -3.0 * d[s];
  const auto good = most_likely_path(m, policy_iteration(shape_with_potential(m, phi)).policy, w.start());
  EXPECT_TRUE(good.reaches_absorbing);
  EXPECT_EQ(good.states.size(), 9u);  // 8 steps from corner to corner
  EXPECT_TRUE(good.cycle().empty());
}

TEST(ShapingAudit, ScopeIncludesListedTransitionsThatCannotHappen) {
  const FiniteMdp m = line();
  // Consistent with Phi = (-2, -1, 0) on the support, but the listed 0 -> 0 entry demands Phi(0) - Phi(0)
  // = 5.
  const ShapingTable ok(3, 2, {{0, 0, 1, 1.0}, {0, 1, 1, 1.0}, {1, 0, 2, 1.0}, {1, 1, 2, 1.0}});
  EXPECT_TRUE(audit_shaping(m, ok).potential_based);
  const ShapingTable bad(3, 2,
                         {{0, 0, 1, 1.0}, {0, 1, 1, 1.0}, {1, 0, 2, 1.0}, {1, 1, 2, 1.0}, {0, 0, 0, 5.0}});
  const ShapingAudit audit = audit_shaping(m, bad);
  EXPECT_FALSE(audit.potential_based);
  EXPECT_EQ(audit.scope_size, 5u);
  ASSERT_TRUE(audit.counterexample.has_value());
  EXPECT_TRUE(audit.counterexample->verified);
}

TEST(ShapingAudit, RejectsTablesOfAnotherShapeAndBadOptions) {
  const FiniteMdp m = line();
  EXPECT_THAT(input_error_message([&] { audit_shaping(m, ShapingTable(4, 2, {})); }),
              HasSubstr("4 states x 2 actions"));
  AuditOptions o;
  o.tolerance = 0.0;
  EXPECT_THAT(input_error_message([&] { audit_shaping(m, ShapingTable(3, 2, {}), o); }),
              HasSubstr("tolerance must be > 0"));
}

TEST(ShapingTable, RoundTripsThroughJsonAndNamesFileAndFieldInErrors) {
  const ShapingTable f(3, 2, {{1, 0, 2, -0.1}, {0, 1, 1, 0.30000000000000004}});
  const auto path = (std::filesystem::temp_directory_path() / "pegasus_shaping_test.json").string();
  save_shaping(f, path);
  const ShapingTable g = load_shaping(path);
  ASSERT_EQ(g.entries().size(), 2u);
  EXPECT_EQ(g(0, 1, 1), 0.30000000000000004);
  EXPECT_EQ(g(1, 0, 2), -0.1);
  EXPECT_EQ(g(2, 0, 0), 0.0);  // unlisted
  std::filesystem::remove(path);

  auto j = shaping_to_json(f);
  j["entries"][1][2] = 3;
  EXPECT_THAT(input_error_message([&] { shaping_from_json(j, "f.json"); }),
              HasSubstr("f.json: entries[1][2]: expected a next_state in [0, 3), got 3"));
  j = shaping_to_json(f);
  j["entries"].push_back(j["entries"][0]);
  EXPECT_THAT(input_error_message([&] { shaping_from_json(j, "f.json"); }),
              HasSubstr("f.json: entries: triple (0, 1, 1) listed twice"));
  j = shaping_to_json(f);
  j["entries"][0] = nlohmann::json::array({0, 1, 1});
  EXPECT_THAT(input_error_message([&] { shaping_from_json(j, "f.json"); }),
              HasSubstr("f.json: entries[0]: expected [state, action, next_state, F], got [0,1,1]"));
  j = shaping_to_json(f);
  j.erase("num_actions");
  EXPECT_THAT(input_error_message([&] { shaping_from_json(j, "f.json"); }),
              HasSubstr("f.json: num_actions: missing"));
  EXPECT_THAT(input_error_message([] { load_shaping("/nonexistent/f.json"); }),
              HasSubstr("/nonexistent/f.json: expected a readable shaping file"));
}

}  // namespace
}  // namespace pegasus
