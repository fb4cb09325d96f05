#include "pegasus/envs/bicycle_policy.hpp"

namespace pegasus {

std::vector<std::string> BicycleFeatures::names() {
  return {"omega",          "omega_sq",       "omega_cube", "omega_dot",  "omega_dot_sq",
          "omega_dot_cube", "theta",          "theta_sq",   "theta_cube", "theta_dot",
          "theta_dot_sq",   "theta_dot_cube", "goal",       "goal_sq",    "goal_sin"};
}

BicyclePolicy make_bicycle_policy() {
  return BicyclePolicy(BicycleFeatures{}, Bicycle().action_space(), {"T", "d"}, BicycleFeatures::names(),
                       1.0);
}

Theta bicycle_balancing_theta() {
  Theta theta(2 * BicycleFeatures::kCount, 0.0);
  // The sigmoid maps w.x to T = 4 sigmoid(w.x) - 2, slope 1 N m per unit at 0: weights are gains times the
  // features' scales.
  theta[0] = 10.0 * BicycleFeatures::kOmegaScale;
  theta[3] = 5.0 * BicycleFeatures::kOmegaDotScale;
  theta[6] = -5.0 * BicycleFeatures::kThetaScale;
  theta[9] = -0.3 * BicycleFeatures::kThetaDotScale;
  return theta;
}

}  // namespace pegasus
