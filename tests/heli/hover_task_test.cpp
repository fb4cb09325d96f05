// The hover task of §5.3: reward (Eqs 5.9-5.10, wrapped yaw), the task wrapper, the LQR start, and PEGASUS
// training on a small identified model (improves U-hat, same bits for any thread count, resumes exactly).
// The policy file and flights on the ground truth are in hover_flight_test.cpp.
#include "pegasus/heli/hover_task.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "heli/hover_fixtures.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::heli {
namespace {

using test_fixtures::identify_pilot_flight;
using test_fixtures::small_model;
using test_fixtures::xcell_hover_file;

bool sanitized() { return std::getenv("PEGASUS_SANITIZED") != nullptr; }

HoverTrainingOptions tiny_options() {
  HoverTrainingOptions o;
  o.scenarios = 3;
  o.seconds = sanitized() ? 2 : 4;
  o.optimizer.gradient.max_iterations = 2;
  o.optimizer.hill_climbing.max_iterations = 2;
  o.optimizer.hill_climbing.proposals_per_iteration = 4;
  return o;
}

TEST(HoverReward, IsZeroAtTheSetPointAndQuadraticAway) {
  const HoverReward r = HoverReward::from_typical(0.5, 0.5, 0.1, 0.1, {0, 0, 0.2, 0.1});
  const SetPoint sp{1, 2, -10, 0.5};
  LoggedState s{1, 2, -10, 0.3, -0.2, 0.5, 0, 0, 0, 0.4, 0.4, 0.4};  // attitude and rates are not priced
  EXPECT_EQ(r.state_cost(s, sp), 0.0);
  EXPECT_EQ(r.action_cost({0, 0, 0.2, 0.1}), 0.0);
  s[0] += 0.5;  // one typical position error: cost 1
  EXPECT_NEAR(r.state_cost(s, sp), 1.0, 1e-12);
  s[0] += 0.5;  // twice: 4
  EXPECT_NEAR(r.state_cost(s, sp), 4.0, 1e-12);
  s = {1, 2, -10, 0, 0, 0.5, 0, -0.5, 0, 0, 0, 0};
  EXPECT_NEAR(r.state_cost(s, sp), 1.0, 1e-12);
  EXPECT_NEAR(r.action_cost({0.1, 0, 0.2, 0.1}), 1.0, 1e-12);
  EXPECT_NEAR(r.action_cost({0, 0, 0.1, 0.1}), 1.0, 1e-12);  // about the centre, not about 0
}

TEST(HoverReward, AttitudeAndRateTermsPriceTheirTypicalSizeAtOneAndAZeroTypicalSizeLeavesATermOut) {
  HoverReward r = HoverReward::from_typical(0.5, 0.5, 0.1, 0.0, {0, 0, 0.2, 0.1});
  EXPECT_EQ(r.alpha_action, (std::array<double, 4>{0, 0, 0, 0}));  // no action cost
  EXPECT_EQ(r.action_cost({1, -1, 1, -1}), 0.0);
  const SetPoint sp{0, 0, -10, 0};
  const LoggedState s{0, 0, -10, 0.2, -0.1, 0, 0, 0, 0, 0.5, 0, -1.0};
  EXPECT_EQ(r.state_cost(s, sp), 0.0);
  r.alpha_attitude.fill(HoverReward::weight_of_typical(0.1));  // 0.1 rad typical
  EXPECT_NEAR(r.state_cost(s, sp), 4.0 + 1.0, 1e-12);          // roll 2 typical sizes, pitch 1
  r.alpha_rate.fill(HoverReward::weight_of_typical(0.5));      // 0.5 rad/s typical
  EXPECT_NEAR(r.state_cost(s, sp), 5.0 + 1.0 + 4.0, 1e-12);
  std::string error;
  r.alpha_rate[2] = -1;
  EXPECT_FALSE(r.IsValid(&error));
  EXPECT_EQ(error, "alpha_rate: expected numbers in [0, 1000000000000], got -1");
}

// What HoverReward::VisitFields lists: each member's bytes and address, each name and key once.
struct ListedMembers {
  HoverReward r;
  std::size_t bytes = 0;
  std::set<const void*> addresses;
  std::set<std::string> names, keys;
  template <class T>
  void field(const char* name, T HoverReward::*member, const char*) {
    bytes += sizeof(T);
    EXPECT_TRUE(addresses.insert(&(r.*member)).second) << name << " listed twice";
    EXPECT_TRUE(names.insert(name).second) << name;
  }
  template <class T>
  void weight(const char* name, T HoverReward::*member, const char* doc) {
    field(name, member, doc);
  }
  template <class T>
  void size(const HoverRewardSize& s, T HoverReward::*member, const char* doc) {
    field(s.field, member, doc);
    EXPECT_TRUE(keys.insert(s.key).second) << s.key;
    for (const double w : elements(r.*member))  // the default size is the default weight's
      EXPECT_EQ(w, HoverReward::weight_of_typical(s.typical)) << s.key;
  }
  static std::vector<double> elements(double x) { return {x}; }
  template <std::size_t N>
  static std::vector<double> elements(const std::array<double, N>& a) {
    return {a.begin(), a.end()};
  }
};

TEST(HoverReward, TheDescriptionListsEveryMemberOnce) {
  ListedMembers listed;
  HoverReward::VisitFields(listed);
  // Every member is a double or an array of doubles (no padding): a member VisitFields leaves out shows here.
  EXPECT_EQ(listed.bytes, sizeof(HoverReward));
  EXPECT_EQ(HoverReward::field_names().size(), listed.names.size());
  EXPECT_EQ(HoverReward::field_names().front(), "alpha_pos");
  EXPECT_EQ(listed.keys.size(), HoverReward::sizes().size());
  HoverReward r;
  r.set_typical(HoverReward::sizes()[1], 0.25);  // velocity_mps
  EXPECT_EQ(r.alpha_vel, (std::array<double, 3>{16, 16, 16}));
  EXPECT_EQ(r.alpha_pos, HoverReward{}.alpha_pos);
}

TEST(HoverReward, YawErrorWrapsAboutTwoPi) {
  const HoverReward r = HoverReward::from_typical(0.5, 0.5, 0.1, 0.1, {});
  const SetPoint sp{0, 0, -10, 0.01};
  LoggedState s{0, 0, -10, 0, 0, 2 * std::numbers::pi - 0.01, 0, 0, 0, 0, 0, 0};
  EXPECT_NEAR(r.state_cost(s, sp), 0.02 * 0.02 / 0.01, 1e-9);  // footnote 12: 0.02 rad, not 2 pi - 0.02
  s[5] = -std::numbers::pi + 0.01;
  const SetPoint back{0, 0, -10, std::numbers::pi - 0.01};
  EXPECT_NEAR(r.state_cost(s, back), 0.02 * 0.02 / 0.01, 1e-9);
}

TEST(HoverTask, RewardAddsTheLearnedModelsCrashPenalty) {
  const auto model = small_model();
  sysid::LearnedModelOptions lo;
  HoverTask<sysid::LearnedHeliModel> task(sysid::LearnedHeliModel(model, lo), SetPoint{0, 0, -10, 0},
                                          HoverReward::from_typical(0.5, 0.5, 0.1, 0.1, {}));
  auto s = task.initial_state(std::array<double, 6>{0.5, 0.5, 0.5, 0.5, 0.5, 0.5});
  auto crashed = s;
  crashed.model.crashed = true;
  const Controls a{0, 0, 0, 0};
  EXPECT_EQ(task.reward(s, a, s), 0.0);
  EXPECT_EQ(task.reward(s, a, crashed), lo.crash_reward);
  EXPECT_EQ(task.observe(s).target, (SetPoint{0, 0, -10, 0}));
}

TEST(HoverTask, TrimEstimateComesFromTheLogs) {
  const auto model = small_model();
  const HoverPolicyInit init = hover_init_from_model(*model);
  const Aircraft truth;
  // The pilot hovers about trim and sweeps symmetrically: the log means are near the true trim.
  for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(init.trim[c], truth.hover_trim().controls[c], 0.05) << c;
  EXPECT_NEAR(init.trim_roll, truth.hover_trim().roll, 0.03);
}

std::shared_ptr<const sysid::IdentifiedModel> flipped_model() {
  static const auto model = identify_pilot_flight(true);
  return model;
}

// LQR on the identified model at the hover gives starting gains with the signs a stabilising controller needs
// (the constants' on the X-Cell, the opposite ones for the channels whose sign an aircraft reverses), and the
// hover class's share of them holds both the linear model and the learned model, where the X-Cell's constants
// crash the reversed aircraft at once.
TEST(LqrStart, GainsFollowTheIdentifiedControlSignsAndHoldTheLearnedModel) {
  HoverTrainingOptions o = tiny_options();
  o.scenarios = 6;
  o.seconds = 10;
  const LqrStart x_cell = lqr_hover_init(*small_model(), o);
  ASSERT_TRUE(x_cell.used) << x_cell.reason;
  EXPECT_LT(x_cell.spectral_radius, 1.0);
  const HoverPolicyInit c;  // the constants
  const HoverPolicyInit& g = x_cell.init;
  const std::array<std::pair<double, double>, 10> pairs = {{{g.k_pos, c.k_pos},
                                                            {g.k_vel, c.k_vel},
                                                            {g.k_att, c.k_att},
                                                            {g.k_pos_lat, c.k_pos_lat},
                                                            {g.k_vel_lat, c.k_vel_lat},
                                                            {g.k_roll, c.k_roll},
                                                            {g.k_alt, c.k_alt},
                                                            {g.k_climb, c.k_climb},
                                                            {g.k_yaw, c.k_yaw},
                                                            {g.k_yaw_rate, c.k_yaw_rate}}};
  for (std::size_t i = 0; i < pairs.size(); ++i) EXPECT_GT(pairs[i].first * pairs[i].second, 0.0) << i;
  const LqrStart reversed = lqr_hover_init(*flipped_model(), o);
  ASSERT_TRUE(reversed.used) << reversed.reason;
  const HoverPolicyInit& r = reversed.init;
  EXPECT_LT(r.k_pos * g.k_pos, 0.0);  // a1 reversed: its gains flip
  EXPECT_LT(r.k_att * g.k_att, 0.0);
  EXPECT_LT(r.k_yaw * g.k_yaw, 0.0);    // a4 reversed
  EXPECT_GT(r.k_roll * g.k_roll, 0.0);  // a2 and a3 as they were
  EXPECT_GT(r.k_alt * g.k_alt, 0.0);
  ThreadPool pool(2);
  const StartingPolicyCheck constants = check_starting_policy(flipped_model(), o, pool);
  EXPECT_GT(constants.crashed, o.scenarios / 2);
  o.lqr_start = true;
  EXPECT_EQ(check_starting_policy(flipped_model(), o, pool).crashed, 0);
  EXPECT_EQ(check_starting_policy(small_model(), o, pool).crashed, 0);
}

// An LQR start with the reward's action weights can move the controls far from the pilot's for a large start
// error and leave the learned model's data: training then makes it gentler, tenfold at a time, and uses the
// first factor whose starting policy holds the model; the policy it returns starts from those gains.
TEST(LqrStart, TrainingMakesACrashingLqrStartGentlerUntilItHolds) {
  HoverTrainingOptions o = tiny_options();
  o.scenarios = 10;
  o.seconds = 5;
  o.start_pos_sigma = 4;
  o.start_vel_sigma = 1;
  o.lqr_start = true;
  o.optimizer.gradient.max_iterations = 1;
  o.then_hill_climb = false;
  ThreadPool pool(2);
  const auto crashes = [&](double factor) {
    HoverTrainingOptions f = o;
    f.lqr_action_factor = factor;
    return check_starting_policy(small_model(), f, pool).crashed;
  };
  const int allowed = static_cast<int>(o.max_start_crash_fraction * o.scenarios);
  ASSERT_GT(crashes(1), allowed);  // the reward's weights crash this setting
  const HoverTrainingResult r = train_hover(small_model(), o, {}, pool);
  EXPECT_GT(r.lqr_action_factor, 1.0);
  EXPECT_LE(crashes(r.lqr_action_factor), allowed);       // the factor chosen holds
  EXPECT_GT(crashes(r.lqr_action_factor / 10), allowed);  // and is the first that does
  EXPECT_EQ(r.start.crashed, crashes(r.lqr_action_factor));
  // Every try is recorded with its crash count, the last the one taken (a model with no other class: the
  // chosen model's gains at each factor).
  ASSERT_FALSE(r.start_tries.empty());
  for (std::size_t i = 0; i < r.start_tries.size(); ++i) {
    const StartTry& t = r.start_tries[i];
    EXPECT_EQ(t.gains, "chosen model");
    EXPECT_EQ(t.action_factor, std::pow(10.0, static_cast<double>(i)));
    EXPECT_EQ(t.check.crashed, crashes(t.action_factor)) << i;
    EXPECT_EQ(t.taken, i + 1 == r.start_tries.size()) << i;
  }
  // Not made gentler when the reward's weights already hold, or for the constants.
  o.start_pos_sigma = 0.5;
  o.start_vel_sigma = 0.1;
  EXPECT_EQ(train_hover(small_model(), o, {}, pool).lqr_action_factor, 1.0);
}

// A model that records the class identify did not choose (here the global linear fit on the same data): when
// the chosen model's LQR start crashes too often, the other class's gains are tried at the same action
// weights before any are raised, and flown on the chosen model (issue 48).
TEST(LqrStart, TheOtherModelClassIsTriedBeforeTheActionWeightsAreRaised) {
  const auto chosen = small_model();
  sysid::IdentifiedModel copy(chosen->structure(), chosen->data(), chosen->inv_bandwidth(), chosen->sigma2());
  copy.set_model_choice({{"chosen", "locally weighted"}}, std::array<double, sysid::kInputs>{});
  const auto model = std::make_shared<const sysid::IdentifiedModel>(std::move(copy));
  HoverTrainingOptions o = tiny_options();
  o.scenarios = 10;
  o.seconds = 5;
  o.start_pos_sigma = 4;
  o.start_vel_sigma = 1;
  o.lqr_start = true;
  o.optimizer.gradient.max_iterations = 1;
  o.then_hill_climb = false;
  ThreadPool pool(2);
  const HoverTrainingResult r = train_hover(model, o, {}, pool);
  ASSERT_GE(r.start_tries.size(), 2u);
  EXPECT_EQ(r.start_tries[0].gains, "chosen model");
  EXPECT_EQ(r.start_tries[1].gains, "global linear");
  EXPECT_EQ(r.start_tries[1].action_factor, 1.0);
  HoverTrainingOptions other = o;
  other.lqr_gains_from_alternative = true;
  // The other class's gains are the LQR on the global fit of the same data, flown on the chosen model.
  const auto alternative = model->alternative();
  ASSERT_TRUE(alternative.has_value());
  ASSERT_TRUE(alternative->is_global());
  EXPECT_EQ(lqr_hover_init(*model, other).init.k_pos, lqr_hover_init(*alternative, o).init.k_pos);
  if (r.start_tries[1].lqr_used) {
    EXPECT_EQ(r.start_tries[1].check.crashed, check_starting_policy(model, other, pool).crashed);
  }
  const auto taken =
      std::find_if(r.start_tries.begin(), r.start_tries.end(), [](const StartTry& t) { return t.taken; });
  ASSERT_NE(taken, r.start_tries.end());
  EXPECT_EQ(r.lqr_gains_from_alternative, taken->gains == "global linear");
  EXPECT_EQ(r.lqr_action_factor, taken->action_factor);
  EXPECT_EQ(r.start.crashed, taken->check.crashed);
}

// A global linear model's training limits the policy's commands to the logs' range of each control widened by
// command_margin of its width per side (within [-1, 1]); a locally weighted model's keeps [-1, 1] (issue 48).
TEST(CommandLimits, AGlobalModelsPolicyKeepsToTheLoggedControlsWidenedAndALocalModelsDoesNot) {
  const auto global = identify_pilot_flight(false, false);
  ASSERT_TRUE(global->is_global());
  const auto& x = global->data().x;
  HoverTrainingOptions o = tiny_options();
  o.lqr_start = true;
  o.command_margin = 0.5;
  const HoverPolicy policy = hover_policy_for(*global, o);
  ASSERT_TRUE(policy.has_command_limits());
  for (std::size_t c = 0; c < 4; ++c) {
    double lo = 1, hi = -1;
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      lo = std::min(lo, x(i, sysid::kA1 + static_cast<int>(c)));
      hi = std::max(hi, x(i, sysid::kA1 + static_cast<int>(c)));
    }
    ASSERT_LT(lo, hi) << c;
    EXPECT_DOUBLE_EQ(policy.command_lower()[c], std::max(-1.0, lo - 0.5 * (hi - lo))) << c;
    EXPECT_DOUBLE_EQ(policy.command_upper()[c], std::min(1.0, hi + 0.5 * (hi - lo))) << c;
  }
  // The start's weights do not depend on the limits.
  o.command_margin = 100;  // beyond [-1, 1] on every channel: no limits
  const HoverPolicy wide = hover_policy_for(*global, o);
  EXPECT_FALSE(wide.has_command_limits());
  EXPECT_EQ(wide.parameters().initial(), policy.parameters().initial());
  // A locally weighted model crashes off its data instead.
  o.command_margin = 0.5;
  EXPECT_FALSE(hover_policy_for(*small_model(), o).has_command_limits());
  // The limits are in the policy file training writes.
  const PolicyFile file = hover_policy_file(policy, policy.parameters().initial(), o.target, {});
  EXPECT_EQ(hover_file_command_limits(file, "p.json").command_upper, policy.command_upper());
}

