// Controllers out (codegen/c_policy.hpp): the generated C compiles with gcc -std=c99 -Wall -Wextra -Werror
// -pedantic, and its outputs equal the C++ policy's bit for bit on 100,000 inputs per class and inside the
// ground-truth flight loop.
#include "pegasus/codegen/c_policy.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <new>
#include <numbers>
#include <random>

#include "c_policy_fixture.hpp"
#include "logs/outside_aircraft.hpp"
#include "pegasus/codegen/c_loader.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/policies/policy_json.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus::codegen {
namespace {

using heli::Controls;
using heli::LoggedState;
using namespace c_policy_test;

constexpr int kInputs = 100000;

// Counts the inputs where the C action differs in any bit from the C++ one; `report` describes the first.
struct Mismatches {
  int count = 0;
  std::string first;
  template <std::size_t N>
  void check(const std::array<double, N>& cpp, const double* c, const std::string& where) {
    for (std::size_t k = 0; k < N; ++k)
      if (!same_bits(cpp[k], c[k])) {
        if (count++ == 0) first = fmt::format("{}: output {}: C++ {:a}, C {:a}", where, k, cpp[k], c[k]);
        return;
      }
  }
};

// A manoeuvre file; `ablated` drops the learned delay and the feed-forward, as the ablations of heli
// maneuver; `limited` gives it the command limits kCommandLower/Upper (a hover policy's on a global model).
heli::PolicyFile maneuver_file(const std::string& name, std::uint64_t seed, double spread = 0.5,
                               bool ablated = false, bool limited = false) {
  heli::ManeuverFileOptions options;
  options.name = name;
  options.policy.learn_delay = options.policy.feedforward = !ablated;
  auto trajectory = std::make_shared<const heli::Trajectory>(heli::maneuver_trajectory(name));
  heli::HoverPolicyInit init = kTrimmedInit;
  if (limited) {
    init.command_lower = kCommandLower;
    init.command_upper = kCommandUpper;
  }
  const heli::ManeuverPolicy policy(trajectory, init, options.policy);
  std::mt19937_64 rng(seed);
  Theta theta = policy.from_hover(perturbed_hover_theta(heli::HoverPolicy(kTrimmedInit), rng, spread));
  theta[heli::ManeuverPolicy::kTailToLat] = 0.2;
  theta[heli::ManeuverPolicy::kCollToTail] = -0.3;
  if (!ablated) {
    theta[heli::ManeuverPolicy::kHover + 2] = 0.7;  // z_delay, s
    theta[heli::ManeuverPolicy::kHover + 3] = 0.9;  // feedforward
  }
  return heli::maneuver_policy_file(options, policy, theta, kTrimmedInit.trim);
}

// C and C++ helicopter controllers on kInputs (time, state) pairs; returns how many actions were clipped.
int expect_heli_bit_identical(const heli::PolicyFile& file, const LoadedCPolicy& c, double max_time,
                              std::uint64_t seed) {
  const auto cpp = heli::make_controller(file, "policy.json");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> time(-1.0, max_time);
  Mismatches actions, targets;
  int clipped = 0;
  for (int i = 0; i < kInputs; ++i) {
    const double t = time(rng);
    const heli::SetPoint sp = cpp->target(t);
    const LoggedState s = random_state(rng, sp);
    std::array<double, 13> observation;
    observation[0] = t;
    std::copy(s.begin(), s.end(), observation.begin() + 1);
    double action[4], target[4];
    EXPECT_EQ(c.act()(observation.data(), action), 0);
    const Controls a = cpp->act(s, t);
    actions.check(a, action, fmt::format("input {} (t = {})", i, t));
    c.target()(t, target);
    targets.check(std::array<double, 4>{sp.x, sp.y, sp.z, sp.yaw}, target,
                  fmt::format("target at t = {}", t));
    clipped += std::abs(a[0]) == 1 || std::abs(a[1]) == 1 || std::abs(a[2]) == 1 || std::abs(a[3]) == 1;
  }
  EXPECT_EQ(actions.count, 0) << actions.first;
  EXPECT_EQ(targets.count, 0) << targets.first;
  return clipped;
}

TEST_F(CPolicyExport, HoverIsBitIdenticalToTheCppPolicyOn100000States) {
  const heli::PolicyFile file = hover_file(1, 1.0, {3.0, -2.0, -12.0, 0.7});
  const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "hover.json");
  EXPECT_EQ(code.class_name, "hover");
  const LoadedCPolicy c(code, dir_);
  const int clipped = expect_heli_bit_identical(file, c, 60.0, 2);
  // Both sides of the clip are exercised.
  EXPECT_GT(clipped, kInputs / 20);
  EXPECT_LT(clipped, kInputs);
}

