// What an identified model predicts on a hold-out log (thesis §5.2): the open-loop simulation of the model at
// its own rate, and Fig 5.2's errors against horizon (also as hover training runs the model, and the
// constant- velocity baseline). Fig 5.3's noise check is in noise_filter.cpp and noise_check_cells.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "log_at_rate.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::sysid {

namespace logged = heli::logged;

using heli::Vec3;

const std::array<const char*, kReportVars> kReportVarNames = {
    "x",    "y",         "z",          "roll",     "pitch",  "yaw",    "xdot",  "ydot",
    "zdot", "roll_rate", "pitch_rate", "yaw_rate", "xdot_b", "ydot_b", "zdot_b"};

// ---------------------------------------------------------------- simulation

InputVec sim_input(const SimState& s, const std::array<double, 4>& a) {
  InputVec x;
  x.head<kBodyVars>() = body_from_log_state(s.world);
  x[kFlapLon] = s.flap_lon;
  x[kFlapLat] = s.flap_lat;
  x[kGyro] = s.gyro;
  for (int c = 0; c < 4; ++c) x[kA1 + c] = a[static_cast<std::size_t>(c)];
  x[kOne] = 1;
  return x;
}

SimState sim_advance(const ModelStructure& m, const SimState& s, const std::array<double, 4>& a,
                     const BodyVec& delta, double dt) {
  const BodyVec b0 = body_from_log_state(s.world);
  const BodyVec b1 = b0 + delta;
  SimState n = s;
  auto& w = n.world;
  w[logged::roll] = b1[kRoll];
  w[logged::pitch] = b1[kPitch];
  w[logged::yaw] =
      heli::wrap_angle(s.world[logged::yaw] + dt * 0.5 * (s.world[logged::yaw_rate] + b1[kYawRate]));
  w[logged::roll_rate] = b1[kRollRate];
  w[logged::pitch_rate] = b1[kPitchRate];
  w[logged::yaw_rate] = b1[kYawRate];
  const Vec3 v_W = heli::world_from_body(heli::attitude_of(w), Vec3(b1[kU], b1[kV], b1[kW]));
  // Position by the trapezoid rule on the world velocity, axis by axis (x, y, z and xdot, ydot, zdot).
  for (std::size_t i = 0; i < 3; ++i) {
    w[logged::x + i] =
        s.world[logged::x + i] + dt * 0.5 * (s.world[logged::xdot + i] + v_W[static_cast<int>(i)]);
    w[logged::xdot + i] = v_W[static_cast<int>(i)];
  }
  const Vec3 w_B =
      heli::body_rates_from_euler_rates(heli::attitude_of(s.world), heli::euler_rates_of(s.world));
  m.extra.advance(dt, w_B, a, &n.flap_lon, &n.flap_lat, &n.gyro);
  return n;
}

ReportState report_state(const std::array<double, kLogStates>& s) {
  ReportState r{};
  std::copy(s.begin(), s.end(), r.begin());
  const BodyVec b = body_from_log_state(s);
  r[report_column::xdot_b] = b[kU];
  r[report_column::ydot_b] = b[kV];
  r[report_column::zdot_b] = b[kW];
  return r;
}

namespace {

// The log rows where open-loop predictions of `steps` model steps of `k` log rows start.
std::vector<std::size_t> prediction_starts(const FlightLog& test, std::size_t k, std::size_t steps,
                                           double start_spacing_s) {
  const auto spacing =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(start_spacing_s / test.dt())));
  std::vector<std::size_t> starts;
  for (std::size_t r = 0; r + steps * k < test.rows(); r += spacing) starts.push_back(r);
  return starts;
}

using Errors = std::vector<std::array<double, kReportVars>>;

// Squared prediction errors of every report variable (yaw's wrapped).
std::array<double, kReportVars> squared_errors(const std::array<double, kLogStates>& predicted,
                                               const std::array<double, kLogStates>& truth) {
  const ReportState p = report_state(predicted), t = report_state(truth);
  std::array<double, kReportVars> sq{};
  for (std::size_t v = 0; v < sq.size(); ++v) {
    const double d = v == 5 ? heli::wrap_angle(p[v] - t[v]) : p[v] - t[v];
    sq[v] = d * d;
  }
  return sq;
}

HorizonMse average(const std::vector<Errors>& per_start, std::size_t steps, double dt) {
  HorizonMse out;
  out.seconds.resize(steps + 1);
  out.mse.assign(steps + 1, {});
  out.count.assign(steps + 1, 0);
  for (std::size_t t = 0; t <= steps; ++t) out.seconds[t] = static_cast<double>(t) * dt;
  for (const Errors& e : per_start)
    for (std::size_t t = 0; t < e.size(); ++t) {
      for (int v = 0; v < kReportVars; ++v)
        out.mse[t][static_cast<std::size_t>(v)] += e[t][static_cast<std::size_t>(v)];
      ++out.count[t];
    }
  for (std::size_t t = 0; t <= steps; ++t)
    if (out.count[t] > 0)
      for (double& v : out.mse[t]) v /= out.count[t];
  return out;
}

}  // namespace

