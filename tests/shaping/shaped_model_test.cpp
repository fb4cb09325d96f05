#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "pegasus/envs/flags.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/learners.hpp"
#include "pegasus/mdp/mdp_model.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/random/block_stream.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

using ShapedGrid = ShapedModel<GridWorld, TablePotential>;
static_assert(SimulativeModel<ShapedGrid>);
static_assert(TabularModel<ShapedGrid>);
static_assert(TabularModel<ProgressBonusModel<GridWorld, TablePotential>>);

TEST(ShapedModel, AddsGammaPhiNextMinusPhiWithZeroAtTerminalStates) {
  const GridWorld w = corner_gridworld(4);
  const auto phi = manhattan_potential(w);
  const auto shaped = shape(w, TablePotential{phi}, 0.9);
  const int s = w.geometry().index({1, 1}), n = w.geometry().index({1, 2});
  EXPECT_DOUBLE_EQ(shaped.reward(s, kNorth, n),
                   -1.0 + 0.9 * phi[static_cast<std::size_t>(n)] - phi[static_cast<std::size_t>(s)]);
  // Entering the goal: Phi(goal) counts as 0 whatever the table says.
  TablePotential odd{phi};
  odd.values[static_cast<std::size_t>(w.goal())] = 100.0;
  const int near = w.geometry().index({3, 2});
  EXPECT_DOUBLE_EQ(shape(w, odd, 0.9).reward(near, kNorth, w.goal()),
                   -1.0 - phi[static_cast<std::size_t>(near)]);
  EXPECT_DOUBLE_EQ(shape(w, odd, 0.9, false).reward(near, kNorth, w.goal()),
                   -1.0 + 90.0 - phi[static_cast<std::size_t>(near)]);
  // Everything but the reward is the wrapped model's.
  const std::array<double, 1> u{0.3};
  EXPECT_EQ(shaped.step(s, kEast, u), w.step(s, kEast, u));
  EXPECT_EQ(shaped.num_states(), w.num_states());
}

// The shaping collected along any episode telescopes to -Phi(s0) (§3.3): the return changes by a constant.
TEST(ShapedModel, EpisodeReturnShiftsByMinusPhiOfTheStart) {
  const GridWorld w = corner_gridworld(6);
  const auto phi = manhattan_potential(w, 0.7);
  for (double gamma : {1.0, 0.95}) {
    const auto shaped = shape(w, TablePotential{phi}, gamma);
    BlockUniformStream rng(3, 0);
    for (int episode = 0; episode < 20; ++episode) {
      int s = w.start();
      double ret = 0.0, shaped_ret = 0.0, discount = 1.0;
      for (int t = 0; t < 100000 && !w.terminal(s); ++t) {
        const int a = static_cast<int>(rng.next_below(4));
        const std::array<double, 1> p{rng.next()};
        const int n = w.step(s, a, p);
        ret += discount * w.reward(s, a);
        shaped_ret += discount * shaped.reward(s, a, n);
        discount *= gamma;
        s = n;
      }
      ASSERT_TRUE(w.terminal(s));
      EXPECT_NEAR(shaped_ret, ret - phi[static_cast<std::size_t>(w.start())], 1e-9);
    }
  }
}

// A semi-MDP: a chain whose steps take random durations tau; rewards and potentials are discounted by
// exp(-beta * elapsed time). With F = exp(-beta tau) Phi(s') - Phi(s) (§3.5) the shaping still telescopes.
struct TimedChain {
  using State = int;
  using Action = int;
  using Observation = int;
  int length = 6;
  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  State initial_state(std::span<const double>) const { return 0; }
  State step(State s, Action a, std::span<const double>) const { return std::min(length, s + 1 + a); }
  double reward(State, Action) const { return -1.0; }
  bool terminal(State s) const { return s == length; }
  Observation observe(State s) const { return s; }
  ActionSpace action_space() const { return ActionSpace::finite(2); }
};
static_assert(SimulativeModel<TimedChain>);

TEST(ShapedModel, SmdpFormTelescopesUnderContinuousTimeDiscounting) {
  const double beta = 0.3;
  const TablePotential phi{{-4.0, -3.5, -2.0, -1.0, 3.0, 0.5, 0.0}};
  auto duration = [](int s, int a, int) { return 0.5 + 0.25 * s + a; };
  const auto shaped = shape_smdp(TimedChain{}, phi, beta, duration);
  const TimedChain base;
  for (int pattern = 0; pattern < 8; ++pattern) {
    int s = 0, t = 0;
    double elapsed = 0.0, shaping = 0.0;
    while (!base.terminal(s)) {
      const int a = (pattern >> (t++ % 3)) & 1;
      const int n = base.step(s, a, {});
      shaping += std::exp(-beta * elapsed) * (shaped.reward(s, a, n) - base.reward(s, a));
      elapsed += duration(s, a, n);
      s = n;
    }
    EXPECT_NEAR(shaping, -phi(0), 1e-12);
  }
}

