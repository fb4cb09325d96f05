// The hover task of §5.3: reward (Eqs 5.9-5.10, wrapped yaw), the task wrapper, PEGASUS training on a small
// identified model (improves U-hat, same bits for any thread count, resumes exactly), the policy file and
// flights on the ground truth.
#include "pegasus/heli/hover_task.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
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
  EXPECT_EQ(error, "alpha_rate: expected finite numbers >= 0");
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
  crashed.crashed = true;
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
  // Not made gentler when the reward's weights already hold, or for the constants.
  o.start_pos_sigma = 0.5;
  o.start_vel_sigma = 0.1;
  EXPECT_EQ(train_hover(small_model(), o, {}, pool).lqr_action_factor, 1.0);
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
                            Controls act(const LoggedState&, double) const override { return a; }
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

}  // namespace
}  // namespace pegasus::heli