// With command limits, every output stays within its channel's limits, and the C clips exactly as the C++:
// at the limits, at [-1, 1] where a channel has none, and not at all.
TEST_F(CPolicyExport, HoverWithCommandLimitsIsBitIdenticalAndStaysWithinThem) {
  const heli::PolicyFile file = hover_file(5, 1.0, {3.0, -2.0, -12.0, 0.7}, {}, true);
  ASSERT_TRUE(file.options.contains("command_limits"));
  const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "hover.json");
  EXPECT_NE(code.source.find("kCommandLower"), std::string::npos);
  const LoadedCPolicy c(code, dir_);
  expect_heli_bit_identical(file, c, 60.0, 6);
  const auto cpp = heli::make_controller(file, "hover.json");
  std::mt19937_64 rng(7);
  std::array<int, 4> at_lower{}, at_upper{}, inside{};
  for (int i = 0; i < kInputs / 10; ++i) {
    const Controls a = cpp->act(random_state(rng, file.target), 0.0);
    for (std::size_t k = 0; k < 4; ++k) {
      ASSERT_GE(a[k], kCommandLower[k]);
      ASSERT_LE(a[k], kCommandUpper[k]);
      at_lower[k] += a[k] == kCommandLower[k];
      at_upper[k] += a[k] == kCommandUpper[k];
      inside[k] += a[k] > kCommandLower[k] && a[k] < kCommandUpper[k];
    }
  }
  for (std::size_t k = 0; k < 4; ++k) {
    SCOPED_TRACE(fmt::format("a{}", k + 1));
    EXPECT_GT(at_lower[k], kInputs / 1000);
    EXPECT_GT(at_upper[k], kInputs / 1000);
    EXPECT_GT(inside[k], kInputs / 1000);
  }
  // Without limits the file and the C are as they were: no table, no second clip.
  const heli::PolicyFile plain = hover_file(5, 1.0, {3.0, -2.0, -12.0, 0.7});
  EXPECT_FALSE(plain.options.contains("command_limits"));
  EXPECT_EQ(export_c_policy(heli::policy_file_json(plain), "hover.json").source.find("kCommandLower"),
            std::string::npos);
}

TEST_F(CPolicyExport, TheComparisonSeesOneReorderedSum) {
  // The same code with row 2 of the body-frame rotation summed left to right, as a careless transcription
  // would: the comparison must tell (Eigen sums that row as a0 + (a1 + a2)).
  const heli::PolicyFile file = hover_file(1, 1.0, {3.0, -2.0, -12.0, 0.7});
  CPolicyCode code = export_c_policy(heli::policy_file_json(file), "hover.json");
  const std::string exact = "r02 * dx + (r12 * dy + r22 * dz)";
  ASSERT_NE(code.source.find(exact), std::string::npos);
  code.source.replace(code.source.find(exact), exact.size(), "r02 * dx + r12 * dy + r22 * dz");
  const LoadedCPolicy c(code, dir_);
  const auto cpp = heli::make_controller(file, "hover.json");
  std::mt19937_64 rng(2);
  int differ = 0;
  for (int i = 0; i < 10000; ++i) {
    const LoggedState s = random_state(rng, file.target);
    std::array<double, 13> observation{};
    std::copy(s.begin(), s.end(), observation.begin() + 1);
    double action[4];
    c.act()(observation.data(), action);
    const Controls a = cpp->act(s, 0.0);
    differ += !std::equal(a.begin(), a.end(), action, same_bits);
  }
  EXPECT_GT(differ, 100);
}

