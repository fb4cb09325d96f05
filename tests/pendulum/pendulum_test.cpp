// Pendulum-v1 (envs/pendulum.hpp): the model against steps of Gymnasium's equations worked out by hand
// (Python floats, which are IEEE doubles like numpy's float64), the reward, angle normalisation,
// determinism, the swing-up policy class, and a small training that clears the bar of issue 7.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/models/model.hpp"

namespace pegasus {
namespace {

static_assert(SimulativeModel<Pendulum>);
static_assert(PolicyFor<PendulumSwingUpPolicy, PendulumObservation, double>);

constexpr double kPi = std::numbers::pi;
const std::span<const double> kNoNoise{};

struct HandStep {
  double theta, theta_dot, u;               // state and action
  double next_theta, next_theta_dot, reward;  // pendulum.py's result
};

// Each row: one call of pendulum.py's step, computed in Python with its expressions in its order.
const HandStep kHandSteps[] = {
    {1.0, 0.5, 1.0, 1.064055161930296, 1.2811032386059225, -1.0259999999999998},
    {kPi / 2, 7.9, 5.0, 1.9707963267948965, 8.0, -8.71240110027234},    // torque and speed clipped
    {-2.5, -3.0, -0.7, -2.6776927054038984, -3.5538541080779673, -7.1504900000000005},
    {4.0, 1.0, 0.0, 4.021619906425952, 0.4323981285190538, -5.312935146920741},  // reward of the wrapped angle
    {-7.5, -7.9, -3.0, -7.9, -8.0, -7.725637996663638},  // both clips at the negative end, theta never wrapped
};

TEST(Pendulum, StepsAndRewardsMatchGymnasiumComputedByHand) {
  const Pendulum pendulum;
  for (const auto& h : kHandSteps) {
    const PendulumState s{h.theta, h.theta_dot};
    const PendulumState next = pendulum.step(s, h.u, kNoNoise);
    EXPECT_DOUBLE_EQ(next.theta, h.next_theta) << "theta " << h.theta << " thetadot " << h.theta_dot;
    EXPECT_DOUBLE_EQ(next.theta_dot, h.next_theta_dot) << "theta " << h.theta << " thetadot " << h.theta_dot;
    EXPECT_DOUBLE_EQ(pendulum.reward(s, h.u), h.reward) << "theta " << h.theta << " thetadot " << h.theta_dot;
  }
}

TEST(Pendulum, SemiImplicitEulerMovesTheAngleByTheNewRate) {
  const Pendulum pendulum;
  const PendulumState s{0.3, -1.2};
  const PendulumState next = pendulum.step(s, 0.8, kNoNoise);
  const double rate = -1.2 + (15.0 * std::sin(0.3) + 3.0 * 0.8) * 0.05;
  EXPECT_DOUBLE_EQ(next.theta_dot, rate);
  EXPECT_DOUBLE_EQ(next.theta, 0.3 + rate * 0.05);
}

TEST(Pendulum, AngleNormalisationIsPythonsFloorModulo) {
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(0.0), 0.0);
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(kPi), -kPi);  // [-pi, pi): +pi maps to -pi
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(-kPi), -kPi);
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(3 * kPi), -kPi);
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(7.0), 0.7168146928204138);
  EXPECT_DOUBLE_EQ(pendulum_angle_normalize(-7.0), -0.7168146928204138);
  for (double x = -40.0; x <= 40.0; x += 0.37) {
    const double y = pendulum_angle_normalize(x);
    EXPECT_GE(y, -kPi);
    EXPECT_LT(y, kPi);
    const double turns = (x - y) / (2 * kPi);
    EXPECT_NEAR(turns, std::round(turns), 1e-9) << x;
  }
}

