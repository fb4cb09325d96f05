// A vehicle file's judged cost (issue 53 item 3, issue 48 item 5): [cost] maps exactly onto the hover reward.
// A known state of the shipped ROS-convention quadrotor (ENU, FLU, quaternion x y z w, degrees) is priced by
// hand in the aircraft's own terms, with an independent quaternion product, and must equal the reward the
// pipeline computes on the converted state; no default term stays; bad sections name their line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "support/input_error.hpp"

namespace pegasus::logs::cost_test {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

template <class F>
void expect_error(F&& f, std::initializer_list<const char*> parts) {
  const std::string message = test_support::input_error_message(std::forward<F>(f));
  for (const char* part : parts) EXPECT_THAT(message, ::testing::HasSubstr(part));
}

std::string shipped(const char* name) {
  std::ifstream in(std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles" / name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The ROS quadrotor with a judged cost on every kind of term (weights in its frames and units).
constexpr const char* kRosCost = R"(
[cost]
position = [1.0, 2.0, 4.0]        # per m^2, ENU axes
velocity = [0.5, 0.25, 3.0]       # per (m/s)^2, ENU axes
quaternion = [10.0, 20.0, 30.0]   # per unit^2, FLU body axes
body_rates = [0.001, 0.002, 0.0005]  # per (deg/s)^2, FLU body axes
controls = [0.01, 0.02, 0.0001, 5.0]  # per channel unit^2: roll_sp deg, pitch_sp deg, yaw_rate_sp deg/s, thrust
controls_about = [0, 0, 0, 0.5]
crash = 1000
)";

TEST(JudgedCost, EqualsTheHoverRewardOnAKnownStateOfARosQuadrotor) {
  const Vehicle v = parse_vehicle(shipped("ros-quadrotor.toml") + kRosCost, "ros-cost.toml");
  ASSERT_TRUE(v.cost.has_value());
  EXPECT_EQ(v.cost->crash, 1000);
  // The aircraft's native state: ENU position and velocity, the attitude of body FLU in world ENU as x y z w,
  // FLU body rates in deg/s, and its four channels.
  const Eigen::Vector3d p(1.2, -0.5, 2.7), vel(0.3, -0.4, 0.2), w(10, -5, 20);
  const Eigen::Quaterniond q = Eigen::AngleAxisd(100 * kDeg, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-3 * kDeg, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(5 * kDeg, Eigen::Vector3d::UnitX());
  const std::array<double, 4> u{3, -2, 15, 0.55};  // roll_sp, pitch_sp (deg), yaw_rate_sp (deg/s), thrust
  // By hand, in its own terms: the set point is (0, 0, 2) m ENU facing north (yaw 90 deg from east).
  const Eigen::Vector3d target(0, 0, 2);
  const Eigen::Quaterniond q_target(Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d q_err = (q_target.inverse() * q).vec();  // FLU body axes
  const Eigen::Vector3d e = p - target;
  double by_hand = 1.0 * e.x() * e.x() + 2.0 * e.y() * e.y() + 4.0 * e.z() * e.z();
  by_hand += 0.5 * vel.x() * vel.x() + 0.25 * vel.y() * vel.y() + 3.0 * vel.z() * vel.z();
  by_hand += 10 * q_err.x() * q_err.x() + 20 * q_err.y() * q_err.y() + 30 * q_err.z() * q_err.z();
  by_hand += 0.001 * w.x() * w.x() + 0.002 * w.y() * w.y() + 0.0005 * w.z() * w.z();
  by_hand += 0.01 * 3 * 3 + 0.02 * 2 * 2 + 0.0001 * 15 * 15 + 5.0 * 0.05 * 0.05;
  // The pipeline's: the state converted as `control --vehicle` converts it, the reward the file's cost maps
  // to.
  const std::vector<double> native{p.x(), p.y(), p.z(), vel.x(), vel.y(), vel.z(), q.x(),
                                   q.y(), q.z(), q.w(), w.x(),   w.y(),   w.z()};
  const heli::LoggedState s = v.state_of(native);
  const heli::SetPoint t{v.target[0], v.target[1], v.target[2], v.target[3]};
  const heli::HoverReward r = judged_reward(v);
  std::string error;
  ASSERT_TRUE(r.IsValid(&error)) << error;
  const double pipeline = r.state_cost(s, t) + r.action_cost(v.axes_of(u));
  EXPECT_NEAR(pipeline, by_hand, 1e-12 * by_hand) << by_hand;
  EXPECT_GT(by_hand, 1);  // every term counted: not a comparison of zeros
  // At the set point at rest, level, facing north, with the controls at controls_about, it costs nothing.
  const Eigen::Quaterniond level(Eigen::AngleAxisd(90 * kDeg, Eigen::Vector3d::UnitZ()));
  const std::vector<double> hover{0, 0, 2, 0, 0, 0, level.x(), level.y(), level.z(), level.w(), 0, 0, 0};
  EXPECT_NEAR(
      r.state_cost(v.state_of(hover), t) + r.action_cost(v.axes_of(std::array<double, 4>{0, 0, 0, 0.5})), 0,
      1e-12);
}

TEST(JudgedCost, EulerWeightsInDegreesAndNoDefaultTermStays) {
  // The PX4 quadrotor (NED, FRD, rad) with an Euler cost: the yaw error wraps, and only the stated terms
  // stay.
  const Vehicle v = parse_vehicle(shipped("px4-quadrotor.toml") + R"(
[cost]
position = [2.0, 2.0, 0.0]
euler = [3.0, 4.0, 5.0]
)",
                                  "px4-cost.toml");
  const heli::HoverReward r = judged_reward(v);
  EXPECT_EQ(r.alpha_vel, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(r.alpha_action, (std::array<double, 4>{0, 0, 0, 0}));
  EXPECT_EQ(r.alpha_rate, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(r.alpha_body_rate, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(r.alpha_quaternion, (std::array<double, 3>{0, 0, 0}));
  heli::LoggedState s{};
  s[heli::logged::x] = 1, s[heli::logged::z] = -7, s[heli::logged::roll] = 0.1, s[heli::logged::pitch] = -0.2;
  s[heli::logged::yaw] = 3.1, s[heli::logged::xdot] = 5, s[heli::logged::roll_rate] = 2;
  const heli::SetPoint t{0, 0, -5, -3.1};  // 0.083 rad away across pi
  const double yaw_error = 2 * std::numbers::pi - 6.2;
  EXPECT_NEAR(r.state_cost(s, t), 2.0 * 1 + 3.0 * 0.01 + 4.0 * 0.04 + 5.0 * yaw_error * yaw_error, 1e-12);
  EXPECT_EQ(r.action_cost({0.5, 0.5, 0.5, 0.5}), 0);
  EXPECT_EQ(r.terms(50000).find("velocity"), std::string::npos) << r.terms(50000);
  EXPECT_NE(r.terms(50000).find("position x y z 2 2 0"), std::string::npos) << r.terms(50000);
  // In degrees the same cost has weights (pi/180)^2 smaller per deg^2.
  const Vehicle deg =
      parse_vehicle(shipped("ros-quadrotor.toml") + "[cost]\neuler = [3.0, 4.0, 5.0]\n", "d.toml");
  EXPECT_NEAR(judged_reward(deg).alpha_attitude[0], 3.0 / (kDeg * kDeg), 1e-9);
}

TEST(JudgedCost, EnvelopeLimitsAreInTheFilesUnits) {
  const Vehicle v = parse_vehicle(
      shipped("ros-quadrotor.toml") + "max_position_error = 3\nmax_speed = 4\nmax_rate = 180\n", "e.toml");
  EXPECT_EQ(v.max_position_error_m, 3);
  EXPECT_EQ(v.max_speed_mps, 4);
  EXPECT_NEAR(v.max_rate_radps, std::numbers::pi, 1e-15);  // 180 deg/s
  EXPECT_TRUE(std::isinf(parse_vehicle(shipped("ros-quadrotor.toml"), "r.toml").max_speed_mps));
}

TEST(JudgedCost, BadSectionsNameTheLineAndTheKey) {
  const std::string ros = shipped("ros-quadrotor.toml");
  expect_error([&] { parse_vehicle(ros + "[cost]\nposition = [1, 2]\n", "b.toml"); },
               {"b.toml:", "cost.position", "3 weights"});
  expect_error([&] { parse_vehicle(ros + "[cost]\neuler = [1, 2, 3]\nquaternion = [1, 2, 3]\n", "b.toml"); },
               {"b.toml:", "cost.quaternion", "not both"});
  expect_error(
      [&] { parse_vehicle(ros + "[cost]\nvelocity = [1, 1, 1]\n[hover.reward]\naction = 0\n", "b.toml"); },
      {"b.toml:", "hover.reward", "either [cost] or [hover.reward]"});
  expect_error([&] { parse_vehicle(ros + "[cost]\nposition_m = 1\n", "b.toml"); },
               {"b.toml:", "cost.position_m"});
}

}  // namespace
}  // namespace pegasus::logs::cost_test