TEST_F(CPolicyExport, ManeuversAreBitIdenticalToTheCppPolicyOn100000StatesAndTimes) {
  for (const auto name : heli::kManeuverNames) {
    SCOPED_TRACE(std::string(name));
    const heli::PolicyFile file = maneuver_file(std::string(name), 3);
    const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "maneuver.json");
    EXPECT_EQ(code.class_name, "maneuver");
    const LoadedCPolicy c(code, dir_ / std::string(name));
    const double duration = heli::maneuver_trajectory(name).duration();
    expect_heli_bit_identical(file, c, duration + 2.0, 4);
  }
  // Without the learned delay and the feed-forward (the other branches of the set point).
  const heli::PolicyFile ablated = maneuver_file("III.1", 3, 0.5, true);
  EXPECT_EQ(ablated.names.size(), 36u);
  const LoadedCPolicy c(export_c_policy(heli::policy_file_json(ablated), "ablated.json"), dir_ / "ablated");
  expect_heli_bit_identical(ablated, c, heli::maneuver_trajectory("III.1").duration() + 2.0, 5);
}

// A manoeuvre with command limits (started from a hover policy that has them, issue 48): the file keeps
// them, and the C clips as the C++ does, every output within its channel's limits.
TEST_F(CPolicyExport, AManeuverWithCommandLimitsIsBitIdenticalAndStaysWithinThem) {
  const heli::PolicyFile file = maneuver_file("III.1", 6, 1.0, false, true);
  ASSERT_TRUE(file.options.contains("command_limits"));
  const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "maneuver.json");
  EXPECT_NE(code.source.find("kCommandLower"), std::string::npos);
  const LoadedCPolicy c(code, dir_);
  const double duration = heli::maneuver_trajectory("III.1").duration();
  expect_heli_bit_identical(file, c, duration + 2.0, 7);
  const auto cpp = heli::make_controller(file, "maneuver.json");
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> time(0.0, duration);
  std::array<int, 4> at_limit{};
  for (int i = 0; i < kInputs / 10; ++i) {
    const Controls a = cpp->act(random_state(rng, file.target), time(rng));
    for (std::size_t k = 0; k < 4; ++k) {
      ASSERT_GE(a[k], kCommandLower[k]);
      ASSERT_LE(a[k], kCommandUpper[k]);
      at_limit[k] += a[k] == kCommandLower[k] || a[k] == kCommandUpper[k];
    }
  }
  for (std::size_t k = 0; k < 4; ++k) EXPECT_GT(at_limit[k], kInputs / 1000) << "a" << k + 1;
  // The file read back keeps them; without limits a manoeuvre file has none, and its C no table.
  EXPECT_EQ(heli::checked_maneuver_policy(file, "maneuver.json").policy.init().command_upper, kCommandUpper);
  const heli::PolicyFile plain = maneuver_file("III.1", 6);
  EXPECT_FALSE(plain.options.contains("command_limits"));
  EXPECT_EQ(export_c_policy(heli::policy_file_json(plain), "maneuver.json").source.find("kCommandLower"),
            std::string::npos);
}

TEST_F(CPolicyExport, HeliNonFiniteObservationGetsTheTrimAsHeliControlAnswers) {
  const heli::PolicyFile file = hover_file(1, 1.0, {0, 0, -10, 0});
  const LoadedCPolicy c(export_c_policy(heli::policy_file_json(file), "hover.json"), dir_);
  std::array<double, 13> observation{};
  observation[3] = -10;
  observation[6] = std::numeric_limits<double>::quiet_NaN();
  double action[4];
  EXPECT_EQ(c.act()(observation.data(), action), 1);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(action[k], file.trim[k]);
}

