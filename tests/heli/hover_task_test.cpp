// The hover task of §5.3: reward (Eqs 5.9-5.10, wrapped yaw), the task wrapper, PEGASUS training on a small
// identified model (improves U-hat, same bits for any thread count, resumes exactly), the policy file and
// flights on the ground truth.
#include "pegasus/heli/hover_task.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/sysid/identify.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using test_support::input_error_message;

bool sanitized() { return std::getenv("PEGASUS_SANITIZED") != nullptr; }

// A model identified from a short pilot flight (a few tenths of a second); `reversed` negates a1 and a4 in
// the logs first, as an aircraft whose longitudinal cyclic and tail act with the opposite signs.
std::shared_ptr<const sysid::IdentifiedModel> identify_pilot_flight(bool reversed) {
  const Aircraft heli;
  PilotOptions o;
  o.hover_seconds = 4;
  auto log = fly_pilot(heli, o, 60, 3).log;
  if (reversed)
    for (auto& a : log.controls) a[0] = -a[0], a[3] = -a[3];
  sysid::IdentifyOptions io;
  io.cv_points = 40;
  io.scale_grid = {2, 4};
  io.coordinate_passes = 0;
  ThreadPool pool(2);
  return std::make_shared<const sysid::IdentifiedModel>(sysid::identify(log, io, pool));
}

// Made once each.
std::shared_ptr<const sysid::IdentifiedModel> small_model() {
  static const auto model = identify_pilot_flight(false);
  return model;
}

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

TEST(PolicyFile, RoundTripsExactlyAndFliesTheSameControls) {
  const HoverPolicy pi;
  Theta theta = pi.parameters().initial();
  theta[1] = 0.1 + 1e-17 * 3;  // bits that only an exact round trip keeps
  theta[0] = 1.0 / 3.0;
  const PolicyFile f = hover_policy_file(pi, theta, {1, 2, -12, 0.3}, {0.01, 0.03, 0.18, 0.19});
  const PolicyFile back = parse_policy_file(nlohmann::json::parse(policy_file_json(f).dump()), "p.json");
  EXPECT_EQ(back.values, f.values);
  EXPECT_EQ(back.names, f.names);
  EXPECT_EQ(back.target, f.target);
  EXPECT_EQ(back.trim, f.trim);
  const auto c = make_controller(back, "p.json");
  HeliObservation o;
  o.state = {1.5, 2, -12, 0, 0, 0.3, 0.1, 0, 0, 0, 0, 0};
  o.target = f.target;
  EXPECT_EQ(c->act(o.state, 0.0), pi.act(theta, o));
  EXPECT_EQ(c->target(7.0), f.target);
}

TEST(PolicyFile, BadFilesNameTheFileAndTheField) {
  const HoverPolicy pi;
  const nlohmann::json good = policy_file_json(hover_policy_file(pi, pi.parameters().initial(), {}, {}));
  auto message = [](const nlohmann::json& j) {
    return input_error_message([&] { make_controller(parse_policy_file(j, "p.json"), "p.json"); });
  };
  EXPECT_EQ(message(good), "(no error)");
  nlohmann::json j = good;
  j["format"] = "other";
  EXPECT_EQ(message(j), "p.json: format: expected \"pegasus-heli-policy\", got \"other\"");
  j = good;
  j.erase("target");
  EXPECT_EQ(message(j), "p.json: target: missing");
  j = good;
  j["parameters"][3]["value"] = "x";
  EXPECT_EQ(message(j), "p.json: parameters[3].value (a1.err_tanh_in): expected a number, got \"x\"");
  j = good;
  j["parameters"][2]["name"] = "a1.typo";
  EXPECT_EQ(message(j),
            "p.json: parameters[2].name: expected \"a1.err_tanh_gain\" (class hover), got \"a1.typo\"");
  j = good;
  j["parameters"].erase(33);
  EXPECT_EQ(message(j), "p.json: parameters: expected 34 parameters for class hover, got 33");
  j = good;
  j["class"] = "loop";
  EXPECT_NE(message(j).find("p.json: class: expected one of "), std::string::npos) << message(j);
  j = good;
  j["trim"]["a3"] = 1.5;
  EXPECT_EQ(message(j), "p.json: trim.a3: expected a control in [-1, 1], got 1.5");
  j = good;
  j["version"] = 2;
  EXPECT_EQ(message(j), "p.json: version: expected 1, got 2");
}

TEST(PolicyFile, RegistryTakesNewClasses) {
  register_policy_class("test-constant",
                        [](const PolicyFile& p, const std::string&) -> std::unique_ptr<HeliController> {
                          struct Constant final : HeliController {
                            Controls a;
                            SetPoint sp;
                            Controls act(const LoggedState&, double, ControllerMemory&) const override {
                              return a;
                            }
                            SetPoint target(double) const override { return sp; }
                          };
                          auto c = std::make_unique<Constant>();
                          c->a = p.trim;
                          c->sp = p.target;
                          return c;
                        });
  PolicyFile f;
  f.class_name = "test-constant";
  f.names = {"w"};
  f.values = {0};
  f.trim = {0.1, 0.2, 0.3, 0.4};
  EXPECT_EQ(make_controller(f, "c.json")->act({}, 0), f.trim);
  const auto names = policy_class_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "hover"), names.end());
}

