#include "pegasus/mdp/finite_mdp.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>

#include "pegasus/core/error.hpp"
#include "pegasus/mdp/random_mdp.hpp"
#include "support/input_error.hpp"

namespace pegasus {

using test_support::input_error_message;
namespace {

using ::testing::HasSubstr;

// 0 -> 1 -> 2 (absorbing), one action.
FiniteMdp chain(double gamma) {
  FiniteMdpBuilder b(3, 1, gamma);
  b.set_absorbing(2);
  b.add_transition(0, 0, 1, 1.0, -1.0);
  b.add_transition(1, 0, 2, 1.0, -1.0);
  return b.build();
}

TEST(FiniteMdp, BuilderAddsTheThreeRewardFormsAndMergesDuplicateSuccessors) {
  FiniteMdpBuilder b(3, 2, 0.9);
  b.set_absorbing(2);
  b.set_state_reward(0, 1.0);             // R(s)
  b.set_state_action_reward(0, 1, 10.0);  // R(s, a)
  b.add_transition(0, 0, 1, 0.25, 2.0);   // R(s, a, s')
  b.add_transition(0, 0, 1, 0.25, 4.0);   // merged with the previous: p 0.5, reward 3
  b.add_transition(0, 0, 2, 0.5);
  b.add_transition(0, 1, 0, 1.0);
  for (int a = 0; a < 2; ++a) b.add_transition(1, a, 2, 1.0, -1.0);
  const FiniteMdp m = b.build();
  EXPECT_EQ(m.num_entries(), 2u + 1u + 2u + 2u);  // absorbing rows hold one self-loop each
  EXPECT_DOUBLE_EQ(m.expected_reward[m.row(0, 0)], 0.5 * (3.0 + 1.0) + 0.5 * 1.0);
  EXPECT_DOUBLE_EQ(m.expected_reward[m.row(0, 1)], 11.0);
  EXPECT_DOUBLE_EQ(m.expected_reward[m.row(2, 0)], 0.0);
  EXPECT_TRUE(m.is_absorbing(2));
  // Default D: uniform over the non-absorbing states.
  EXPECT_DOUBLE_EQ(m.initial[0], 0.5);
  EXPECT_DOUBLE_EQ(m.initial[2], 0.0);
}

TEST(FiniteMdp, RejectsRowsThatDoNotSumToOneWithin1e9) {
  FiniteMdpBuilder b(2, 1, 0.9);
  b.add_transition(0, 0, 1, 0.5);
  b.add_transition(0, 0, 0, 0.5 - 2e-9);
  b.add_transition(1, 0, 1, 1.0);
  EXPECT_THAT(input_error_message([&] { b.build(); }), HasSubstr("state 0 action 0: probabilities sum to"));

  FiniteMdpBuilder ok(2, 1, 0.9);
  ok.add_transition(0, 0, 1, 0.5);
  ok.add_transition(0, 0, 0, 0.5 - 5e-10);
  ok.add_transition(1, 0, 1, 1.0);
  EXPECT_NO_THROW(ok.build());
}

TEST(FiniteMdp, RejectsProbabilitiesOutsideTheUnitInterval) {
  FiniteMdpBuilder b(2, 1, 0.9);
  EXPECT_THAT(input_error_message([&] { b.add_transition(0, 0, 1, 1.5); }), HasSubstr("outside [0, 1]"));
  EXPECT_THAT(input_error_message([&] { b.add_transition(0, 0, 1, -0.1); }), HasSubstr("outside [0, 1]"));
  // And in an MDP assembled by hand.
  FiniteMdp m = chain(0.9);
  m.probability[0] = 1.25;
  EXPECT_THAT(input_error_message([&] { validate(m, "hand.json"); }),
              HasSubstr("hand.json: state 0 action 0: probability 1.25"));
}

TEST(FiniteMdp, RejectsMissingRowsBadIndicesAndBadGamma) {
  FiniteMdpBuilder b(2, 2, 0.9);
  b.add_transition(0, 0, 1, 1.0);
  b.add_transition(1, 0, 1, 1.0);
  b.add_transition(1, 1, 1, 1.0);
  EXPECT_THAT(input_error_message([&] { b.build(); }),
              HasSubstr("no transitions given for state 0 action 1"));
  EXPECT_THAT(input_error_message([&] { b.add_transition(0, 0, 7, 1.0); }),
              HasSubstr("successor state 7 outside [0, 2)"));
  EXPECT_THAT(input_error_message([&] { b.add_transition(0, 2, 0, 1.0); }),
              HasSubstr("action 2 outside [0, 2)"));
  EXPECT_THAT(input_error_message([] { FiniteMdpBuilder(2, 2, 1.5); }),
              HasSubstr("gamma must lie in [0, 1]"));
  FiniteMdp m = chain(0.9);
  m.reward[m.row_start[m.row(2, 0)]] = 1.0;  // an absorbing state that pays
  EXPECT_THAT(input_error_message([&] { validate(m); }),
              HasSubstr("absorbing state 2 must loop to itself with reward 0"));
}

TEST(FiniteMdp, UndiscountedMdpMustBeProperUnderEveryPolicy) {
  EXPECT_NO_THROW(chain(1.0));
  // Action 1 in state 1 loops forever: improper, although action 0 would reach the absorbing state.
  FiniteMdpBuilder b(3, 2, 1.0);
  b.set_absorbing(2);
  for (int a = 0; a < 2; ++a) b.add_transition(0, a, 1, 1.0, -1.0);
  b.add_transition(1, 0, 2, 1.0, -1.0);
  b.add_transition(1, 1, 1, 1.0, -1.0);
  EXPECT_THAT(input_error_message([&] { b.build(); }), HasSubstr("requires a proper MDP, but from state"));
  // The same MDP is fine when discounted, and the check names a trapping state.
  FiniteMdp m = chain(0.9);
  EXPECT_FALSE(find_improper_state(m).has_value());
  FiniteMdpBuilder d(3, 2, 0.9);
  d.set_absorbing(2);
  for (int a = 0; a < 2; ++a) d.add_transition(0, a, 1, 1.0, -1.0);
  d.add_transition(1, 0, 2, 1.0, -1.0);
  d.add_transition(1, 1, 0, 0.5);
  d.add_transition(1, 1, 1, 0.5);
  const auto bad = find_improper_state(d.build());
  ASSERT_TRUE(bad.has_value());
  EXPECT_TRUE(*bad == 0 || *bad == 1);
}

TEST(FiniteMdp, StochasticLeakMakesACycleProper) {
  // A cycle 0 <-> 1 that leaks to the absorbing state with probability 0.1 per step is proper.
  FiniteMdpBuilder b(3, 1, 1.0);
  b.set_absorbing(2);
  b.add_transition(0, 0, 1, 0.9);
  b.add_transition(0, 0, 2, 0.1);
  b.add_transition(1, 0, 0, 1.0);
  EXPECT_NO_THROW(b.build());
}

TEST(FiniteMdp, RandomEpisodicMdpsAreProper) {
  UniformStream rng(7, 0);
  for (int i = 0; i < 50; ++i) {
    RandomMdpOptions o;
    o.num_states = 2 + i % 20;
    o.num_actions = 1 + i % 4;
    o.successors = 1 + i % o.num_states;
    o.gamma = 1.0;
    const FiniteMdp m = random_mdp(o, rng);
    EXPECT_FALSE(find_improper_state(m).has_value());
  }
}

}  // namespace
}  // namespace pegasus
