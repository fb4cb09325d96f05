#include "pegasus/heli/flights.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/random/seed.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {
namespace {

// Flies one flight with act(estimate, time) -> controls and target(time) -> set point.
template <class Act, class Target>
FlightRecord fly_one(const GroundTruth& aircraft, const FlightOptions& o, int flight, Act&& act,
                     Target&& target) {
  const double dt = aircraft.step_seconds();
  const auto steps = static_cast<int>(std::llround(o.seconds / dt));
  const std::uint64_t seed = mix_seed(o.seed, static_cast<std::uint64_t>(flight));
  UniformStream init(seed, 0), noise(seed, 1);
  std::vector<double> p(static_cast<std::size_t>(aircraft.initial_noise_dim()));
  for (double& u : p) u = init.next();
  const std::unique_ptr<SimulatedFlight> s = aircraft.start_flight(p);
  p.resize(static_cast<std::size_t>(aircraft.step_noise_dim()));
  FlightRecord r;
  const bool trace = flight < o.trace_flights;
  if (trace) r.trace.reserve(static_cast<std::size_t>(steps));
  Controls a{};
  for (int t = 0; t < steps; ++t) {
    const double time = t * dt;
    const LoggedState truth = s->truth();
    const bool control_step = t % o.control_every == 0;
    if (control_step) a = act(s->observe(), time);
    const SetPoint sp = target(time);
    if (o.cost && control_step)
      r.judged_cost += o.cost->reward.state_cost(truth, sp) + o.cost->reward.action_cost(a);
    // The set point's velocity by central differences (exactly 0 for a fixed set point).
    const SetPoint before = target(time - dt), after = target(time + dt);
    const double vx = (after.x - before.x) / (2 * dt), vy = (after.y - before.y) / (2 * dt),
                 vz = (after.z - before.z) / (2 * dt);
    const double ex = truth[logged::x] - sp.x, ey = truth[logged::y] - sp.y, ez = truth[logged::z] - sp.z;
    const double eu = truth[logged::xdot] - vx, ev = truth[logged::ydot] - vy, ew = truth[logged::zdot] - vz;
    const double eyaw = wrap_angle(truth[logged::yaw] - sp.yaw);
    r.sum_sq_position += ex * ex + ey * ey + ez * ez;
    r.sum_sq_velocity += eu * eu + ev * ev + ew * ew;
    r.sum_sq_yaw += eyaw * eyaw;
    ++r.steps;
    if (trace) r.trace.push_back({time, truth, a, sp});
    for (double& u : p) u = noise.next();
    s->step(a, p);
    if (s->crash() != CrashReason::kNone) {
      r.crashed = true;
      r.crash = s->crash();
      r.crash_time = time + dt;
      if (o.cost) r.judged_cost += o.cost->crash;
      break;
    }
  }
  return r;
}

template <class FlyOne>
std::vector<FlightRecord> fly_all(const FlightOptions& o, ThreadPool* pool, FlyOne&& fly) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("flights: " + error);
  std::vector<FlightRecord> records(static_cast<std::size_t>(o.flights));
  auto body = [&](std::size_t i) { records[i] = fly(static_cast<int>(i)); };
  if (pool) {
    pool->parallel_for(records.size(), body, 1);
  } else {
    for (std::size_t i = 0; i < records.size(); ++i) body(i);
  }
  return records;
}

}  // namespace

bool FlightOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (std::string out = numbers_out_of_bounds(*this); !out.empty()) return fail(std::move(out));
  if (control_every < 1)
    return fail(fmt::format("control_every: expected an integer >= 1, got {}", control_every));
  return true;
}

FlightSummary summarize_flights(const std::vector<FlightRecord>& flights) {
  FlightSummary s;
  double pos = 0, vel = 0, yaw = 0, cost = 0;
  long long steps = 0;
  for (const auto& f : flights) {
    ++s.flights;
    s.crashes += f.crashed ? 1 : 0;
    pos += f.sum_sq_position;
    vel += f.sum_sq_velocity;
    yaw += f.sum_sq_yaw;
    cost += f.judged_cost;
    steps += f.steps;
  }
  if (s.flights > 0) s.judged_cost = cost / s.flights;
  if (steps > 0) {
    const auto n = static_cast<double>(steps);
    s.rms_position_m = std::sqrt(pos / n);
    s.rms_velocity_mps = std::sqrt(vel / n);
    s.rms_yaw_rad = std::sqrt(yaw / n);
  }
  return s;
}

std::vector<FlightRecord> fly_controller(const GroundTruth& aircraft, const HeliController& controller,
                                         const FlightOptions& options, ThreadPool* pool) {
  return fly_all(options, pool, [&](int i) {
    ControllerMemory memory;  // the flight's: zero at its start
    return fly_one(
        aircraft, options, i,
        [&](const LoggedState& est, double time) { return controller.act(est, time, memory); },
        [&](double time) { return controller.target(time); });
  });
}

std::vector<FlightRecord> fly_pilot_hover(const GroundTruth& aircraft, const PilotOptions& pilot_options,
                                          const SetPoint& hold, const FlightOptions& options,
                                          ThreadPool* pool) {
  PilotOptions po = pilot_options;
  po.sweeps = false;
  return fly_all(options, pool, [&](int i) {
    ScriptedPilot pilot(aircraft, po, mix_seed(options.seed, static_cast<std::uint64_t>(i)), 2);
    pilot.set_total_seconds(options.seconds);
    pilot.set_hold(hold.x, hold.y, hold.z, hold.yaw);
    return fly_one(
        aircraft, options, i, [&](const LoggedState& est, double time) { return pilot.act(est, time); },
        [&](double) { return hold; });
  });
}

}  // namespace pegasus::heli
