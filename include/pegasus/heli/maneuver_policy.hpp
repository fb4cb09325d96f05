#pragma once
// The manoeuvre policy class of thesis §5.4 (Fig 5.9): the hover networks of Fig 5.4 (hover_policy.hpp) fed a
// set point that moves along a trajectory (trajectory.hpp), with the couplings Fig 5.9 adds.
//
// At time t (s since the manoeuvre began) with logged state s:
//   1. set point (x*, y*, z*, yaw*) = trajectory.delayed(t, z_delay): the ideal set point, except that in
//   angled
//      climbs and descents z* lags by the learned delay t of §5.4 (parameter "z_delay", s);
//   2. optional velocity feed-forward (an extension beyond Fig 5.9, off with
//   ManeuverPolicyOptions::feedforward =
//      false): the hover networks see the velocity relative to k_ff times the set point's own velocity and
//      yaw rate (parameter "feedforward", initially 1). A pure set-point follower lags a moving set point by
//      (velocity gain / position gain) x speed, several metres at 2.5 m/s, and cuts every corner by as much;
//      §5.4 names inverse-dynamics style corrections as the related practice;
//   3. t_c, a_c of the four hover networks (Eqs 5.7-5.8, HoverPolicy::unclipped);
//   4. the couplings of Fig 5.9, on the outputs' departure from trim:
//        a2 += "couple.tail_to_lat" * (a4 - trim4)   tail-rotor thrust pushes the aircraft sideways; lateral
//                                                     cyclic leans against it
//        a4 += "couple.coll_to_tail" * (a3 - trim3)  more collective, more main-rotor torque: the tail
//        answers
//   5. clipped to [-1, 1]; NaN becomes 0 (as HoverPolicy).
// Parameters: the 34 hover weights first (names "a1.bias", ...), then "couple.tail_to_lat",
// "couple.coll_to_tail", then "z_delay" (when learned) and "feedforward" (when used).
#include <memory>
#include <span>
#include <string>

#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/heli/trajectory.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus::heli {

// What the manoeuvre policy sees: the 12 logged states and the time since the manoeuvre began.
struct ManeuverObservation {
  LoggedState state{};
  double time = 0;  // s
};

struct ManeuverPolicyOptions {
  bool learn_delay = true;  // "z_delay" is a parameter (else the delay is 0)
  bool feedforward = true;  // "feedforward" is a parameter (else the hover networks see the plain velocity)
  double max_delay_s = 3;   // upper bound of z_delay, s
};

class ManeuverPolicy {
 public:
  using Observation = ManeuverObservation;
  using Action = Controls;
  static constexpr int kHover = HoverPolicy::kParameters;
  static constexpr int kTailToLat = kHover, kCollToTail = kHover + 1;

  // `init` gives the hover weights' starting values and the trim the couplings act about.
  ManeuverPolicy(std::shared_ptr<const Trajectory> trajectory, const HoverPolicyInit& init = {},
                 ManeuverPolicyOptions options = {});
  const ParameterSpec& parameters() const { return spec_; }
  const Trajectory& trajectory() const { return *trajectory_; }
  const ManeuverPolicyOptions& options() const { return options_; }
  const HoverPolicyInit& init() const { return init_; }

  // The z delay and feed-forward gain theta holds (0 and 0 where not parameters).
  double z_delay(std::span<const double> theta) const {
    return delay_index_ < 0 ? 0.0 : theta[static_cast<std::size_t>(delay_index_)];
  }
  double feedforward(std::span<const double> theta) const {
    return ff_index_ < 0 ? 0.0 : theta[static_cast<std::size_t>(ff_index_)];
  }
  // The set point fed to the hover networks at time t.
  SetPoint target(std::span<const double> theta, double time) const;
  Controls act(std::span<const double> theta, const ManeuverObservation& o) const;

  // Starting theta from a trained hover policy's 34 weights (couplings 0, no delay, feed-forward 1).
  Theta from_hover(std::span<const double> hover_theta) const;

 private:
  std::shared_ptr<const Trajectory> trajectory_;
  HoverPolicyInit init_;
  ManeuverPolicyOptions options_;
  ParameterSpec spec_;
  int delay_index_ = -1, ff_index_ = -1;
};

}  // namespace pegasus::heli