TEST(Pendulum, RewardIsAtMostZeroAndZeroOnlyUprightAtRestWithoutTorque) {
  const Pendulum pendulum;
  EXPECT_EQ(pendulum.reward({0.0, 0.0}, 0.0), 0.0);
  EXPECT_EQ(pendulum.reward({2 * kPi, 0.0}, 0.0), 0.0);
  // The worst reward of Pendulum-v1: pi^2 + 0.1 * 8^2 + 0.001 * 2^2 (the torque is clipped first).
  EXPECT_DOUBLE_EQ(pendulum.reward({-kPi, 8.0}, -9.0), -(kPi * kPi + 6.4 + 0.004));
}

TEST(Pendulum, InitialStateMapsTheTwoUniformsOntoGymnasiumsStartBox) {
  const Pendulum pendulum;
  EXPECT_EQ(pendulum.initial_noise_dim(), 2);
  EXPECT_EQ(pendulum.noise_dim(), 0);
  const std::vector<double> low = {0.0, 0.0}, mid = {0.5, 0.5}, high = {1.0, 1.0};
  EXPECT_DOUBLE_EQ(pendulum.initial_state(low).theta, -kPi);
  EXPECT_DOUBLE_EQ(pendulum.initial_state(low).theta_dot, -1.0);
  EXPECT_DOUBLE_EQ(pendulum.initial_state(mid).theta, 0.0);
  EXPECT_DOUBLE_EQ(pendulum.initial_state(high).theta, kPi);
  EXPECT_DOUBLE_EQ(pendulum.initial_state(high).theta_dot, 1.0);
}

TEST(Pendulum, ObservationIsCosSinAndRate) {
  const Pendulum pendulum;
  const auto o = pendulum.observe({2.0, -3.0});
  EXPECT_DOUBLE_EQ(o.cos_theta, std::cos(2.0));
  EXPECT_DOUBLE_EQ(o.sin_theta, std::sin(2.0));
  EXPECT_DOUBLE_EQ(o.theta_dot, -3.0);
  EXPECT_FALSE(pendulum.terminal({1.0, 1.0}));
  ASSERT_EQ(pendulum.action_space().dim(), 1);
  EXPECT_DOUBLE_EQ(pendulum.action_space().high()[0], 2.0);
}

Theta swing_up_theta() { return {0.1, 0.5, 9.0, 2.2, 1.0}; }

TEST(PendulumPolicy, ZeroGainsApplyNoTorque) {
  const PendulumSwingUpPolicy policy;
  const Theta zero = policy.parameters().initial();
  for (double th = -3.0; th <= 3.0; th += 0.5)
    EXPECT_EQ(policy.act(zero, Pendulum().observe({th, 1.5 - th})), 0.0) << th;
}

TEST(PendulumPolicy, SwingUpPumpsEnergyAlongTheMotionAndTheStabiliserHoldsTheTop) {
  const PendulumSwingUpPolicy policy;
  const Theta w = swing_up_theta();
  // Hanging down and moving counter-clockwise: push counter-clockwise (energy in).
  EXPECT_GT(policy.act(w, Pendulum().observe({kPi - 0.2, 0.5})), 0.0);
  EXPECT_LT(policy.act(w, Pendulum().observe({kPi - 0.2, -0.5})), 0.0);
  // From 0.3 rad off upright at rest the pendulum is caught and stays within 0.05 rad for the rest of an
  // episode.
  const Pendulum pendulum;
  PendulumState s{0.3, 0.0};
  for (int t = 0; t < 200; ++t) s = pendulum.step(s, policy.act(w, pendulum.observe(s)), kNoNoise);
  EXPECT_LT(std::abs(pendulum_angle_normalize(s.theta)), 0.05);
  EXPECT_LT(std::abs(s.theta_dot), 0.05);
}

TEST(PendulumPolicy, SwingsUpFromRestHangingDown) {
  const PendulumSwingUpPolicy policy;
  const Theta w = swing_up_theta();
  const Pendulum pendulum;
  PendulumState s{kPi - 0.05, 0.0};
  double ret = 0.0;
  for (int t = 0; t < 200; ++t) {
    const double u = policy.act(w, pendulum.observe(s));
    ret += pendulum.reward(s, u);
    s = pendulum.step(s, u, kNoNoise);
  }
  EXPECT_LT(std::abs(pendulum_angle_normalize(s.theta)), 0.05);
  EXPECT_GT(ret, -500.0);  // hanging still without torque costs 200 pi^2 ~ -1974
}