// In an aircraft's own terms (a vehicle file: quaternion, body velocity and rates in; its channels out in its
// order, ranges and signs), the exported controller answers what `pegasus control --vehicle` computes: the
// vehicle's conversion, the policy, the channels' mapping, bit for bit, for the hover and a manoeuvre.
TEST_F(CPolicyExport, InAVehiclesOwnTermsItIsBitIdenticalToTheCppConversionAndPolicy) {
  const logs::Vehicle vehicle = logs::parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  for (const heli::PolicyFile& file :
       {hover_file(3, 1.0, {1.0, 2.0, -8.0, 0.3}), maneuver_file("III.2", 4)}) {
    const CPolicyCode code =
        export_c_policy(heli::policy_file_json(file), "p.json", {.prefix = "outside", .vehicle = &vehicle});
    EXPECT_EQ(code.vehicle_action_names, (std::vector<std::string>{"thr", "ail", "ele", "rudder_us"}));
    ASSERT_EQ(code.vehicle_observation_names.size(), 14u);
    EXPECT_EQ(code.vehicle_observation_names[7], "qw");
    const LoadedCPolicy c(code, dir_ / file.class_name);
    ASSERT_NE(c.act_vehicle(), nullptr);
    const auto cpp = heli::make_controller(file, "p.json");
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> time(0.0, 10.0);
    Mismatches actions;
    for (int i = 0; i < kInputs / 4; ++i) {
      const double t = time(rng);
      const auto native_state = test_support::outside_state(random_state(rng, cpp->target(t)));
      std::array<double, 14> observation;
      observation[0] = t;
      std::copy(native_state.begin(), native_state.end(), observation.begin() + 1);
      double action[4];
      EXPECT_EQ(c.act_vehicle()(observation.data(), action), 0);
      actions.check(vehicle.native_of(cpp->act(vehicle.state_of(native_state), t)), action,
                    fmt::format("{} input {}", file.class_name, i));
    }
    EXPECT_EQ(actions.count, 0) << actions.first;
    // A non-finite field, or a quaternion of length 0: the trim, in the channels' terms.
    std::array<double, 14> zero{};
    double action[4];
    EXPECT_EQ(c.act_vehicle()(zero.data(), action), 1);
    const auto trim = vehicle.native_of(file.trim);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(action[k], trim[k]) << k;
  }
  // Only the helicopter classes speak a vehicle's terms.
  const std::string message = test_support::input_error_message([&] {
    (void)export_c_policy(pendulum_policy_json({1, 2, 3, 4, 5}), "p.json", {.vehicle = &vehicle});
  });
  EXPECT_NE(message.find("p.json: --vehicle: only the helicopter classes"), std::string::npos) << message;
}

