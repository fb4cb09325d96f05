// Every task's reward weights, shaping rates and penalties are bounded by kMaxRewardWeight in the library's
// own IsValid, so a Python or C++ caller is refused as the CLI is (at 1e308 a return overflowed to inf or NaN
// and training ended as if it had worked).
#include "pegasus/core/reward_limits.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "pegasus/envs/bicycle.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/maneuver_task.hpp"

namespace pegasus {
namespace {

// One bounded field: `field` is how the error names it, `is_valid(value)` validates options with the field
// set to value, `signed_range` when -kMaxRewardWeight is allowed too (a penalty).
struct BoundedField {
  std::string field;
  std::function<bool(double, std::string*)> is_valid;
  bool signed_range = false;
};

template <class Options, class Set>
BoundedField bounded(std::string field, Set set, bool signed_range = false) {
  return {field,
          [set](double value, std::string* error) {
            Options o;
            set(o, value);
            return o.IsValid(error);
          },
          signed_range};
}

std::vector<BoundedField> every_bounded_field() {
  return {
      bounded<BicycleOptions>(
          "fall_reward", [](auto& o, double v) { o.fall_reward = v; }, true),
      bounded<BicycleOptions>(
          "goal_reward", [](auto& o, double v) { o.goal_reward = v; }, true),
      bounded<BicycleTrainingOptions>("shaping_per_metre",
                                      [](auto& o, double v) { o.shaping_per_metre = v; }),
      bounded<heli::ManeuverReward>("alpha_pos", [](auto& o, double v) { o.alpha_pos = v; }),
      bounded<heli::ManeuverReward>("alpha_yaw", [](auto& o, double v) { o.alpha_yaw = v; }),
      bounded<heli::ManeuverReward>("alpha_vel", [](auto& o, double v) { o.alpha_vel = v; }),
      bounded<heli::ManeuverReward>("alpha_action[2]", [](auto& o, double v) { o.alpha_action[2] = v; }),
      bounded<heli::ManeuverTrainingOptions>("shaping_per_metre",
                                             [](auto& o, double v) { o.shaping_per_metre = v; }),
      bounded<heli::HoverReward>("alpha_pos", [](auto& o, double v) { o.alpha_pos[1] = v; }),
      bounded<heli::HoverReward>("alpha_vel", [](auto& o, double v) { o.alpha_vel[2] = v; }),
      bounded<heli::HoverReward>("alpha_yaw", [](auto& o, double v) { o.alpha_yaw = v; }),
      bounded<heli::HoverReward>("alpha_attitude", [](auto& o, double v) { o.alpha_attitude[0] = v; }),
      bounded<heli::HoverReward>("alpha_rate", [](auto& o, double v) { o.alpha_rate[2] = v; }),
      bounded<heli::HoverReward>("alpha_action", [](auto& o, double v) { o.alpha_action[3] = v; }),
  };
}

TEST(RewardLimits, EveryTaskTakesItsBoundAndRefusesJustBeyondItNamingTheField) {
  const double beyond = std::nextafter(kMaxRewardWeight, std::numeric_limits<double>::infinity());
  for (const BoundedField& f : every_bounded_field()) {
    SCOPED_TRACE(f.field);
    std::string error;
    EXPECT_TRUE(f.is_valid(kMaxRewardWeight, &error)) << error;
    EXPECT_TRUE(f.is_valid(0, &error)) << error;
    if (f.signed_range) {
      EXPECT_TRUE(f.is_valid(-kMaxRewardWeight, &error)) << error;
    }
    const double lowest = f.signed_range ? -beyond : -1e-300;
    for (const double bad : {beyond, lowest, 1e308, std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN()}) {
      error.clear();
      EXPECT_FALSE(f.is_valid(bad, &error)) << bad;
      EXPECT_NE(error.find(f.field), std::string::npos) << error;
      EXPECT_NE(error.find("1000000000000"), std::string::npos) << "the bound is named: " << error;
    }
  }
}

}  // namespace
}  // namespace pegasus
