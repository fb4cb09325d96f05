#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/flags.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/mdp_model.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/models/model.hpp"

namespace pegasus {
namespace {

static_assert(SimulativeModel<GridWorld>);
static_assert(TabularModel<GridWorld>);
static_assert(TabularModel<FlagWorld>);
static_assert(TabularModel<MdpModel>);

TEST(GridWorld, MovesIntendedEightyPercentAndUniformlyOtherwise) {
  const GridWorld w = corner_gridworld(5);
  const int centre = w.geometry().index({2, 2});
  // One uniform per step: (0, 0.8) keeps the action, then four bands of 0.05 for N, E, S, W.
  auto step = [&](int a, double u) { return w.step(centre, a, std::array<double, 1>{u}); };
  EXPECT_EQ(step(kNorth, 0.79), w.geometry().index({2, 3}));
  EXPECT_EQ(step(kNorth, 0.81), w.geometry().index({2, 3}));  // random direction happened to be north
  EXPECT_EQ(step(kNorth, 0.86), w.geometry().index({3, 2}));
  EXPECT_EQ(step(kNorth, 0.91), w.geometry().index({2, 1}));
  EXPECT_EQ(step(kNorth, 0.99), w.geometry().index({1, 2}));
  // Walls keep the agent in place.
  EXPECT_EQ(w.step(w.start(), kSouth, std::array<double, 1>{0.5}), w.start());
  EXPECT_EQ(w.step(w.start(), kWest, std::array<double, 1>{0.5}), w.start());
  EXPECT_TRUE(w.terminal(w.goal()));
  EXPECT_EQ(w.reward(w.start(), kNorth), -1.0);
}

TEST(GridWorld, TabulatedMdpMatchesTheSimulativeModel) {
  const GridWorld w = corner_gridworld(4);
  const FiniteMdp m = to_finite_mdp(w);
  ASSERT_EQ(m.num_states, 16);
  EXPECT_TRUE(m.is_absorbing(w.goal()));
  EXPECT_EQ(m.initial[static_cast<std::size_t>(w.start())], 1.0);
  // Integrate the model's step over a fine grid of uniforms and compare with P.
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    for (int a = 0; a < 4; ++a) {
      std::vector<double> p(16, 0.0);
      const int n = 20000;
      for (int i = 0; i < n; ++i)
        p[static_cast<std::size_t>(w.step(s, a, std::array<double, 1>{(i + 0.5) / n}))] += 1.0 / n;
      const std::size_t r = m.row(s, a);
      for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
        EXPECT_NEAR(p[static_cast<std::size_t>(m.next_state[k])], m.probability[k], 1e-9);
    }
  }
}

TEST(GridWorld, ManhattanPotentialIsTheThesisEstimate) {
  const GridWorld w = corner_gridworld(10);
  const auto phi = manhattan_potential(w);
  EXPECT_DOUBLE_EQ(phi[static_cast<std::size_t>(w.start())], -18.0 / 0.8);
  EXPECT_DOUBLE_EQ(phi[static_cast<std::size_t>(w.goal())], 0.0);
  EXPECT_DOUBLE_EQ(manhattan_potential(w, 0.5)[static_cast<std::size_t>(w.start())], -9.0 / 0.8);
}

TEST(GridWorld, RejectsBadGeometry) {
  EXPECT_THROW(corner_gridworld(1), InputError);
  EXPECT_THROW(GridWorld(GridGeometry(3, 3), {0, 0}, {0, 0}), InputError);
  EXPECT_THROW(GridWorld(GridGeometry(3, 3), {0, 0}, {3, 0}), InputError);
  EXPECT_THROW(GridWorld(GridGeometry(3, 3, {{1, 1}}), {0, 0}, {1, 1}), InputError);
  EXPECT_THROW(GridWorld(GridGeometry(3, 3), {0, 0}, {2, 2}, 0.0), InputError);
}

TEST(FlagWorld, CollectsFlagsOnlyInOrder) {
  const FlagWorld w = flags_5x5();  // flags (3,0), (4,3), (1,2), (0,4), goal (4,4)
  const auto& g = w.geometry();
  const std::array<double, 1> intended{0.1};
  int s = w.initial_state({});
  EXPECT_EQ(w.collected(s), 0);
  for (int i = 0; i < 3; ++i) s = w.step(s, kEast, intended);  // reach (3, 0): flag 1
  EXPECT_EQ(w.collected(s), 1);
  EXPECT_EQ(w.cell(s), g.index({3, 0}));
  // Walking over flag 3's cell (1, 2) before flag 2 collects nothing.
  int t = w.state_of(1, g.index({1, 1}));
  t = w.step(t, kNorth, intended);
  EXPECT_EQ(w.collected(t), 1);
  // From next to the goal with four flags, stepping on it ends the episode.
  int u = w.state_of(4, g.index({3, 4}));
  u = w.step(u, kEast, intended);
  EXPECT_TRUE(w.terminal(u));
  EXPECT_EQ(w.num_states(), 5 * 25 + 1);
}

TEST(FlagWorld, PotentialsFollowTheThesisFormulas) {
  const FlagWorld w = flags_5x5();
  EXPECT_DOUBLE_EQ(w.estimated_steps(), 18.0 / 0.8);
  const auto phi0 = flags_phi0(w), phi1 = flags_phi1(w);
  const double t = w.estimated_steps();
  const int s0 = w.initial_state({});
  EXPECT_DOUBLE_EQ(phi0[static_cast<std::size_t>(s0)], -((5 - 0 - 0.5) / 5) * t);
  // Phi0 jumps by t/5 at each subgoal.
  const int before = w.state_of(1, 0), after = w.state_of(2, 0);
  EXPECT_NEAR(phi0[static_cast<std::size_t>(after)] - phi0[static_cast<std::size_t>(before)], t / 5, 1e-12);
  EXPECT_DOUBLE_EQ(phi1[static_cast<std::size_t>(s0)], -18.0 / 0.8);
  EXPECT_EQ(phi0[static_cast<std::size_t>(w.terminal_state())], 0.0);
  EXPECT_EQ(phi1[static_cast<std::size_t>(w.terminal_state())], 0.0);
}

TEST(FlagWorld, TabulatedMdpIsProperAndItsOptimumIsSlowerThanTheRouteLength) {
  for (int size : {5, 8}) {
    const FlagWorld w = flag_world(size);
    const FiniteMdp m = to_finite_mdp(w);  // gamma = 1: validation checks properness
    const auto sol = policy_iteration(m);
    const double steps = -expected_under_initial(m, sol.value);
    EXPECT_GT(steps, w.remaining_path_length(w.initial_state({})));
    EXPECT_LT(steps, 1.5 * w.estimated_steps());
  }
  EXPECT_THROW(flag_world(6), InputError);
}

TEST(MdpModel, SamplesSuccessorsWithTheRowProbabilities) {
  const FiniteMdp m = to_finite_mdp(corner_gridworld(3));
  const MdpModel model(m);
  for (int a = 0; a < 4; ++a) {
    std::vector<double> p(9, 0.0);
    const int n = 10000;
    for (int i = 0; i < n; ++i)
      p[static_cast<std::size_t>(model.step(4, a, std::array<double, 1>{(i + 0.5) / n}))] += 1.0 / n;
    const std::size_t r = m.row(4, a);
    for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
      EXPECT_NEAR(p[static_cast<std::size_t>(m.next_state[k])], m.probability[k], 1e-3);
  }
  EXPECT_EQ(model.initial_state(std::array<double, 1>{0.3}), 0);
  EXPECT_EQ(model.reward(4, 0, 7), -1.0);
}

}  // namespace
}  // namespace pegasus
