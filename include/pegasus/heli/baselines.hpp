#pragma once
// Hand-tuned baselines to judge a learned hover controller against (issues 48 and 53), one per ground truth
// that registers one (heli/simulators.hpp: GroundTruthEntry::baseline), flown by `pegasus fly --baseline` /
// `--compare-baseline`. Each is the scripted pilot's stabilising law (hover_feedback) with its delay, lag,
// noise and sweeps gone, gains tuned by hand on its ground truth, and an integral term on the position and
// yaw errors:
//   "linear" (xcell, heavy-heli): a linear hover controller, attitude and rate feedback to the cyclic;
//   "cascaded-pd" (crazyflie2): a multirotor's onboard position stack: position and velocity errors (plus
//   their integral) to a tilt set point, sent as the angle-mode commands; altitude and climb rate to the
//   collective; heading to the yaw-rate command.
// They see the state estimate only, as a learned controller does, and run at the rate they are called.
// docs/results/baselines.md gives the tuning and the comparison.
#include <array>
#include <memory>
#include <string>

#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"

namespace pegasus::heli {

// The baseline's name for a ground truth ("linear", "cascaded-pd"); throws std::invalid_argument for one
// without a baseline.
std::string baseline_name(const std::string& simulator);
// Its hand-tuned gains, from its registry entry (the values and how they were tuned: simulators.cpp).
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