// With no action cost (a judged cost may have none) the gains use the documented floor on the action weight,
// and the reward keeps its zero.
TEST(LqrStart, AZeroActionCostUsesTheFloorForTheGainsOnly) {
  HoverTrainingOptions zero = tiny_options(), floor = tiny_options();
  zero.reward.alpha_action.fill(0);
  floor.reward.alpha_action.fill(HoverTrainingOptions::kLqrMinActionWeight);
  const LqrStart a = lqr_hover_init(*small_model(), zero), b = lqr_hover_init(*small_model(), floor);
  ASSERT_TRUE(a.used) << a.reason;
  EXPECT_EQ(a.init.k_pos, b.init.k_pos);
  EXPECT_EQ(a.init.k_alt, b.init.k_alt);
  EXPECT_EQ(a.spectral_radius, b.spectral_radius);
  EXPECT_EQ(hover_reward_for(*small_model(), zero).alpha_action[0], 0.0);
}

TEST(HoverTraining, ImprovesUhatAndIsTheSameForAnyThreadCount) {
  const auto model = small_model();
  const HoverTrainingOptions o = tiny_options();
  ThreadPool one(1), two(2);
  const HoverTrainingResult a = train_hover(model, o, {}, one);
  const HoverTrainingResult b = train_hover(model, o, {}, two);
  EXPECT_GT(a.final_uhat, a.initial_uhat);
  EXPECT_EQ(a.final_uhat, b.final_uhat);
  EXPECT_EQ(a.theta, b.theta);
  ASSERT_EQ(a.progress.size(), b.progress.size());
  for (std::size_t k = 0; k < a.progress.size(); ++k) EXPECT_EQ(a.progress[k].value, b.progress[k].value);
  // Gradient ascent, then hill climbing from its best: the progress never goes down.
  for (std::size_t k = 1; k < a.progress.size(); ++k) EXPECT_GE(a.progress[k].value, a.progress[k - 1].value);
  EXPECT_EQ(a.gradient.method, "gradient");
  EXPECT_EQ(a.hill_climb.method, "hill-climb");
}