// In other conventions too (issue 53): a ROS aircraft (ENU, FLU, quaternion x, y, z, w, body velocity, body
// rates in deg/s), Euler angles in degrees in an ENU world with an FRD body and Euler rates in deg/s, and a
// world-to-body quaternion in NED with an FLU body: the exported controller reads each as `pegasus control
// --vehicle` does, bit for bit, including the quaternion's and the frames' edge cases.
TEST_F(CPolicyExport, InEveryConventionItIsBitIdenticalToTheCppConversion) {
  using test_support::replaced;
  const std::string outside = test_support::kOutsideVehicle;
  const auto with = [&](const std::string& log_keys, const std::string& attitude_keys,
                        const std::string& rates_keys) {
    return replaced(replaced(replaced(outside, "time = \"t\"", "time = \"t\"\n" + log_keys),
                             "form = \"quaternion\"", attitude_keys),
                    "form = \"body\"", rates_keys);
  };
  const std::vector<std::string> texts = {
      with("world_frame = \"ENU\"\nbody_frame = \"FLU\"",
           "form = \"quaternion\"\norder = \"xyzw\"\nunit = \"deg\"", "form = \"body\"\nunit = \"deg/s\""),
      replaced(
          replaced(with("world_frame = \"ENU\"", "form = \"euler\"\nunit = \"deg\"",
                        "form = \"euler\"\nunit = \"deg/s\""),
                   "fields = [\"qw\", \"qx\", \"qy\", \"qz\"]", "fields = [\"roll\", \"pitch\", \"yaw\"]"),
          "frame = \"body\"", "frame = \"world\""),
      replaced(with("body_frame = \"FLU\"", "form = \"quaternion\"\ndirection = \"world_to_body\"",
                    "form = \"euler\""),
               "frame = \"body\"", "frame = \"world\""),
  };
  const heli::PolicyFile file = hover_file(3, 1.0, {1.0, 2.0, -8.0, 0.3});
  const auto cpp = heli::make_controller(file, "p.json");
  for (std::size_t v = 0; v < texts.size(); ++v) {
    const logs::Vehicle vehicle = logs::parse_vehicle(texts[v], "conventions.toml");
    ASSERT_FALSE(vehicle.log.pipeline_conventions()) << v;
    const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "p.json",
                                             {.prefix = fmt::format("conv{}", v), .vehicle = &vehicle});
    const LoadedCPolicy c(code, dir_ / fmt::format("conv{}", v));
    ASSERT_NE(c.act_vehicle(), nullptr);
    const std::size_t size = code.vehicle_observation_names.size();
    std::mt19937_64 rng(11 + v);
    std::uniform_real_distribution<double> time(0.0, 10.0);
    Mismatches actions;
    for (int i = 0; i < kInputs / 10; ++i) {
      const double t = time(rng);
      const std::vector<double> native_state = vehicle.native_state(random_state(rng, cpp->target(t)));
      ASSERT_EQ(native_state.size() + 1, size);
      std::vector<double> observation{t};
      observation.insert(observation.end(), native_state.begin(), native_state.end());
      double action[4];
      EXPECT_EQ(c.act_vehicle()(observation.data(), action), 0);
      actions.check(vehicle.native_of(cpp->act(vehicle.state_of(native_state), t)), action,
                    fmt::format("vehicle {} input {}", v, i));
    }
    EXPECT_EQ(actions.count, 0) << actions.first;
    std::vector<double> zero(size, 0.0);
    double action[4];
    EXPECT_EQ(c.act_vehicle()(zero.data(), action), v == 1 ? 0 : 1)
        << v;  // all-zero Euler angles are an attitude
  }
}

// Names from the user's files stand in the generated comments: none may end a comment or open one.
TEST_F(CPolicyExport, NamesThatLookLikeCommentMarkersStayInsideTheComments) {
  using test_support::replaced;
  const std::string text = replaced(replaced(test_support::kOutsideVehicle, "name = \"outside-heli\"",
                                             "name = \"heli */ #error injected /*\""),
                                    "name = \"rudder_us\"", "name = \"rudder*/us/*\\u00e9\"");
  const logs::Vehicle vehicle = logs::parse_vehicle(text, "evil*/.toml");
  const CPolicyCode code = export_c_policy(heli::policy_file_json(hover_file(3, 1.0, {1.0, 2.0, -8.0, 0.3})),
                                           "run*/policy.json", {.prefix = "evil", .vehicle = &vehicle});
  for (const std::string* file : {&code.header, &code.source}) {
    EXPECT_EQ(file->find("*/ #error"), std::string::npos);
    EXPECT_NE(file->find("heli * / #error injected / *"), std::string::npos);
  }
  EXPECT_NE(code.source.find("run* /policy.json"), std::string::npos);
  EXPECT_NE(code.source.find("rudder* /us/ *__"), std::string::npos);  // and no byte beyond ASCII
  // It compiles with -Werror (a nested "/*" would be refused), and the vehicle's channels act as before.
  const LoadedCPolicy c(code, dir_ / "evil");
  ASSERT_NE(c.act_vehicle(), nullptr);
  std::array<double, 14> zero{};
  double action[4];
  EXPECT_EQ(c.act_vehicle()(zero.data(), action), 1);
}

