// The manoeuvre task (thesis §5.4): the reward pays distance to the path, not lag behind the set point; the
// shaping potential grows along the path, is 0 at the start and at absorbing (crash) states, and telescopes;
// the manoeuvre policy's couplings and delay; flights on the ground truth are deterministic.
#include "pegasus/heli/maneuver_task.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <span>

#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/maneuver_policy.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::heli;

// A point "helicopter" for checking the wrapper: the action a1..a3 is the velocity (m/s) in W, a4 the yaw
// rate; it crashes (absorbing) below the ground or when told to (a velocity above 5 m/s).
struct PointModel {
  struct State {
    LoggedState s{};
    bool crashed = false;
  };
  using Action = Controls;
  using Observation = LoggedState;
  int state_dim() const { return 12; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  ActionSpace action_space() const { return ActionSpace::box({-10, -10, -10, -10}, {10, 10, 10, 10}); }
  State initial_state(std::span<const double>) const {
    State s;
    s.s[2] = -10;
    return s;
  }
  State step(const State& s, const Action& a, std::span<const double>) const {
    State n = s;
    for (int k = 0; k < 3; ++k) {
      n.s[static_cast<std::size_t>(k)] += 0.02 * a[static_cast<std::size_t>(k)];
      n.s[static_cast<std::size_t>(6 + k)] = a[static_cast<std::size_t>(k)];
    }
    n.s[5] = wrap_angle(s.s[5] + 0.02 * a[3]);
    n.crashed = n.s[2] > 0 || std::abs(a[0]) > 5;
    return n;
  }
  bool terminal(const State& s) const { return s.crashed; }
  Observation observe(const State& s) const { return s.s; }
  double reward(const State& s, const Action&, const State& n) const {
    return !s.crashed && n.crashed ? -1000.0 : 0.0;
  }
};
static_assert(SimulativeModel<PointModel>);
static_assert(SimulativeModel<ManeuverTask<PointModel>>);

struct Fixture {
  std::shared_ptr<const Trajectory> trajectory =
      std::make_shared<const Trajectory>(maneuver_trajectory("III.1"));
  std::shared_ptr<const PathObserver> observer = std::make_shared<const PathObserver>(*trajectory);
  ManeuverReward reward{};
  ManeuverTask<PointModel> task{PointModel{}, observer, reward};
};

// Flies the point model along the ideal set point (action = the set point's velocity), optionally crashing at
// step crash_at; returns the discounted shaping collected, and the states.
double shaped_flight(const Fixture& f, double gamma, int steps, int crash_at, double per_metre,
                     std::vector<ManeuverTask<PointModel>::State>* states) {
  const auto shaped = shape(f.task, PathProgressPotential{per_metre}, gamma);
  auto s = shaped.initial_state({});
  double sum = 0, w = 1;
  double p = 0.5;
  states->push_back(s);
  for (int t = 0; t < steps && !shaped.terminal(s); ++t) {
    const TrajectoryPoint sp = f.trajectory->at(t * 0.02);
    Controls a{sp.v_W.x(), sp.v_W.y(), sp.v_W.z(), sp.yaw_rate};
    if (t == crash_at) a[0] = 9;
    const auto n = shaped.step(s, a, std::span<const double>(&p, 1));
    sum += w * shaped.shaping(s, a, n);
    w *= gamma;
    s = n;
    states->push_back(s);
  }
  return sum;
}

TEST(ManeuverTask, ShapingPotentialIsZeroAtTheStartAndAtTheAbsorbingCrash) {
  const Fixture f;
  constexpr double gamma = 0.9995, per_metre = 5;
  std::vector<ManeuverTask<PointModel>::State> states;
  const double sum = shaped_flight(f, gamma, 1500, 1000, per_metre, &states);
  ASSERT_TRUE(f.task.terminal(states.back()));
  EXPECT_EQ(states.size(), 1002u);
  EXPECT_EQ(states.front().path.progress, 0.0);  // Phi(s0) = 0: the flight starts at the path's start
  // The crash transition pays F = gamma * 0 - Phi(s): the potential of an absorbing state is 0 (Theorem 1's
  // condition for episodic tasks), so the shaping of a crashed flight telescopes to -Phi(s0) = 0.
  const auto shaped = shape(f.task, PathProgressPotential{per_metre}, gamma);
  const auto& before = states[states.size() - 2];
  EXPECT_GT(before.path.progress, 5.0);
  EXPECT_DOUBLE_EQ(shaped.shaping(before, Controls{9, 0, 0, 0}, states.back()),
                   -per_metre * before.path.progress);
  EXPECT_NEAR(sum, 0.0, 1e-9);
}

TEST(ManeuverTask, ShapingTelescopesToTheProgressAtTheHorizon) {
  const Fixture f;
  constexpr double gamma = 0.999, per_metre = 2;
  std::vector<ManeuverTask<PointModel>::State> states;
  const int steps = 1200;
  const double sum = shaped_flight(f, gamma, steps, -1, per_metre, &states);
  ASSERT_FALSE(f.task.terminal(states.back()));
  EXPECT_NEAR(sum, std::pow(gamma, steps) * per_metre * states.back().path.progress, 1e-9);
  // Progress grows along the flown path and the projection is the set point itself.
  for (std::size_t k = 1; k < states.size(); ++k)
    ASSERT_GE(states[k].path.progress, states[k - 1].path.progress);
  EXPECT_GT(states.back().path.progress, 15.0);
}

TEST(ManeuverTask, RewardPaysDistanceToThePathNotLagBehindTheSetPoint) {
  const Fixture f;
  const ManeuverReward r{.alpha_pos = 4, .alpha_yaw = 4, .alpha_vel = 0, .alpha_action = {0, 0, 0, 0}};
  // On the path, well behind the moving set point: no cost.
  PathProjection on = f.observer->start();
  const TrajectoryPoint behind = f.trajectory->at(3.0);
  on = f.observer->update(on, behind.p_W, 0.0);
  LoggedState s{};
  s[0] = behind.p_W.x(), s[1] = behind.p_W.y(), s[2] = behind.p_W.z();
  EXPECT_NEAR(r.state_cost(s, on), 0.0, 1e-12);
  // 1 m beside the path: alpha_pos * 1 m^2.
  s[1] += 1;
  const PathProjection off = f.observer->update(on, Vec3(s[0], s[1], s[2]), 0.0);
  EXPECT_NEAR(r.state_cost(s, off), 4.0, 1e-9);
}

TEST(ManeuverPolicy, FollowsTheSetPointAndAppliesTheCouplingsAboutTrim) {
  auto trajectory = std::make_shared<const Trajectory>(maneuver_trajectory("III.1"));
  HoverPolicyInit init;
  init.trim = {0.01, 0.03, 0.18, 0.19};
  const ManeuverPolicy policy(trajectory, init);
  const auto& spec = policy.parameters();
  ASSERT_EQ(spec.size(), 38u);
  EXPECT_EQ(spec[34].name, "couple.tail_to_lat");
  EXPECT_EQ(spec[35].name, "couple.coll_to_tail");
  EXPECT_EQ(spec[36].name, "z_delay");
  EXPECT_EQ(spec[37].name, "feedforward");
  Theta theta = spec.initial();
  // The set point at time t is the trajectory's; the delay moves only z on the angled legs.
  for (double t : {0.0, 5.0, 20.0, 30.0}) {
    const SetPoint sp = policy.target(theta, t);
    const TrajectoryPoint q = trajectory->at(t);
    EXPECT_DOUBLE_EQ(sp.x, q.p_W.x());
    EXPECT_DOUBLE_EQ(sp.z, q.p_W.z());
  }
  theta[36] = 1.0;
  for (double t = 0; t < trajectory->duration(); t += 0.5)
    EXPECT_DOUBLE_EQ(policy.target(theta, t).z, trajectory->delayed(t, 1.0).p_W.z());
  theta[36] = 0;
  // Couplings: a2 moves by c1 * (a4 - trim4), a4 by c2 * (a3 - trim3).
  ManeuverObservation o;
  o.state[2] = -10.5;  // below the set point: more collective
  o.state[5] = 0.2;    // yawed: tail answers
  o.time = 0.5;
  const Controls plain = policy.act(theta, o);
  theta[34] = 0.5;
  theta[35] = -0.3;
  const Controls coupled = policy.act(theta, o);
  EXPECT_NEAR(coupled[1] - plain[1], 0.5 * (plain[3] - init.trim[3]), 1e-12);
  // a4's own coupling also changes a4, and a2 follows the unclipped a4 before its coupling.
  EXPECT_NEAR(coupled[3] - plain[3], -0.3 * (plain[2] - init.trim[2]), 1e-12);
  EXPECT_NEAR(coupled[0], plain[0], 1e-15);
  EXPECT_NEAR(coupled[2], plain[2], 1e-15);
  // Without the delay and feed-forward the class has 36 parameters.
  EXPECT_EQ(
      ManeuverPolicy(trajectory, init, {.learn_delay = false, .feedforward = false}).parameters().size(),
      36u);
}

TEST(ManeuverFlights, OnTheGroundTruthAreDeterministicForAnyThreadCount) {
  ManeuverSize size;
  size.circle_radius = 3;
  size.hold_end_s = 0.5;
  auto trajectory = std::make_shared<const Trajectory>(maneuver_trajectory("III.2", size));
  Aircraft heli;
  HoverPolicyInit init;
  init.trim = heli.hover_trim().controls;
  init.trim_roll = heli.hover_trim().roll;
  init.trim_pitch = heli.hover_trim().pitch;
  const ManeuverPolicy policy(trajectory, init);
  const PathObserver observer(*trajectory);
  ManeuverFlightOptions o;
  o.flights = 3;
  ThreadPool two(2);
  const auto a = fly_maneuver(policy, policy.parameters().initial(), observer, o, nullptr);
  const auto b = fly_maneuver(policy, policy.parameters().initial(), observer, o, &two);
  ASSERT_EQ(a.size(), 3u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].truth.size(), b[i].truth.size());
    EXPECT_EQ(a[i].truth.back(), b[i].truth.back());
    EXPECT_EQ(a[i].deviation, b[i].deviation);
    EXPECT_EQ(a[i].truth.size(), a[i].controls.size());
  }
  const auto s = summarize_maneuver_flights(a, observer.length());
  EXPECT_EQ(s.flights, 3);
  EXPECT_GE(s.rms_path_deviation_m, 0.0);
  EXPECT_LE(s.rms_path_deviation_m, s.max_path_deviation_m);
}

}  // namespace