TEST(ControlLoop, ParsesTwelveThirteenAndSeventeenFields) {
  LoggedState s{};
  bool has_time = false;
  double t = 0;
  std::string why;
  EXPECT_TRUE(parse_state_line("1,2,-10,0,0,0.5,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(has_time);
  EXPECT_EQ(s[5], 0.5);
  EXPECT_TRUE(parse_state_line(" 0.5, 1,2,-10,0,0,0.25,0,0,0,0,0,0\r", &s, &has_time, &t, &why));
  EXPECT_TRUE(has_time);
  EXPECT_EQ(t, 0.5);
  EXPECT_EQ(s[5], 0.25);
  EXPECT_TRUE(parse_state_line("0.5,1,2,-10,0,0,0.25,0,0,0,0,0,0,0.1,0.2,0.3,0.4", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("1,2,3", &s, &has_time, &t, &why));
  EXPECT_EQ(why, "expected 12, 13 or 17 fields, got 3");
  EXPECT_FALSE(parse_state_line("1,2,-10,0,0,nan,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_EQ(why, "field 6: expected a finite number, got 'nan'");
  EXPECT_FALSE(parse_state_line("1,2,,0,0,0,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("1,2,3x,0,0,0,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("", &s, &has_time, &t, &why));
}

TEST(Flights, PolicyAndPilotMeetTheSameStartsAndScoresAreConsistent) {
  AircraftParams p;
  p.start_pos_sigma = 1.0;
  p.start_vel_sigma = 0.3;
  const Aircraft aircraft(p);
  const auto model = small_model();
  const HoverPolicy pi = hover_policy_for(*model);
  const PolicyFile f = hover_policy_file(pi, pi.parameters().initial(), {0, 0, -10, 0}, {});
  const auto controller = make_controller(f, "f.json");
  FlightOptions fo;
  fo.flights = 3;
  fo.seconds = 4;
  fo.trace_flights = 2;
  ThreadPool pool(2);
  const auto flown = fly_controller(aircraft, *controller, fo, &pool);
  const auto again = fly_controller(aircraft, *controller, fo, nullptr);
  const auto pilot = fly_pilot_hover(aircraft, PilotOptions{}, {0, 0, -10, 0}, fo, &pool);
  ASSERT_EQ(flown.size(), 3u);
  EXPECT_EQ(flown[0].trace.size(), 200u);
  EXPECT_TRUE(flown[2].trace.empty());
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(flown[i].trace[0].truth, pilot[i].trace[0].truth) << i;  // same perturbed start
    EXPECT_EQ(flown[i].sum_sq_position, again[i].sum_sq_position);     // threads change nothing
  }
  EXPECT_NE(flown[0].trace[0].truth, flown[1].trace[0].truth);
  const FlightSummary s = summarize_flights(flown);
  EXPECT_EQ(s.flights, 3);
  double pos = 0;
  int steps = 0;
  for (const auto& r : flown) {
    pos += r.sum_sq_position;
    steps += r.steps;
  }
  EXPECT_NEAR(s.rms_position_m, std::sqrt(pos / steps), 1e-12);
  EXPECT_GT(s.rms_position_m, 0.0);
}

// ---- The integral term (issue 15) ----------------------------------------------------------------------

// The X-Cell's hover policy at its calm-air trim, with or without the integral term.
PolicyFile xcell_hover_file(const Aircraft& aircraft, double integral_seconds) {
  const HoverPoint trim = aircraft.hover_point();
  const HoverPolicy pi(HoverPolicyInit{.trim = trim.controls,
                                       .trim_roll = trim.roll,
                                       .trim_pitch = trim.pitch,
                                       .integral_seconds = integral_seconds});
  const ErrorIntegrator integrator{.dt = integral_seconds > 0 ? 0.02 : 0.0};
  return hover_policy_file(pi, pi.parameters().initial(), {0, 0, -10, 0}, trim.controls, integrator);
}

// Training and flying must see the same controller: the task's state carries the integral exactly as a
// flight's memory does, so the actions of a rollout equal the flown controller's bit for bit.
TEST(HoverTask, CarriesTheErrorIntegralExactlyAsTheFlownControllerDoes) {
  AircraftParams p;
  p.start_pos_sigma = 1.0;
  p.start_vel_sigma = 0.3;
  p.gust_sigma = 0.5;
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

// The point of the term: in a steady wind the thesis's class holds a steady offset, the integral removes it.
TEST(Flights, IntegralTermRemovesTheSteadyOffsetOfASteadyWind) {
  AircraftParams p;
  p.mean_wind_W = Vec3(4, 2, 0);  // m/s from the south-west, no gusts, exact estimates
  p.gust_sigma = 0;
  p.est_sigma_pos = p.est_sigma_vel = p.est_sigma_angle = p.est_sigma_rate = 0;
  const Aircraft aircraft(p);
  FlightOptions fo;
  fo.flights = 1;
  fo.seconds = 60;
  fo.trace_flights = 1;
  // Mean distance to the set point over the last 10 s.
  const auto offset = [&](double integral_seconds) {
    const auto controller = make_controller(xcell_hover_file(aircraft, integral_seconds), "f.json");
    const auto flights = fly_controller(aircraft, *controller, fo, nullptr);
    EXPECT_FALSE(flights[0].crashed);
    double sum = 0;
    int n = 0;
    for (const FlightRow& row : flights[0].trace) {
      if (row.time < 50) continue;
      sum += std::hypot(row.truth[logged::x], row.truth[logged::y], row.truth[logged::z] + 10);
      ++n;
    }
    return sum / n;
  };
  const double without = offset(0), with = offset(5);
  std::printf("steady offset in a 4.5 m/s wind: %.4f m without the integral term, %.4f m with it\n", without,
              with);
  EXPECT_GT(without, 1.0);
  EXPECT_LT(with, 0.05);
}

TEST(PolicyFile, IntegralTermRoundTripsAndBadIntegratorsNameTheField) {
  const Aircraft aircraft;
  const PolicyFile f = xcell_hover_file(aircraft, 5);
  EXPECT_EQ(f.values.size(), 38u);
  const PolicyFile back = parse_policy_file(nlohmann::json::parse(policy_file_json(f).dump()), "p.json");
  EXPECT_EQ(hover_file_integrator(back, "p.json"), (ErrorIntegrator{.dt = 0.02}));
  EXPECT_EQ(back.values, f.values);
  auto message = [](const nlohmann::json& j) {
    return input_error_message([&] { make_controller(parse_policy_file(j, "p.json"), "p.json"); });
  };
  const nlohmann::json good = policy_file_json(f);
  EXPECT_EQ(message(good), "(no error)");
  nlohmann::json j = good;
  j["options"]["integral"].erase("dt");
  EXPECT_EQ(message(j), "p.json: options.integral.dt: missing");
  j = good;
  j["options"]["integral"]["limit_yaw"] = 0;
  EXPECT_EQ(message(j), "p.json: options.integral.limit_yaw: expected a number > 0, rad s, got 0");
  j = good;
  j["options"]["integral"] = 5;
  EXPECT_EQ(message(j),
            "p.json: options.integral: expected {\"dt\", \"limit_position\", \"limit_yaw\"}, got 5");
  j = good;
  j["options"].erase("integral");  // 38 weights without the integrator
  EXPECT_EQ(message(j), "p.json: parameters: expected 34 parameters for class hover, got 38");
  j = policy_file_json(xcell_hover_file(aircraft, 0));
  j["options"]["integral"] = good["options"]["integral"];  // an integrator without the weights
  EXPECT_EQ(message(j), "p.json: parameters: expected 38 parameters for class hover, got 34");
}

// `heli control` serves one flight: the memory runs over its lines, and a malformed line leaves it alone.
TEST(ControlLoop, ControllerMemoryRunsOverTheLinesAndSkipsMalformedOnes) {
  const Aircraft aircraft;
  const auto controller = make_controller(xcell_hover_file(aircraft, 5), "f.json");
  const std::vector<LoggedState> states = {{1, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0},
                                           {1.5, -0.5, -9, 0, 0, 0.1, 0, 0, 0, 0, 0, 0},
                                           {2, -1, -9.5, 0.05, 0, 0.2, 0, 0, 0, 0, 0, 0}};
  std::string input;
  for (std::size_t i = 0; i < states.size(); ++i) {
    for (std::size_t k = 0; k < 12; ++k) input += fmt::format("{}{}", k ? "," : "", states[i][k]);
    input += "\n";
    if (i == 0) input += "1,2,x\n";
  }
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char* out_text = nullptr;
  std::size_t out_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = std::tmpfile();
  run_control_loop(*controller, {0, 0, 0, 0}, in, out, err);
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size);
  std::free(out_text);
  ControllerMemory memory;
  std::string expected;
  for (std::size_t i = 0; i < states.size(); ++i) {
    const Controls a = controller->act(states[i], 0.02 * static_cast<double>(i), memory);
    expected += fmt::format("{},{},{},{}\n", a[0], a[1], a[2], a[3]);
    if (i == 0) expected += "0,0,0,0\n";
  }
  EXPECT_EQ(answers, expected);
  EXPECT_NE(memory.integral[0], 0.0);
  EXPECT_NE(controller->act(states[2], 0.04), controller->act(states[2], 0.04, memory));
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
  EXPECT_EQ(why,
            "integral_seconds: expected 0 (no integral term) or a number in [0.02, 3600] (at least one "
            "control step, 1 / control_rate_hz), got -1");
  o.integral_seconds = 5;
  o.integral_limit_yaw = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "integral_limit_yaw: expected a finite number > 0 (rad s)");
}

}  // namespace
}  // namespace pegasus::heli
