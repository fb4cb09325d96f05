#pragma once
// A policy class for Pendulum-v1 (envs/pendulum.hpp): an energy-pumping swing-up with a linear stabiliser
// near the top, a "partial program" in the sense of thesis §4.1 with five tunable numbers.
//
// With a = 3 g / (2 l) and b = 3 / (m l^2) the pendulum obeys thetadot' = a sin(theta) + b u, so
//   E = thetadot^2 / 2 + a cos(theta)
// is conserved without torque, equals a at rest upright, and changes at dE/dt = b u thetadot. Hence
//   swing-up:   u = clip(k_E (E* - E) thetadot, +-2),  E* = a + e_0,
// pumps energy in while E < E* and takes it out above (a bang-bang push along the motion once k_E is
// large: the torque of 2 N m lifts at most sin(theta) = 0.4 statically, so the pendulum must swing).
//   stabilise:  u = clip(-k_p phi - k_d thetadot, +-2)  while |phi| < r,
// phi = atan2(sin, cos) the angle from upright in (-pi, pi]. The parameters, in this order:
//   swing.gain        k_E >= 0   (N m s / rad^3; scale 0.05)
//   swing.energy      e_0        (rad^2/s^2; energy target above rest upright, scale 1)
//   stabilise.angle   k_p >= 0   (N m / rad; scale 2)
//   stabilise.rate    k_d >= 0   (N m s / rad; scale 0.5)
//   stabilise.region  r in [0, pi] (rad; scale 0.2)
// All gains start at 0 (no torque at all: the search starts from a policy that knows nothing), the region
// at 0.5 rad.
#include <algorithm>
#include <cmath>
#include <span>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

class PendulumSwingUpPolicy {
 public:
  using Action = double;
  enum Index { kSwingGain = 0, kSwingEnergy, kStabiliseAngle, kStabiliseRate, kStabiliseRegion, kCount };

  PendulumSwingUpPolicy();
  const ParameterSpec& parameters() const { return spec_; }

  double act(std::span<const double> w, const PendulumObservation& o) const {
    using K = PendulumConstants;
    constexpr double a = 3.0 * K::g / (2.0 * K::l);
    const double phi = std::atan2(o.sin_theta, o.cos_theta);
    double u;
    if (std::abs(phi) < w[kStabiliseRegion]) {
      u = -w[kStabiliseAngle] * phi - w[kStabiliseRate] * o.theta_dot;
    } else {
      const double energy = 0.5 * o.theta_dot * o.theta_dot + a * o.cos_theta;
      u = w[kSwingGain] * (a + w[kSwingEnergy] - energy) * o.theta_dot;
    }
    return std::clamp(u, -K::max_torque, K::max_torque);
  }

 private:
  ParameterSpec spec_;
};

}  // namespace pegasus