TEST(HoverTraining, ResumesFromEveryCheckpointToTheSameResult) {
  const auto model = small_model();
  const HoverTrainingOptions o = tiny_options();
  ThreadPool pool(2);
  std::vector<nlohmann::json> checkpoints;
  HoverTrainingHooks hooks;
  hooks.on_checkpoint = [&](const nlohmann::json& c) { checkpoints.push_back(c); };
  const HoverTrainingResult full = train_hover(model, o, hooks, pool);
  ASSERT_GE(checkpoints.size(), 3u);
  for (std::size_t k : {std::size_t{0}, checkpoints.size() / 2, checkpoints.size() - 1}) {
    HoverTrainingHooks resume;
    resume.resume_from = nlohmann::json::parse(checkpoints[k].dump());  // through text, as from the file
    const HoverTrainingResult r = train_hover(model, o, resume, pool);
    EXPECT_EQ(r.theta, full.theta) << "checkpoint " << k;
    EXPECT_EQ(r.final_uhat, full.final_uhat) << "checkpoint " << k;
    EXPECT_EQ(r.progress.size(), full.progress.size()) << "checkpoint " << k;
  }
}

// ---- The integral term (issue 15) ----------------------------------------------------------------------

// Training and flying must see the same controller: the task's state carries the integral exactly as a
// flight's memory does, so the actions of a rollout equal the flown controller's bit for bit.
TEST(HoverTask, CarriesTheErrorIntegralExactlyAsTheFlownControllerDoes) {
  AircraftParams p;
  p.conditions.start_pos_sigma = 1.0;
  p.conditions.start_vel_sigma = 0.3;
  p.conditions.gust_sigma = 0.5;
  const Aircraft aircraft(p);
  const PolicyFile file = xcell_hover_file(aircraft, 5);
  const auto controller = make_controller(file, "f.json");
  const HoverPolicy pi(HoverPolicyInit{.integral_seconds = 5});
  const HoverTask<Aircraft> task(aircraft, file.target, HoverReward{}, hover_file_integrator(file, "f.json"));
  UniformStream rng(7, 0);
  std::vector<double> p0(static_cast<std::size_t>(task.initial_noise_dim())),
      noise(static_cast<std::size_t>(task.noise_dim()));
  for (double& u : p0) u = rng.next();
  auto s = task.initial_state(p0);
  ControllerMemory memory;
  double largest = 0;
  for (int t = 0; t < 500; ++t) {
    const HeliObservation o = task.observe(s);
    const Controls a = pi.act(file.values, o);
    ASSERT_EQ(a, controller->act(o.state, t * 0.02, memory)) << "step " << t;
    ASSERT_EQ(o.integral, memory.integral) << "step " << t;
    largest = std::max(largest, std::abs(o.integral[0]));
    for (double& u : noise) u = rng.next();
    s = task.step(s, a, noise);
  }
  EXPECT_GT(largest, 0.05);  // the integral did move (a 1 m start error over 10 s)
}

