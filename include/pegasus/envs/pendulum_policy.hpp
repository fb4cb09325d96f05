#pragma once
// A policy class for Pendulum-v1 (envs/pendulum.hpp): an energy-pumping swing-up with a linear stabiliser
// near the top, a "partial program" in the sense of thesis §4.1 with seven tunable numbers.
//
// With a = 3 g / (2 l) and b = 3 / (m l^2) the pendulum obeys thetadot' = a sin(theta) + b u, so
//   E = thetadot^2 / 2 + a cos(theta)
// is conserved without torque, equals a at rest upright, and changes at dE/dt = b u thetadot. Hence
//   swing-up:   u = clip(k_E (E* - E) (thetadot + l_s sin(theta)), +-2),  E* = a + e_0,
// pumps energy in while E < E* and takes it out above (a bang-bang push along the motion once k_E is
// large: the torque of 2 N m lifts at most sin(theta) = 0.4 statically, so the pendulum must swing).
// thetadot + l_s sin(theta) = thetadot + (l_s / a) a sin(theta) is the rate about l_s / a seconds ahead
// under gravity alone: with l_s > 0 the push turns round before the swing does, instead of fighting
// gravity through each turning point.
//   stabilise:  u = clip(-k_p phi - k_d thetadot, +-2)  while |phi + c thetadot| < r,
// phi = atan2(sin, cos) the angle from upright in (-pi, pi]; phi + c thetadot is the angle about c seconds
// ahead, so with c > 0 a pendulum arriving fast is caught a little early and one leaving is let go.
// The parameters, in this order:
//   swing.gain        k_E >= 0   (N m s / rad^3; scale 0.05)
//   swing.energy      e_0        (rad^2/s^2; energy target above rest upright, scale 1)
//   stabilise.angle   k_p >= 0   (N m / rad; scale 2)
//   stabilise.rate    k_d >= 0   (N m s / rad; scale 0.5)
//   stabilise.region  r in [0, pi] (rad; scale 0.2)
//   swing.lead        l_s in [-6, 6] (rad/s; scale 0.5: a lead of a few time steps is l_s ~ 1-3)
//   stabilise.skew    c in [-1, 1]   (s; scale 0.1: a few time steps of 0.05 s)
// All gains start at 0 (no torque at all: the search starts from a policy that knows nothing), the region
// at 0.5 rad, the lead and the skew at 0, where the class is the five-number class before them (bit for
// bit). PendulumSwingUpPolicy(false) is that five-number class: its spec lists the first five only, and
// act() reads the lead and the skew as 0 from a theta without them. Training (experiments/
// pendulum_experiment.hpp) races to the bar with the five and then refines all seven.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

class PendulumSwingUpPolicy {
 public:
  using Action = double;
  enum Index {
    kSwingGain = 0,
    kSwingEnergy,
    kStabiliseAngle,
    kStabiliseRate,
    kStabiliseRegion,
    kSwingLead,
    kStabiliseSkew,
    kCount
  };
  static constexpr std::size_t kBaseCount =
      kSwingLead;  // the five numbers of the swing-up without refinements

  // refinements = false: the spec lists the first kBaseCount parameters only.
  explicit PendulumSwingUpPolicy(bool refinements = true);
  const ParameterSpec& parameters() const { return spec_; }

  double act(std::span<const double> w, const PendulumObservation& o) const {
    using K = PendulumConstants;
    constexpr double a = 3.0 * K::g / (2.0 * K::l);
    const double phi = std::atan2(o.sin_theta, o.cos_theta);
    const double lead = w.size() > kSwingLead ? w[kSwingLead] : 0.0;
    const double skew = w.size() > kStabiliseSkew ? w[kStabiliseSkew] : 0.0;
    double u;
    if (std::abs(phi + skew * o.theta_dot) < w[kStabiliseRegion]) {
      u = -w[kStabiliseAngle] * phi - w[kStabiliseRate] * o.theta_dot;
    } else {
      const double energy = 0.5 * o.theta_dot * o.theta_dot + a * o.cos_theta;
      u = w[kSwingGain] * (a + w[kSwingEnergy] - energy) * (o.theta_dot + lead * o.sin_theta);
    }
    return std::clamp(u, -K::max_torque, K::max_torque);
  }

 private:
  ParameterSpec spec_;
};

}  // namespace pegasus