HorizonMse constant_velocity_mse(const FlightLog& test, double dt, double horizon_s, double start_spacing_s) {
  const std::size_t k = detail::rows_per_step(dt, test);
  const auto steps = static_cast<std::size_t>(std::lround(horizon_s / dt));
  const auto starts = prediction_starts(test, k, steps, start_spacing_s);
  std::vector<Errors> per_start(starts.size());
  for (std::size_t si = 0; si < starts.size(); ++si) {
    const auto& s0 = test.states[starts[si]];
    for (std::size_t t = 0; t <= steps; ++t) {
      auto predicted = s0;
      for (std::size_t i = 0; i < 3; ++i) predicted[i] = s0[i] + static_cast<double>(t) * dt * s0[6 + i];
      per_start[si].push_back(squared_errors(predicted, test.states[starts[si] + t * k]));
    }
  }
  return average(per_start, steps, dt);
}

HorizonMse horizon_mse(const IdentifiedModel& model, const FlightLog& test, double horizon_s,
                       double start_spacing_s, ThreadPool& pool) {
  const detail::LogAtRate lr = detail::log_at_rate(model, test);
  const auto k = lr.step;
  const auto steps = static_cast<std::size_t>(std::lround(horizon_s / model.dt()));
  const auto refit_every = static_cast<std::size_t>(refit_steps_at(1 / model.dt()));
  const std::vector<std::size_t> starts = prediction_starts(test, k, steps, start_spacing_s);
  std::vector<Errors> per_start(starts.size());
  pool.parallel_for(starts.size(), [&](std::size_t si) {
    const std::size_t r0 = starts[si];
    SimState s = detail::sim_state_at(test, lr, r0);
    Errors& e = per_start[si];
    e.reserve(steps + 1);
    LocalFit fit;
    for (std::size_t t = 0; t <= steps; ++t) {
      e.push_back(squared_errors(s.world, test.states[r0 + t * k]));
      if (t == steps) break;
      const auto a = detail::mean_controls(test, r0 + t * k, k);
      const InputVec x = sim_input(s, a);
      if (t % refit_every == 0) fit = model.regression().fit(x);
      if (fit.singular) break;
      s = sim_advance(model.structure(), s, a, model.mean_change(fit, x), model.dt());
    }
  });
  return average(per_start, steps, model.dt());
}

HorizonMse horizon_mse_as_trained(const IdentifiedModel& model, const FlightLog& test, double control_rate_hz,
                                  double horizon_s, double start_spacing_s, ThreadPool& pool) {
  // Log rows per comparison and control steps per comparison: (k, 1) when the log is faster, (1, q) when the
  // controller is.
  std::size_t rows = log_rows_per_model_step(test.dt(), control_rate_hz), per_row = 1;
  if (rows == 0) {
    per_row = log_rows_per_model_step(1 / control_rate_hz, 1 / test.dt());
    if (per_row == 0)
      throw InputError(
          fmt::format("control rate {} Hz: neither it nor the test log's {} Hz is a multiple of the "
                      "other",
                      control_rate_hz, 1 / test.dt()));
    rows = 1;
  }
  const double compare_dt = static_cast<double>(per_row) / control_rate_hz;
  const auto compares = static_cast<std::size_t>(std::lround(horizon_s / compare_dt));
  const std::vector<std::size_t> starts = prediction_starts(test, rows, compares, start_spacing_s);
  // A view of the caller's model for the simulator (which shares ownership of the models it is given).
  const std::shared_ptr<const IdentifiedModel> view(std::shared_ptr<const IdentifiedModel>(), &model);
  std::vector<Errors> per_start(starts.size());
  pool.parallel_for(starts.size(), [&](std::size_t si) {
    const std::size_t r0 = starts[si];
    LearnedModelOptions lo;
    lo.dt = 1 / control_rate_hz;
    lo.refit_every = refit_steps_at(control_rate_hz);  // as hover training refits it
    lo.noise = false;
    lo.start = test.states[r0];
    const LearnedHeliModel sim(view, lo);
    std::vector<double> p0(static_cast<std::size_t>(sim.initial_noise_dim()), 0.5);
    std::vector<double> p(static_cast<std::size_t>(sim.noise_dim()), 0.5);
    LearnedHeliModel::State s = sim.initial_state(p0);
    Errors& e = per_start[si];
    e.reserve(compares + 1);
    for (std::size_t c = 0; c <= compares; ++c) {
      e.push_back(squared_errors(s.sim.world, test.states[r0 + c * rows]));
      if (c == compares) break;
      const auto a = detail::mean_controls(test, r0 + c * rows, rows);
      for (std::size_t j = 0; j < per_row && !s.crashed; ++j) s = sim.step(s, a, p);
      if (s.crashed) break;
    }
  });
  return average(per_start, compares, compare_dt);
}

}  // namespace pegasus::sysid
