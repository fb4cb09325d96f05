#include "pegasus/envs/bicycle.hpp"

#include <fmt/format.h>

#include "pegasus/core/error.hpp"
#include "pegasus/core/reward_limits.hpp"

namespace pegasus {

namespace {
bool reject(std::string* error, const std::string& field, const std::string& expected, double got) {
  if (error) *error = fmt::format("{}: expected {}, got {}", field, expected, got);
  return false;
}
}  // namespace

bool BicycleOptions::IsValid(std::string* error) const {
  const auto finite = [](double x) { return std::isfinite(x); };
  if (!goal.at_infinity) {
    if (!finite(goal.x)) return reject(error, "goal.x", "a finite number", goal.x);
    if (!finite(goal.y)) return reject(error, "goal.y", "a finite number", goal.y);
    if (!(goal.radius > 0.0 && finite(goal.radius)))
      return reject(error, "goal.radius", "a number > 0", goal.radius);
  } else if (!finite(goal.direction)) {
    return reject(error, "goal.direction", "a finite number", goal.direction);
  }
  const std::pair<const char*, double> widths[] = {{"start.omega", start.omega},
                                                   {"start.omega_dot", start.omega_dot},
                                                   {"start.theta", start.theta},
                                                   {"start.theta_dot", start.theta_dot}};
  for (const auto& [name, value] : widths)
    if (!(value >= 0.0 && finite(value))) return reject(error, name, "a finite number >= 0", value);
  if (!(start.omega < BicycleConstants::fall_angle))
    return reject(error, "start.omega", "a number below the fall angle pi/15", start.omega);
  if (!(start.theta <= BicycleConstants::max_handlebar))
    return reject(error, "start.theta", "a number <= 1.3963", start.theta);
  if (!(start.goal_angle >= 0.0 && start.goal_angle <= std::numbers::pi))
    return reject(error, "start.goal_angle", "a number in [0, pi]", start.goal_angle);
  const std::string reward_range = fmt::format("a number in [-{0}, {0}]", kMaxRewardWeight);
  if (!(std::abs(fall_reward) <= kMaxRewardWeight))
    return reject(error, "fall_reward", reward_range, fall_reward);
  if (!(std::abs(goal_reward) <= kMaxRewardWeight))
    return reject(error, "goal_reward", reward_range, goal_reward);
  if (!(noise >= 0.0 && finite(noise))) return reject(error, "noise", "a finite number >= 0", noise);
  return true;
}

Bicycle::Bicycle(const BicycleOptions& options) : options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) throw InputError("bicycle: " + error);
  goal_cos_ = std::cos(options_.goal.direction);
  goal_sin_ = std::sin(options_.goal.direction);
}

ActionSpace Bicycle::action_space() const {
  return ActionSpace::box({-K::max_torque, -K::max_displacement}, {K::max_torque, K::max_displacement});
}

Bicycle::State Bicycle::initial_state(std::span<const double> p0) const {
  const auto uniform = [&](std::size_t j, double half_width) { return half_width * (2.0 * p0[j] - 1.0); };
  State s;
  s.omega = uniform(0, options_.start.omega);
  s.omega_dot = uniform(1, options_.start.omega_dot);
  s.theta = uniform(2, options_.start.theta);
  s.theta_dot = uniform(3, options_.start.theta_dot);
  s.sin_theta = std::sin(s.theta);
  s.cos_theta = std::cos(s.theta);
  s.trig_of = s.theta;
  const double goal_angle = uniform(4, options_.start.goal_angle);
  const double to_goal =
      options_.goal.at_infinity ? options_.goal.direction : std::atan2(options_.goal.y, options_.goal.x);
  // The frame points goal_angle clockwise of the goal, so that the goal lies goal_angle to its left.
  s.psi = bicycle_detail::wrap_angle(to_goal - goal_angle - std::numbers::pi / 2);
  s.xb = 0.0;
  s.yb = 0.0;
  s.xf = -K::l * std::sin(s.psi);
  s.yf = K::l * std::cos(s.psi);
  s.status = State::kRiding;
  return s;
}

double Bicycle::event_fraction(const State& s, const Action&, const State& next) const {
  if (s.status != State::kRiding) return 0.0;
  if (next.status == State::kFallen) {
    // omega(tau) = omega + tau (omega' - omega) reaches +-pi/15.
    const double bound = next.omega > 0.0 ? K::fall_angle : -K::fall_angle;
    const double change = next.omega - s.omega;
    if (change == 0.0) return 0.0;
    return std::clamp((bound - s.omega) / change, 0.0, 1.0);
  }
  if (next.status == State::kAtGoal) {
    // The front tyre moves on the segment f + tau (f' - f); the smallest tau with |f(tau) - goal| = radius.
    const double ex = s.xf - options_.goal.x, ey = s.yf - options_.goal.y;
    const double dx = next.xf - s.xf, dy = next.yf - s.yf;
    const double a = dx * dx + dy * dy;
    const double b = 2.0 * (ex * dx + ey * dy);
    const double c = ex * ex + ey * ey - options_.goal.radius * options_.goal.radius;
    if (a == 0.0) return 0.0;
    const double disc = std::max(0.0, b * b - 4.0 * a * c);
    return std::clamp((-b - std::sqrt(disc)) / (2.0 * a), 0.0, 1.0);
  }
  return 0.0;
}

}  // namespace pegasus