// A model with an event at fraction tau of the step into the goal (footnote 9 of §4.4): the evaluator
// discounts that reward by gamma^(t + tau); the wrapper pre-scales F so that it still telescopes.
struct EventChain : TimedChain {
  double event_fraction(const State&, const Action&, const State& next) const {
    return next == length ? 0.4 : 0.0;
  }
};
static_assert(HasEventFraction<EventChain>);

TEST(ShapedModel, CompensatesEventFractionDiscounting) {
  const double gamma = 0.9;
  const TablePotential phi{{-4.0, -3.5, -2.0, -1.0, 3.0, 0.5, 0.0}};
  const auto shaped = shape(EventChain{}, phi, gamma);
  static_assert(HasEventFraction<decltype(shaped)>);
  const EventChain base;
  int s = 0, t = 0;
  double shaping = 0.0;
  while (!base.terminal(s)) {
    const int n = base.step(s, 0, {});
    const double tau = transition_event_fraction(shaped, s, 0, n);
    shaping += std::pow(gamma, t + tau) * (shaped.reward(s, 0, n) - base.reward(s, 0));
    ++t;
    s = n;
  }
  EXPECT_NEAR(shaping, -phi(0), 1e-12);
}

TEST(ShapedModel, AgreesWithTheShapedFiniteMdp) {
  const GridWorld w = corner_gridworld(4);
  const FiniteMdp m = to_finite_mdp(w, 0.9);
  const auto phi = manhattan_potential(w, 0.5);
  const FiniteMdp shaped_mdp = shape_with_potential(m, phi);
  const MdpModel base(m), direct(shaped_mdp);
  const auto wrapped = shape(base, TablePotential{phi}, 0.9);
  for (int s = 0; s < m.num_states; ++s)
    for (int a = 0; a < 4; ++a)
      for (int d = 0; d < 4; ++d) {
        const int n = w.geometry().move(s, d);
        if (m.is_absorbing(s)) continue;
        EXPECT_NEAR(wrapped.reward(s, a, n), direct.reward(s, a, n), 1e-12);
      }
}

TEST(ProgressBonusModel, PaysOnlyForMovingCloser) {
  const GridWorld w = corner_gridworld(5);
  std::vector<double> d(static_cast<std::size_t>(w.num_states()));
  for (int s = 0; s < w.num_states(); ++s) d[static_cast<std::size_t>(s)] = w.distance_to_goal(s);
  const ProgressBonusModel bonus(w, TablePotential{d}, 0.5);
  const int s = w.geometry().index({2, 2});
  EXPECT_EQ(bonus.reward(s, kNorth, w.geometry().index({2, 3})), -0.5);
  EXPECT_EQ(bonus.reward(s, kSouth, w.geometry().index({2, 1})), -1.0);
  EXPECT_EQ(bonus.reward(s, kSouth, s), -1.0);
}

// A small version of Fig 3.2a: Sarsa (alpha 0.02, 0.1-greedy, Q = 0) reaches the goal much sooner in the
// first episodes with Phi0 = -manhattan/0.8 and with 0.5 Phi0 than without shaping.
TEST(ShapedModel, PotentialShapingSpeedsUpSarsaOnTheGridworld) {
  const GridWorld w = corner_gridworld(10);
  TdOptions o;
  o.episodes = 10;
  auto mean_steps = [&](auto model) {
    double total = 0.0;
    for (std::uint32_t run = 0; run < 8; ++run) {
      BlockUniformStream rng(2026, run);
      QTable q(w.num_states(), 4);
      total += static_cast<double>(sarsa(model, o, rng, q).total_steps);
    }
    return total / (8.0 * o.episodes);
  };
  const double none = mean_steps(w);
  const double half = mean_steps(shape(w, TablePotential{manhattan_potential(w, 0.5)}, 1.0));
  const double full = mean_steps(shape(w, TablePotential{manhattan_potential(w, 1.0)}, 1.0));
  EXPECT_LT(full, 0.5 * none);
  EXPECT_LT(half, 0.8 * none);
}

TEST(FlagShaping, Phi0AndPhi1ArePotentialShapingOfTheFlagWorld) {
  const FlagWorld w = flags_5x5();
  const FiniteMdp m = to_finite_mdp(w);
  const auto base = policy_iteration(m).value;
  for (const auto& phi : {flags_phi0(w), flags_phi1(w)}) {
    const auto shaped = policy_iteration(shape_with_potential(m, phi)).value;
    for (int s = 0; s < m.num_states; ++s)
      EXPECT_NEAR(shaped[static_cast<std::size_t>(s)],
                  base[static_cast<std::size_t>(s)] - phi[static_cast<std::size_t>(s)], 1e-8);
  }
}

}  // namespace
}  // namespace pegasus