TEST_F(CPolicyExport, BicycleIsBitIdenticalToTheCppPolicyOn100000Observations) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  Theta theta(30);
  for (double& w : theta) w = 2 * normal(rng);
  const LoadedCPolicy c(export_c_policy(bicycle_policy_json(theta), "bicycle.json"), dir_);
  const BicyclePolicy policy = make_bicycle_policy();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mismatches m;
  for (int i = 0; i < kInputs; ++i) {
    // Angles to the goal mostly in (-pi, pi], some beyond (angle_sin's std::sin path).
    const BicycleObservation o{0.3 * u(rng), 2 * u(rng), 1.2 * u(rng), 4 * u(rng), 3.5 * u(rng)};
    const double observation[5] = {o.omega, o.omega_dot, o.theta, o.theta_dot, o.goal_angle};
    double action[2];
    EXPECT_EQ(c.act()(observation, action), 0);
    m.check(policy.act(theta, o), action, fmt::format("input {}", i));
  }
  EXPECT_EQ(m.count, 0) << m.first;
}

TEST_F(CPolicyExport, PendulumIsBitIdenticalToTheCppPolicyOn100000ObservationsWithFiveOrSevenNumbers) {
  const Theta seven = {0.3, 1.5, 20.0, 4.0, 0.6, 1.5, 0.05};
  for (const std::size_t count : {PendulumSwingUpPolicy::kBaseCount, seven.size()}) {
    SCOPED_TRACE(count);
    const Theta theta(seven.begin(), seven.begin() + static_cast<std::ptrdiff_t>(count));
    const LoadedCPolicy c(export_c_policy(pendulum_policy_json(theta), "pendulum.json"),
                          dir_ / std::to_string(count));
    const PendulumSwingUpPolicy policy;
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mismatches m;
    int stabilising = 0, saturated = 0;
    for (int i = 0; i < kInputs; ++i) {
      const double angle = std::numbers::pi * u(rng);
      const PendulumObservation o{std::cos(angle), std::sin(angle), 8 * u(rng)};
      const double observation[3] = {o.cos_theta, o.sin_theta, o.theta_dot};
      double action[1];
      EXPECT_EQ(c.act()(observation, action), 0);
      const double torque = policy.act(theta, o);
      m.check(std::array<double, 1>{torque}, action, fmt::format("input {}", i));
      stabilising += std::abs(std::atan2(o.sin_theta, o.cos_theta)) < 0.5;
      saturated += std::abs(torque) == PendulumConstants::max_torque;
    }
    EXPECT_EQ(m.count, 0) << m.first;
    EXPECT_GT(stabilising, kInputs / 20);  // both branches of the class are exercised
    EXPECT_GT(saturated, kInputs / 20);
    EXPECT_LT(saturated, kInputs);
  }
}

// PREFIX_memory of the hover class with the integral term, as its header declares it.
struct CIntegralMemory {
  double integral[4];
  int started;
};

// The exported controller served to the ground-truth flight loop (heli/flights.hpp) through the same
// interface as the C++ one.
class CController final : public heli::HeliController {
 public:
  explicit CController(const LoadedCPolicy& c) : c_(c) {}
  using heli::HeliController::act;
  Controls act(const LoggedState& estimate, double time, heli::ControllerMemory& memory) const override {
    std::array<double, 13> observation;
    observation[0] = time;
    std::copy(estimate.begin(), estimate.end(), observation.begin() + 1);
    Controls a;
    if (!c_.act_flight()) {
      c_.act()(observation.data(), a.data());
      return a;
    }
    // The flight's memory lives in the C struct the header documents ({double integral[4]; int started;}).
    LoadedCPolicy::Memory c_memory;
    CIntegralMemory* m = std::launder(reinterpret_cast<CIntegralMemory*>(c_memory.bytes));
    std::copy(memory.integral.begin(), memory.integral.end(), m->integral);
    m->started = memory.started ? 1 : 0;
    c_.act_flight()(&c_memory, observation.data(), a.data());
    std::copy(m->integral, m->integral + 4, memory.integral.begin());
    memory.started = m->started != 0;
    return a;
  }
  heli::SetPoint target(double time) const override {
    double sp[4];
    c_.target()(time, sp);
    return {sp[0], sp[1], sp[2], sp[3]};
  }