TEST(PendulumEpisodes, ReturnsAreDeterministicAndIndependentOfThreads) {
  const Theta w = swing_up_theta();
  const auto once = pendulum_episode_returns(w, 40, 7);
  ThreadPool two(2);
  const auto threaded = pendulum_episode_returns(w, 40, 7, &two);
  ASSERT_EQ(once.size(), 40u);
  for (std::size_t i = 0; i < once.size(); ++i) EXPECT_EQ(once[i], threaded[i]) << i;
  EXPECT_EQ(pendulum_episode_returns(w, 40, 7), once);
  EXPECT_NE(pendulum_episode_returns(w, 40, 8), once);  // another seed, other starts
}

PendulumTrainingOptions small_training() {
  PendulumTrainingOptions o;
  o.scenarios = 16;
  o.optimizer.hill_climbing.max_iterations = 40;
  o.evaluation_episodes = 100;
  o.seed = 3;
  return o;
}

TEST(PendulumTraining, SmallSearchFromZeroGainsClearsTheBarOnFreshStarts) {
  const PendulumTrainingResult r = train_pendulum(small_training());
  EXPECT_GE(r.mean_return_100, -200.0);
  EXPECT_TRUE(std::isfinite(r.seconds_to_bar));
  EXPECT_GT(r.evaluations_to_bar, 0);
  EXPECT_LE(r.evaluations_to_bar, r.summary.evaluations);
  ASSERT_FALSE(r.checks.empty());
  EXPECT_LT(r.checks.front().mean_return, -200.0);  // the zero policy does not pass
  EXPECT_GE(r.checks.back().mean_return, -200.0);
  // The final mean return is that of the returned theta on the evaluation starts.
  const auto returns = pendulum_episode_returns(r.theta, 100, pendulum_evaluation_seed(3));
  EXPECT_DOUBLE_EQ(ordered_mean(returns), r.mean_return_100);
}

TEST(PendulumTraining, ThreadCountNeverChangesTheResult) {
  PendulumTrainingOptions o = small_training();
  o.optimizer.hill_climbing.max_iterations = 10;
  const auto one = train_pendulum(o);
  o.threads = 2;
  const auto two = train_pendulum(o);
  EXPECT_EQ(one.theta, two.theta);
  EXPECT_EQ(one.summary.best_value, two.summary.best_value);
  EXPECT_EQ(one.mean_return_100, two.mean_return_100);
  EXPECT_EQ(one.evaluations_to_bar, two.evaluations_to_bar);
}

TEST(PendulumTraining, ResumedFromACheckpointEndsLikeAnUninterruptedRun) {
  PendulumTrainingOptions o = small_training();
  o.optimizer.hill_climbing.max_iterations = 12;
  const auto whole = train_pendulum(o);
  std::vector<nlohmann::json> states;
  PendulumTrainingHooks hooks;
  hooks.checkpoint_every = 5;
  hooks.on_checkpoint = [&](const nlohmann::json& j) { states.push_back(j); };
  train_pendulum(o, hooks);
  ASSERT_GE(states.size(), 2u);
  PendulumTrainingHooks resume;
  resume.resume_from = states.front();
  const auto resumed = train_pendulum(o, resume);
  EXPECT_EQ(resumed.theta, whole.theta);
  EXPECT_EQ(resumed.mean_return_100, whole.mean_return_100);
  EXPECT_EQ(resumed.evaluations_to_bar, whole.evaluations_to_bar);
}

TEST(PendulumTraining, InvalidOptionsNameTheField) {
  PendulumTrainingOptions o;
  o.scenarios = 0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("scenarios"), std::string::npos);
  o = PendulumTrainingOptions{};
  o.evaluation_episodes = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("evaluation_episodes"), std::string::npos);
}

}  // namespace
}  // namespace pegasus