TEST(HoverTraining, IntegralTermTrainsThirtyEightWeightsAndItsLqrStartHoldsTheLinearModel) {
  HoverTrainingOptions o = tiny_options();
  o.integral_seconds = 2;
  ThreadPool pool(2);
  const HoverTrainingResult r = train_hover(small_model(), o, {}, pool);
  EXPECT_EQ(r.theta.size(), 38u);
  EXPECT_EQ(r.start.crashed, 0);
  o.lqr_start = true;
  const LqrStart lqr = lqr_hover_init(*small_model(), o);
  ASSERT_TRUE(lqr.used) << lqr.reason;
  EXPECT_GE(lqr.integral_seconds, 2.0);
  EXPECT_LT(lqr.integral_radius, 1.0);
  EXPECT_EQ(hover_policy_for(*small_model(), o).parameters()[34].initial,
            lqr.init.k_pos / lqr.integral_seconds);
  std::string why;
  o.integral_seconds = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "integral_seconds: expected a number in [0, 3600] s, got -1");
  // Within the bounds but shorter than one control step: no integral term a controller can run.
  o.integral_seconds = 0.01;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why,
            "integral_seconds: expected 0 (no integral term) or a number in [0.02, 3600] (at least one "
            "control step, 1 / control_rate_hz), got 0.01");
  o.integral_seconds = 5;
  o.integral_limit_yaw = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "integral_limit_yaw: expected a number in (0, 1000000] rad s, got 0");
}

}  // namespace
}  // namespace pegasus::heli
