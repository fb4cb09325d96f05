#pragma once
// Flights on the ground-truth aircraft (thesis §5.3, Figs 5.6-5.7): a controller (a policy file's
// HeliController) or the scripted pilot holding a hover, from perturbed starts, with gusts and state-estimate
// errors on. The controller sees only the estimate (Aircraft::observe); errors are scored on the true state.
//
// Flight i draws everything from mix_seed(seed, i): stream 0 the initial state, stream 1 the per-step gusts
// and estimate errors, stream 2 the pilot's own noise. The aircraft's noise does not depend on the controls,
// so a controller and the pilot flown with the same seed meet the same start and the same gusts.
//
// Scores over every 50 Hz step of every flight (a crashed flight counts up to its crash), true state s, set
// point s* of that step:
//   rms_position_m    sqrt(mean |p_W - p*_W|^2)                         (3-D distance, m)
//   rms_velocity_mps  sqrt(mean |v_W - v*_W|^2), v* the set point's velocity (0 in a hover; central
//   differences
//                     of target(t) otherwise)
//   rms_yaw_rad       sqrt(mean wrap(yaw - yaw*)^2)
//   judged_cost       with FlightOptions::cost (a vehicle file's [cost]): per flight, the sum over its
//   control
//                     steps of the reward's state cost of the true state and its action cost of the controls
//                     sent, plus the crash cost once for a crash; the mean over the flights
#include <cstdint>
#include <optional>
#include <vector>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus::heli {

// The cost a flight is judged by (logs::judged_reward of a vehicle file's [cost], and its crash cost).
struct FlightCost {
  HoverReward reward{};
  double crash = 0;
};

struct FlightOptions {
  int flights = 100;
  double seconds = 60;
  std::uint64_t seed = 1;
  int trace_flights = 10;  // flights whose every step is kept (FlightRecord::trace)
  // Aircraft steps per controller call: the controls are held in between (a zero-order hold), as on a flight
  // computer that runs its controller slower than the aircraft's 50 Hz (a policy trained at 10 Hz: 5).
  int control_every = 1;
  std::optional<FlightCost> cost{};  // none: no judged cost
  bool IsValid(std::string* error) const;

  // The numbers a user sets, once (issue 49 item 1): `fly`'s options flights, seconds and trace_flights with
  // their bounds and reading, `heli pipeline`'s flights and flight_seconds, and IsValid's bounds.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = FlightOptions;
    v.setting({"flights", 1, 1000000, false, "", "flights from perturbed starts"}, &O::flights);
    v.setting({"seconds", 0, 36000, true, "s", "flight length, s"}, &O::seconds);
    v.setting({"trace_flights", 0, 1000000, false, "",
               "flights written step by step to flights.csv (the first ones)"},
              &O::trace_flights);
  }
};

struct FlightRow {
  double time = 0;
  LoggedState truth{};
  Controls controls{};
  SetPoint target{};
};

struct FlightRecord {
  bool crashed = false;
  CrashReason crash = CrashReason::kNone;
  double crash_time = -1;
  int steps = 0;                                                    // 50 Hz steps flown
  double sum_sq_position = 0, sum_sq_velocity = 0, sum_sq_yaw = 0;  // over the steps
  double judged_cost = 0;                                           // with FlightOptions::cost
  std::vector<FlightRow> trace;  // every step, for the first trace_flights flights
};

struct FlightSummary {
  int flights = 0, crashes = 0;
  double rms_position_m = 0, rms_velocity_mps = 0, rms_yaw_rad = 0;
  double judged_cost = 0;  // mean per flight (FlightRecord::judged_cost)
};
FlightSummary summarize_flights(const std::vector<FlightRecord>& flights);

// A controller's flights. The aircraft's params give the start (start_p_W, start_yaw, start_*_sigma) and the
// disturbances.
std::vector<FlightRecord> fly_controller(const GroundTruth& aircraft, const HeliController& controller,
                                         const FlightOptions& options, ThreadPool* pool = nullptr);
// The scripted pilot's hover (no sweeps) at `hold`, the same starts and gusts.
std::vector<FlightRecord> fly_pilot_hover(const GroundTruth& aircraft, const PilotOptions& pilot,
                                          const SetPoint& hold, const FlightOptions& options,
                                          ThreadPool* pool = nullptr);

}  // namespace pegasus::heli
