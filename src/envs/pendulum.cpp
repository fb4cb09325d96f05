#include "pegasus/envs/pendulum.hpp"

#include <numbers>

#include "pegasus/envs/pendulum_policy.hpp"

namespace pegasus {

ActionSpace Pendulum::action_space() const { return ActionSpace::box({-K::max_torque}, {K::max_torque}); }

PendulumSwingUpPolicy::PendulumSwingUpPolicy(bool refinements) {
  spec_.add({.name = "swing.gain", .initial = 0.0, .lower = 0.0, .upper = 10.0, .scale = 0.05});
  spec_.add({.name = "swing.energy", .initial = 0.0, .lower = -15.0, .upper = 15.0, .scale = 1.0});
  spec_.add({.name = "stabilise.angle", .initial = 0.0, .lower = 0.0, .upper = 100.0, .scale = 2.0});
  spec_.add({.name = "stabilise.rate", .initial = 0.0, .lower = 0.0, .upper = 20.0, .scale = 0.5});
  spec_.add(
      {.name = "stabilise.region", .initial = 0.5, .lower = 0.0, .upper = std::numbers::pi, .scale = 0.2});
  if (!refinements) return;
  spec_.add({.name = "swing.lead", .initial = 0.0, .lower = -6.0, .upper = 6.0, .scale = 0.5});
  spec_.add({.name = "stabilise.skew", .initial = 0.0, .lower = -1.0, .upper = 1.0, .scale = 0.1});
}

}  // namespace pegasus
