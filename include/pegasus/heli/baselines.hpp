#pragma once
// Hand-tuned baselines to judge a learned hover controller against (issues 48 and 53), one per built-in
// ground truth (heli/simulators.hpp), flown by `pegasus fly --baseline` / `--compare-baseline`:
//   xcell       "linear": a linear hover controller, the scripted pilot's law (hover_feedback) with its
//   delay,
//               lag, noise and sweeps gone, gains tuned by hand on the ground truth, and an integral term on
//               the position and yaw errors.
//   crazyflie2  "cascaded-pd": a multirotor's onboard position stack: position and velocity errors (plus
//               their integral) to a tilt set point, sent as the angle-mode commands; altitude and climb rate
//               to the collective; heading to the yaw-rate command.
// Both see the state estimate only, as a learned controller does, and run at the rate they are called.
// docs/results/baselines.md gives the tuning and the comparison.
#include <array>
#include <memory>
#include <string>

#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"

namespace pegasus::heli {

struct BaselineGains {
  PilotOptions law{};              // the feedback gains (PilotOptions' k_* fields and max_tilt_command)
  std::array<double, 4> k_int{};   // per s of the x, y, z and yaw errors' integrals (hover_feedback)
  double integral_limit_m_s = 20;  // anti-windup: |integral| per axis, m s (yaw: rad s)
};

// The baseline's name for a ground truth ("linear", "cascaded-pd"); throws std::invalid_argument for one
// without a baseline.
std::string baseline_name(const std::string& simulator);
// Its hand-tuned gains (the values and how they were tuned: baselines.cpp).
BaselineGains baseline_gains(const std::string& simulator);

// A baseline flown as a controller: holds `hold`, called every `control_seconds` (its integral's period).
class BaselineController : public HeliController {
 public:
  BaselineController(const GroundTruth& aircraft, BaselineGains gains, const SetPoint& hold,
                     double control_seconds);
  Controls act(const LoggedState& estimate, double time, ControllerMemory& memory) const override;
  SetPoint target(double) const override { return hold_; }

 private:
  HoverPoint trim_;
  double gravity_;
  BaselineGains gains_;
  SetPoint hold_;
  ErrorIntegrator integrator_;
};

std::unique_ptr<HeliController> make_baseline(const std::string& simulator, const GroundTruth& aircraft,
                                              const SetPoint& hold, double control_seconds);

}  // namespace pegasus::heli