 private:
  const LoadedCPolicy& c_;
};

void expect_same_flights(const std::vector<heli::FlightRecord>& cpp,
                         const std::vector<heli::FlightRecord>& c) {
  ASSERT_EQ(cpp.size(), c.size());
  for (std::size_t i = 0; i < cpp.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(cpp[i].crashed, c[i].crashed);
    EXPECT_EQ(cpp[i].steps, c[i].steps);
    EXPECT_TRUE(same_bits(cpp[i].sum_sq_position, c[i].sum_sq_position));
    EXPECT_TRUE(same_bits(cpp[i].sum_sq_velocity, c[i].sum_sq_velocity));
    EXPECT_TRUE(same_bits(cpp[i].sum_sq_yaw, c[i].sum_sq_yaw));
    ASSERT_EQ(cpp[i].trace.size(), c[i].trace.size());
    for (std::size_t t = 0; t < cpp[i].trace.size(); ++t) {
      const auto& a = cpp[i].trace[t];
      const auto& b = c[i].trace[t];
      bool same = true;
      for (std::size_t k = 0; k < a.truth.size(); ++k) same = same && same_bits(a.truth[k], b.truth[k]);
      for (std::size_t k = 0; k < 4; ++k) same = same && same_bits(a.controls[k], b.controls[k]);
      same = same && same_bits(a.target.x, b.target.x) && same_bits(a.target.z, b.target.z) &&
             same_bits(a.target.yaw, b.target.yaw);
      ASSERT_TRUE(same) << "step " << t;
    }
  }
}

TEST_F(CPolicyExport, ExportedControllersFlyTheGroundTruthExactlyAsTheCppPolicies) {
  heli::AircraftParams params;
  params.conditions.start_pos_sigma = 1.0;
  params.conditions.start_vel_sigma = 0.3;
  const heli::Aircraft aircraft(params);
  heli::FlightOptions options;
  options.flights = 3;
  options.seconds = 20;
  options.trace_flights = 3;
  options.seed = 7;
  // The hover controller at its trimmed start with tanh terms switched on, and a manoeuvre.
  // And the hover controller with the integral term, in a steady wind that it has to lean into.
  params.conditions.mean_wind_W = heli::Vec3(3, -2, 0);
  const heli::Aircraft windy(params);
  const std::pair<heli::PolicyFile, const heli::Aircraft*> cases[] = {
      {hover_file(8, 0.2, {0, 0, -10, 0}), &aircraft},
      {maneuver_file("III.1", 9, 0.1), &aircraft},
      {hover_file(8, 0.2, {0, 0, -10, 0}, {.dt = 0.02}), &windy}};
  for (const auto& [file, flown_on] : cases) {
    SCOPED_TRACE(file.class_name + (file.options.contains("integral") ? " with the integral term" : ""));
    const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "policy.json");
    const LoadedCPolicy c(code,
                          dir_ / fmt::format("{}{}", file.class_name, code.has_memory ? "-memory" : ""));
    const auto cpp_flights =
        heli::fly_controller(*flown_on, *heli::make_controller(file, "policy.json"), options);
    const auto c_flights = heli::fly_controller(*flown_on, CController(c), options);
    expect_same_flights(cpp_flights, c_flights);
    // A flight that flies: the comparison covers the whole 20 s, not a crash after a few steps.
    EXPECT_FALSE(cpp_flights[0].crashed);
  }
}

