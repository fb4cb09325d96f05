// Pendulum-v1 (envs/pendulum.hpp): the model against steps of Gymnasium's equations worked out by hand
// (Python floats, which are IEEE doubles like numpy's float64), the reward, angle normalisation,
// determinism, the swing-up policy class, and a small training that clears the bar of issue 7.
#include "pegasus/envs/pendulum.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {
namespace {

static_assert(SimulativeModel<Pendulum>);
static_assert(PolicyFor<PendulumSwingUpPolicy, PendulumObservation, double>);

constexpr double kPi = std::numbers::pi;
const std::span<const double> kNoNoise{};

struct HandStep {
  double theta, theta_dot, u;                 // state and action
  double next_theta, next_theta_dot, reward;  // pendulum.py's result
};

// Each row: one call of pendulum.py's step, computed in Python with its expressions in its order.
const HandStep kHandSteps[] = {
    {1.0, 0.5, 1.0, 1.064055161930296, 1.2811032386059225, -1.0259999999999998},
    {kPi / 2, 7.9, 5.0, 1.9707963267948965, 8.0, -8.71240110027234},  // torque and speed clipped
    {-2.5, -3.0, -0.7, -2.6776927054038984, -3.5538541080779673, -7.1504900000000005},
    {4.0, 1.0, 0.0, 4.021619906425952, 0.4323981285190538,
     -5.312935146920741},  // reward of the wrapped angle
    {-7.5, -7.9, -3.0, -7.9, -8.0,
     -7.725637996663638},  // both clips at the negative end, theta never wrapped
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

// A five-number swing-up as the full class (lead and skew 0).
Theta swing_up_theta() { return {0.1, 0.5, 9.0, 2.2, 1.0, 0.0, 0.0}; }

TEST(PendulumPolicy, TheFullClassExtendsTheFiveNumberClassByTheLeadAndTheSkew) {
  const PendulumSwingUpPolicy five(false), seven;
  ASSERT_EQ(five.parameters().size(), PendulumSwingUpPolicy::kBaseCount);
  ASSERT_EQ(seven.parameters().size(), static_cast<std::size_t>(PendulumSwingUpPolicy::kCount));
  for (std::size_t k = 0; k < five.parameters().size(); ++k) {
    EXPECT_EQ(five.parameters()[k].name, seven.parameters()[k].name);
    EXPECT_EQ(five.parameters()[k].initial, seven.parameters()[k].initial);
  }
  EXPECT_EQ(seven.parameters()[PendulumSwingUpPolicy::kSwingLead].name, "swing.lead");
  EXPECT_EQ(seven.parameters()[PendulumSwingUpPolicy::kStabiliseSkew].name, "stabilise.skew");
  EXPECT_EQ(pendulum_full_theta(five.parameters().initial()), seven.parameters().initial());
}

TEST(PendulumPolicy, LeadAndSkewAtZeroActExactlyAsTheFiveNumberPolicy) {
  const PendulumSwingUpPolicy policy;
  const Pendulum pendulum;
  const std::vector<Theta> fives = {
      {0.1, 0.5, 9.0, 2.2, 1.0}, {0.3, -2.0, 20.0, 5.0, 0.4}, {5.0, 8.0, 1.0, 0.1, 2.5}};
  for (const Theta& five : fives) {
    const Theta full = pendulum_full_theta(five);
    ASSERT_EQ(full.size(), static_cast<std::size_t>(PendulumSwingUpPolicy::kCount));
    EXPECT_EQ(full[PendulumSwingUpPolicy::kSwingLead], 0.0);
    EXPECT_EQ(full[PendulumSwingUpPolicy::kStabiliseSkew], 0.0);
    for (double th = -3.1; th <= 3.1; th += 0.13)
      for (double rate = -8.0; rate <= 8.0; rate += 0.7) {
        const auto o = pendulum.observe({th, rate});
        EXPECT_EQ(policy.act(full, o), policy.act(five, o)) << th << " " << rate;
      }
  }
  // And whole episodes: the returns of the full class at lead = skew = 0 are those of the five numbers,
  // here against a rollout of the five-number theta written out by hand.
  const Theta five = fives[1];
  const auto returns = pendulum_episode_returns(pendulum_full_theta(five), 20, 11);
  const ScenarioSet starts({.seed = 11, .count = 20, .horizon = 200, .noise_dim = 0, .initial_noise_dim = 2});
  for (int i = 0; i < 20; ++i) {
    double p0[2];
    starts.initial_noise(i, p0);
    PendulumState s = pendulum.initial_state(p0);
    double ret = 0.0;
    for (int t = 0; t < 200; ++t) {
      const double u = policy.act(five, pendulum.observe(s));
      ret += pendulum.reward(s, u);
      s = pendulum.step(s, u, kNoNoise);
    }
    EXPECT_EQ(returns[static_cast<std::size_t>(i)], ret) << i;
  }
}

TEST(PendulumPolicy, TheLeadTurnsThePushBeforeTheSwingTurns) {
  const PendulumSwingUpPolicy policy;
  const Pendulum pendulum;
  Theta w = swing_up_theta();
  // Low on the negative side (theta = -2.5, gravity pulls theta further negative) and still rising slowly:
  // without a lead the pump pushes along the motion, with one it already pushes the way of the fall.
  const auto o = pendulum.observe({-2.5, 0.4});
  EXPECT_GT(policy.act(w, o), 0.0);
  w[PendulumSwingUpPolicy::kSwingLead] = 2.0;  // 0.4 + 2 sin(-2.5) < 0
  EXPECT_LT(policy.act(w, o), 0.0);
}

TEST(PendulumPolicy, TheSkewCatchesAPendulumArrivingFastAndLetsOneLeaving) {
  const PendulumSwingUpPolicy policy;
  const Pendulum pendulum;
  Theta w = swing_up_theta();  // region 1 rad
  w[PendulumSwingUpPolicy::kStabiliseSkew] = 0.2;
  const double k_p = w[PendulumSwingUpPolicy::kStabiliseAngle],
               k_d = w[PendulumSwingUpPolicy::kStabiliseRate];
  // 1.2 rad off upright, arriving at 2 rad/s: 1.2 - 0.4 = 0.8 < 1, so the stabiliser acts (saturated here).
  EXPECT_EQ(policy.act(w, pendulum.observe({1.2, -2.0})), std::clamp(-k_p * 1.2 + k_d * 2.0, -2.0, 2.0));
  // 0.9 rad off and leaving at 1 rad/s: 0.9 + 0.2 = 1.1, so the swing-up acts (its energy formula).
  const double energy = 0.5 + 15.0 * std::cos(0.9);
  EXPECT_EQ(policy.act(w, pendulum.observe({0.9, 1.0})),
            std::clamp(0.1 * (15.0 + 0.5 - energy) * 1.0, -2.0, 2.0));
}

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
  o.refine_scenarios = 24;
  o.refine_optimizer.hill_climbing.max_iterations = 8;
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
  o.refine_optimizer.hill_climbing.max_iterations = 4;
  const auto one = train_pendulum(o);
  o.threads = 2;
  const auto two = train_pendulum(o);
  EXPECT_EQ(one.theta, two.theta);
  EXPECT_EQ(one.summary.best_value, two.summary.best_value);
  EXPECT_EQ(one.refine_summary.best_value, two.refine_summary.best_value);
  EXPECT_EQ(one.race_mean_return_100, two.race_mean_return_100);
  EXPECT_EQ(one.mean_return_100, two.mean_return_100);
  EXPECT_EQ(one.evaluations_to_bar, two.evaluations_to_bar);
}

TEST(PendulumTraining, ResumedFromACheckpointOfEitherStageEndsLikeAnUninterruptedRun) {
  PendulumTrainingOptions o = small_training();
  o.optimizer.hill_climbing.max_iterations = 12;
  o.refine_optimizer.hill_climbing.max_iterations = 10;
  const auto whole = train_pendulum(o);
  std::vector<nlohmann::json> states;
  PendulumTrainingHooks hooks;
  hooks.checkpoint_every = 5;
  hooks.on_checkpoint = [&](const nlohmann::json& j) { states.push_back(j); };
  train_pendulum(o, hooks);
  // Race checkpoints after iterations 5 and 10, one between the stages, refinement ones after 5 and 10.
  ASSERT_EQ(states.size(), 5u);
  EXPECT_EQ(states[0].at("stage"), 0);
  EXPECT_EQ(states[2].at("stage"), 1);
  EXPECT_TRUE(states[2].at("optimizer").is_null());
  EXPECT_EQ(states[3].at("stage"), 1);
  for (const std::size_t k : {std::size_t{0}, std::size_t{2}, std::size_t{3}}) {
    PendulumTrainingHooks resume;
    resume.resume_from = states[k];
    const auto resumed = train_pendulum(o, resume);
    EXPECT_EQ(resumed.theta, whole.theta) << k;
    EXPECT_EQ(resumed.race_mean_return_100, whole.race_mean_return_100) << k;
    EXPECT_EQ(resumed.mean_return_100, whole.mean_return_100) << k;
    EXPECT_EQ(resumed.evaluations_to_bar, whole.evaluations_to_bar) << k;
    std::string difference;
    EXPECT_TRUE(SameOutcome(resumed.summary, whole.summary, &difference)) << k << ": " << difference;
    EXPECT_TRUE(SameOutcome(resumed.refine_summary, whole.refine_summary, &difference))
        << k << ": " << difference;
  }
  // A stage-2 checkpoint cannot continue a run configured without the refinement.
  PendulumTrainingOptions race_only = o;
  race_only.refine_scenarios = 0;
  PendulumTrainingHooks resume;
  resume.resume_from = states[3];
  EXPECT_THROW(train_pendulum(race_only, resume), InputError);
}

TEST(PendulumTraining, TheRaceIsTheFiveNumberSearchAndTheRefinementStartsWhereItEnded) {
  PendulumTrainingOptions o = small_training();
  o.refine_scenarios = 0;
  const auto race = train_pendulum(o);
  EXPECT_TRUE(race.refine_summary.method.empty());
  EXPECT_EQ(race.summary.parameter_names.size(), PendulumSwingUpPolicy::kBaseCount);
  EXPECT_EQ(race.theta, pendulum_full_theta(race.summary.best_theta));
  EXPECT_EQ(race.mean_return_100, race.race_mean_return_100);
  const auto both = train_pendulum(small_training());
  std::string difference;
  EXPECT_TRUE(SameOutcome(both.summary, race.summary, &difference)) << difference;
  EXPECT_EQ(both.race_mean_return_100, race.race_mean_return_100);
  EXPECT_EQ(both.refine_summary.parameter_names.size(),
            static_cast<std::size_t>(PendulumSwingUpPolicy::kCount));
  // The refinement's first U-hat is the race's policy on the refinement's starts; it only goes up.
  const PegasusEvaluator<Pendulum, PendulumSwingUpPolicy> refinement(
      Pendulum{}, PendulumSwingUpPolicy{},
      ScenarioSet({.seed = mix_seed(3, 0x52656669),
                   .count = 24,
                   .horizon = 200,
                   .noise_dim = 0,
                   .initial_noise_dim = 2,
                   .variant = ScenarioVariant::kStratified}),
      Discounting{.gamma = 1.0, .horizon = 200});
  EXPECT_EQ(both.refine_summary.initial_value, refinement.evaluate(race.theta));
  EXPECT_GE(both.refine_summary.best_value, both.refine_summary.initial_value);
  EXPECT_EQ(both.refine_summary.best_value, refinement.evaluate(both.theta));
}

TEST(PendulumTraining, TheRefinedPolicyBeatsTheRaceOnManyFreshStarts) {
  // A small refinement (64 starts, 30 iterations) after the small race; both policies on 1000 starts that
  // neither search saw (a sampling error of about 2 on such a mean, but the same starts for both).
  PendulumTrainingOptions o = small_training();
  o.refine_scenarios = 64;
  o.refine_optimizer.hill_climbing.max_iterations = 30;
  const auto r = train_pendulum(o);
  const double race =
      ordered_mean(pendulum_episode_returns(pendulum_full_theta(r.summary.best_theta), 1000, 99));
  const double refined = ordered_mean(pendulum_episode_returns(r.theta, 1000, 99));
  EXPECT_GT(refined, race + 1.0) << race << " -> " << refined;  // -145.49 -> -142.68 when written
  EXPECT_GT(refined, -145.0);
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
  o = PendulumTrainingOptions{};
  o.refine_scenarios = -1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("refine_scenarios"), std::string::npos);
  o = PendulumTrainingOptions{};
  o.refine_optimizer.hill_climbing.initial_step = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("refine_optimizer.hill_climbing"), std::string::npos) << error;
}

}  // namespace
}  // namespace pegasus