namespace {

using namespace pegasus;
using namespace pegasus::heli;

TEST(ManeuverPilot, LogCoversTheManoeuvresSpeedsAndPirouettes) {
  const Aircraft heli;
  std::vector<Trajectory> trajectories{maneuver_trajectory("III.1"), maneuver_trajectory("III.2")};
  const double total = 20 + trajectories[0].duration() + trajectories[1].duration();
  const PilotFlight f = fly_pilot_maneuvers(heli, PilotOptions{}, 20, trajectories, 5);
  ASSERT_EQ(f.crash, CrashReason::kNone);
  EXPECT_NEAR(static_cast<double>(f.log.rows()) * 0.02, total, 0.05);
  double speed = 0, yaw_rate = 0;
  for (const auto& s : f.truth) {
    speed = std::max(speed, std::hypot(s[6], s[7]));
    yaw_rate = std::max(yaw_rate, std::abs(s[11]));
  }
  // Hover and sweeps alone stay near 0.7 rad/s of yaw rate; the manoeuvres go beyond.
  EXPECT_GT(speed, 2.0);
  EXPECT_GT(yaw_rate, 0.8);
}

TEST(ManeuverPolicyFile, RoundTripsThroughTheRegistryAndFliesTheSame) {
  register_policy_class("maneuver", make_maneuver_controller, maneuver_c_text);
  ManeuverFileOptions o;
  o.name = "III.3";
  o.size.rectangle_height = 6;
  auto trajectory = std::make_shared<const Trajectory>(maneuver_trajectory(o.name, o.size, o.limits));
  HoverPolicyInit init;
  init.trim = {0.01, 0.03, 0.18, 0.19};
  const ManeuverPolicy policy(trajectory, init, o.policy);
  Theta theta = policy.parameters().initial();
  theta[ManeuverPolicy::kTailToLat] = 0.1;
  theta[36] = 0.4;
  const auto dir =
      std::filesystem::temp_directory_path() / ("pegasus-maneuver-file-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  write_policy_file(dir / "p.json", maneuver_policy_file(o, policy, theta, init.trim));
  const auto controller = load_controller(dir / "p.json");
  ManeuverObservation obs;
  obs.state[0] = 0.3, obs.state[2] = -10.2, obs.state[5] = 0.1, obs.state[6] = 0.5;
  for (double t : {0.0, 3.0, 17.5, 40.0}) {
    obs.time = t;
    EXPECT_EQ(controller->act(obs.state, t), policy.act(theta, obs)) << t;
    EXPECT_EQ(controller->target(t), policy.target(theta, t)) << t;
  }
  // A file whose options name no manoeuvre is refused, naming the field.
  PolicyFile bad = maneuver_policy_file(o, policy, theta, init.trim);
  bad.options["name"] = "IV.1";
  try {
    make_controller(bad, "bad.json");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("options.name"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