// With the integral term the controller remembers: 100 flights of 1000 control periods (random states, so the
// integral also runs into its limits), the C memory and the C++ memory side by side, and now and then a
// non-finite observation, which both leave alone (the C answers the trim, as `heli control` does).
TEST_F(CPolicyExport, HoverWithTheIntegralTermIsBitIdenticalOverAHundredFlightsOfAThousandSteps) {
  const heli::ErrorIntegrator integrator{.dt = 0.02, .limit_position = 4, .limit_yaw = 1};
  // With command limits too: the act with memory clips as the act without.
  const heli::PolicyFile file = hover_file(3, 1.0, {3.0, -2.0, -12.0, 0.7}, integrator, true);
  const CPolicyCode code = export_c_policy(heli::policy_file_json(file), "hover.json");
  ASSERT_TRUE(code.has_memory);
  EXPECT_NE(code.source.find("kCommandUpper[c]"), std::string::npos);
  EXPECT_NE(
      code.header.find("typedef struct pegasus_policy_memory {\n  double integral[4];\n  int started;\n}"),
      std::string::npos)
      << code.header;
  EXPECT_NE(
      code.header.find("int pegasus_policy_act(pegasus_policy_memory* memory, const double* observation, "
                       "double* action);"),
      std::string::npos);
  const LoadedCPolicy c(code, dir_);
  ASSERT_EQ(c.act(), nullptr);
  const auto cpp = heli::make_controller(file, "hover.json");
  std::mt19937_64 rng(4);
  Mismatches actions, memories;
  int at_limit = 0;
  for (int flight = 0; flight < kInputs / 1000; ++flight) {
    heli::ControllerMemory memory;
    LoadedCPolicy::Memory c_memory;
    c.reset()(&c_memory);
    const auto* m = std::launder(reinterpret_cast<const CIntegralMemory*>(c_memory.bytes));
    for (int step = 0; step < 1000; ++step) {
      const double t = 0.02 * step;
      LoggedState s = random_state(rng, file.target);
      const bool bad = step % 97 == 50;
      if (bad) s[2] = std::numeric_limits<double>::quiet_NaN();
      std::array<double, 13> observation;
      observation[0] = t;
      std::copy(s.begin(), s.end(), observation.begin() + 1);
      double action[4];
      ASSERT_EQ(c.act_flight()(&c_memory, observation.data(), action), bad ? 1 : 0);
      const heli::ControllerMemory before = memory;
      const Controls a = cpp->act(s, t, memory);
      const std::string where = fmt::format("flight {} step {}", flight, step);
      if (bad) {
        EXPECT_EQ(memory.integral, before.integral) << where;
      } else {
        actions.check(a, action, where);
      }
      memories.check(memory.integral, m->integral, where);
      at_limit += std::abs(memory.integral[0]) == integrator.limit_position;
    }
  }
  EXPECT_EQ(actions.count, 0) << actions.first;
  EXPECT_EQ(memories.count, 0) << memories.first;
  EXPECT_GT(at_limit, 1000);  // the anti-windup limit was reached, and matched

  // In an aircraft's own terms the memory comes first too, and one flight's answers match the C++ ones.
  const logs::Vehicle vehicle = logs::parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  const CPolicyCode own =
      export_c_policy(heli::policy_file_json(file), "p.json", {.prefix = "outside", .vehicle = &vehicle});
  EXPECT_NE(own.header.find("int outside_act_vehicle(outside_memory* memory, const double* observation, "
                            "double* action);"),
            std::string::npos);
  const LoadedCPolicy cv(own, dir_ / "vehicle");
  ASSERT_NE(cv.act_vehicle_flight(), nullptr);
  heli::ControllerMemory memory;
  LoadedCPolicy::Memory c_memory;
  cv.reset()(&c_memory);
  for (int step = 0; step < 2000; ++step) {
    const double t = 0.1 * step;
    const auto native_state = test_support::outside_state(random_state(rng, file.target));
    std::array<double, 14> observation;
    observation[0] = t;
    std::copy(native_state.begin(), native_state.end(), observation.begin() + 1);
    double action[4];
    EXPECT_EQ(cv.act_vehicle_flight()(&c_memory, observation.data(), action), 0);
    actions.check(vehicle.native_of(cpp->act(vehicle.state_of(native_state), t, memory)), action,
                  fmt::format("vehicle step {}", step));
  }
  EXPECT_EQ(actions.count, 0) << actions.first;
  EXPECT_NE(memory.integral[0], 0.0);
}

}  // namespace
}  // namespace pegasus::codegen
