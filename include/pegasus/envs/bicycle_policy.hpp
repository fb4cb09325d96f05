#pragma once
// The bicycle's policy class (thesis §4.6): fifteen simple, hand-chosen (not tuned) features x of the
// observation, and
//   T = sigmoid(w_T . x) (T_max - T_min) + T_min,   d = sigmoid(w_d . x) (d_max - d_min) + d_min,
// a SigmoidPolicy<2, BicycleFeatures> with the 30 parameters w_T and w_d ("w.T.<feature>", "w.d.<feature>").
//
// The features. Each of the four bicycle variables is first divided by a nominal size, so that a riding
// bicycle keeps it within about +-1 and every weight has the same scale:
//   omega^ = omega / (pi/15)   (the fall angle),     omega_dot^ = omega_dot / (1 rad/s),
//   theta^ = theta / (pi/4),                         theta_dot^ = theta_dot / (2 rad/s),
// and the heading error to the goal g^ = goal_angle / pi lies in (-1, 1]. Then, for each of the four:
//   x^           linear feedback (steer into the fall, damp the handlebar),
//   x^ |x^|      a signed square: grows faster than linear, a stronger reaction to large deviations,
//   x^^3         a cube: negligible near upright, decisive close to a fall;
// and for the heading error:
//   g^           turn towards the goal, at a rate proportional to the heading error,
//   g^ |g^|      a signed square: turn harder when far off course,
//   sin(goal_angle)   a smooth heading error that vanishes both on course and when the goal is straight
//                behind (where g^ jumps from -1 to +1).
// Every feature is odd under the mirror map (omega, theta, goal_angle and their rates negated) and there
// is no constant feature, so every policy of the class is mirror-symmetric: T(mirror s) = -T(s) and
// d(mirror s) = -d(s); w = 0 is the unsteered bicycle with the rider centred (T = 0, d = 0). The distance
// to the goal is not a feature (§4.6 footnote 15): the policy steers by the angle to the goal only.
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "pegasus/envs/bicycle.hpp"
#include "pegasus/policies/policies.hpp"

namespace pegasus {

struct BicycleFeatures {
  static constexpr int kCount = 15;
  static constexpr double kOmegaScale = std::numbers::pi / 15;  // rad
  static constexpr double kOmegaDotScale = 1.0;                 // rad/s
  static constexpr double kThetaScale = std::numbers::pi / 4;   // rad
  static constexpr double kThetaDotScale = 2.0;                 // rad/s

  int size() const { return kCount; }
  void operator()(const BicycleObservation& o, std::span<double> x) const {
    const std::array<double, 4> v = {o.omega / kOmegaScale, o.omega_dot / kOmegaDotScale,
                                     o.theta / kThetaScale, o.theta_dot / kThetaDotScale};
    for (std::size_t k = 0; k < 4; ++k) {
      x[3 * k] = v[k];
      x[3 * k + 1] = v[k] * std::abs(v[k]);
      x[3 * k + 2] = v[k] * v[k] * v[k];
    }
    const double g = o.goal_angle / std::numbers::pi;
    x[12] = g;
    x[13] = g * std::abs(g);
    x[14] = bicycle_detail::angle_sin(o.goal_angle);
  }
  // "omega", "omega_sq", "omega_cube", "omega_dot", ..., "goal", "goal_sq", "goal_sin".
  static std::vector<std::string> names();
};

using BicyclePolicy = SigmoidPolicy<2, BicycleFeatures>;

// The policy class over the bicycle's action box, parameters "w.T.<feature>" and "w.d.<feature>", all
// starting at 0 with scale 1.
BicyclePolicy make_bicycle_policy();

// A crude hand-set starting point: linear feedback T ~ 10 omega + 5 omega' - 5 theta - 0.3 theta' (N m,
// SI units; steer into the fall and damp the handlebar), nothing else. It keeps the bicycle up but
// ignores the goal. Why a starting point at all: from w = 0 every scenario falls within a second, U-hat
// there is a sum of fall penalties that is rugged at the scale of a finite difference, and gradient ascent
// stalls (random-walk hill climbing does leave that region from w = 0).
Theta bicycle_balancing_theta();

}  // namespace pegasus
