// What an identified model predicts on a hold-out log (thesis §5.2): the open-loop simulation of the model at
// its own rate, Fig 5.2's errors against horizon (also as hover training runs the model, and the constant-
// velocity baseline), and Fig 5.3's noise check with an extended Kalman filter.
#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::sysid {

namespace logged = heli::logged;

using heli::Euler;
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

struct LogAtRate {
  std::size_t step;  // log rows per model step
  std::vector<std::array<double, 3>> extra;
};

// Log rows per model step of dt; InputError unless the log's rate is a multiple of the model's.
std::size_t rows_per_step(double dt, const FlightLog& log) {
  const std::size_t k = log_rows_per_model_step(log.dt(), 1 / dt);
  if (k == 0)
    throw InputError(fmt::format("the test log's rate {} Hz is not a multiple of the model rate {} Hz",
                                 1 / log.dt(), 1 / dt));
  return k;
}

LogAtRate log_at_rate(const IdentifiedModel& model, const FlightLog& log) {
  return {rows_per_step(model.dt(), log), extra_states_along(log, model.structure())};
}

// The simulation's state at log row r: the logged state and the extra states along the log.
SimState sim_state_at(const FlightLog& log, const LogAtRate& lr, std::size_t r) {
  SimState s;
  s.world = log.states[r];
  const auto& [flap_lon, flap_lat, gyro] = lr.extra[r];
  s.flap_lon = flap_lon;
  s.flap_lat = flap_lat;
  s.gyro = gyro;
  return s;
}

std::array<double, 4> mean_controls(const FlightLog& log, std::size_t row, std::size_t k) {
  std::array<double, 4> a{};
  for (std::size_t j = row; j < row + k; ++j)
    for (std::size_t c = 0; c < 4; ++c) a[c] += log.controls[j][c];
  for (double& v : a) v /= static_cast<double>(k);
  return a;
}

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
  const std::size_t k = rows_per_step(dt, test);
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
  const LogAtRate lr = log_at_rate(model, test);
  const auto k = lr.step;
  const auto steps = static_cast<std::size_t>(std::lround(horizon_s / model.dt()));
  const auto refit_every = static_cast<std::size_t>(refit_steps_at(1 / model.dt()));
  const std::vector<std::size_t> starts = prediction_starts(test, k, steps, start_spacing_s);
  std::vector<Errors> per_start(starts.size());
  pool.parallel_for(starts.size(), [&](std::size_t si) {
    const std::size_t r0 = starts[si];
    SimState s = sim_state_at(test, lr, r0);
    Errors& e = per_start[si];
    e.reserve(steps + 1);
    LocalFit fit;
    for (std::size_t t = 0; t <= steps; ++t) {
      e.push_back(squared_errors(s.world, test.states[r0 + t * k]));
      if (t == steps) break;
      const auto a = mean_controls(test, r0 + t * k, k);
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
      const auto a = mean_controls(test, r0 + c * rows, rows);
      for (std::size_t j = 0; j < per_row && !s.crashed; ++j) s = sim.step(s, a, p);
      if (s.crashed) break;
    }
  });
  return average(per_start, compares, compare_dt);
}

namespace {

// The EKF's state: the 8 body variables and the 3 extra states (which the body rates drive, and which drive
// the velocities and rates through the regression), at their places in the regression input.
static_assert(kFlapLon == kBodyVars && kFlapLat == kBodyVars + 1 && kGyro == kBodyVars + 2);
constexpr int kEkfStates = kGyro + 1;
using EkfVec = Eigen::Matrix<double, kEkfStates, 1>;
using EkfMat = Eigen::Matrix<double, kEkfStates, kEkfStates>;

// The model's mean one-step map on the EKF state with the controls and the local fit held.
EkfVec mean_step(const IdentifiedModel& model, const EkfVec& z, const std::array<double, 4>& a,
                 const LocalFit& fit) {
  InputVec x;
  x.head<kBodyVars>() = z.head<kBodyVars>();
  x[kFlapLon] = z[kFlapLon];
  x[kFlapLat] = z[kFlapLat];
  x[kGyro] = z[kGyro];
  for (int c = 0; c < 4; ++c) x[kA1 + c] = a[static_cast<std::size_t>(c)];
  x[kOne] = 1;
  EkfVec out;
  out.head<kBodyVars>() = z.head<kBodyVars>() + model.mean_change(fit, x);
  double fl = z[kFlapLon], fr = z[kFlapLat], gy = z[kGyro];
  const Vec3 w_B = heli::body_rates_from_euler_rates(Euler{z[kRoll], z[kPitch], 0},
                                                     Vec3(z[kRollRate], z[kPitchRate], z[kYawRate]));
  model.structure().extra.advance(model.dt(), w_B, a, &fl, &fr, &gy);
  out[kFlapLon] = fl;
  out[kFlapLat] = fr;
  out[kGyro] = gy;
  return out;
}

}  // namespace

namespace {

// pa = ja pa ja' for the augmented filter's Jacobian ja = [[jac, R, 0], [0, R, 0], [0, 0, Rm]] (R = diag(rho)
// from the AR parts c into the body variables and into c itself, Rm = diag(rho_m) on the logged errors m),
// without forming ja: most of it is zeros, and the calibration runs this once per noise source at every step
// of windows that overlap.
void propagate_augmented(Eigen::MatrixXd& pa, Eigen::MatrixXd& scratch, const EkfMat& jac, const BodyVec& rho,
                         const BodyVec& rho_m, int c0, int m0, bool ar, bool measured) {
  scratch.resize(pa.rows(), pa.cols());
  scratch.topRows<kEkfStates>().noalias() = jac * pa.topRows<kEkfStates>();
  for (int j = 0; j < kBodyVars; ++j) {
    if (ar) {
      scratch.row(j) += rho[j] * pa.row(c0 + j);
      scratch.row(c0 + j) = rho[j] * pa.row(c0 + j);
    }
    if (measured) scratch.row(m0 + j) = rho_m[j] * pa.row(m0 + j);
  }
  pa.leftCols<kEkfStates>().noalias() = scratch.leftCols<kEkfStates>() * jac.transpose();
  for (int j = 0; j < kBodyVars; ++j) {
    if (ar) {
      pa.col(j) += rho[j] * scratch.col(c0 + j);
      pa.col(c0 + j) = rho[j] * scratch.col(c0 + j);
    }
    if (measured) pa.col(m0 + j) = rho_m[j] * scratch.col(m0 + j);
  }
}

// Runs Fig 5.3's filter over the log once per set of noise scales and calls
// visit(r0, t, truth, mean, band variances of each set) after every step counted (t: model steps since the
// reset at log row r0, 0-based). The mean trajectory, its local fits and Jacobians do not depend on the
// noise, so the sets share them; the covariances are propagated per set. With leave_out_s > 0 the log is the
// model's training log and each window's fits leave out its training rows within leave_out_s / 2 of the
// window, as cross-validation leaves out a window around each point.
template <typename Visit>
void run_noise_filter(const IdentifiedModel& model, const FlightLog& test, double reset_s, double leave_out_s,
                      double start_spacing_s, const std::vector<NoiseScale>& scales, ThreadPool& pool,
                      Visit&& visit) {
  const LogAtRate lr = log_at_rate(model, test);
  const auto k = lr.step;
  const auto seg = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(reset_s / model.dt())));
  const ModelStructure& m = model.structure();
  // With AR(1) noise the filter carries each output's AR part c as 8 more states (mean 0: nothing observes
  // them between resets): body' = mean step + c' + w, c' = rho c + eta. At a reset c is unknown and starts at
  // its stationary variance share * sigma^2, so the first step's band is the white model's.
  // With the logged states' own error m (NoiseModel::kAr1Measurement) it carries m as 8 more states,
  // m' = rho_m m + nu: the log shows body + m, and at a reset the filter's body is the logged value, so its
  // error is -m_0 (covariance -sigma_m^2 with m). The band is that of body + m: zero at the reset itself.
  // A white logged error w needs no states: the body's error at a reset is also -w_0 (variance sigma_w^2,
  // independent of all else), and each later logged value adds its own w_t to the band.
  // A set's process scale multiplies the white and AR parts' variances, its measurement scale the logged
  // error's (both parts), and its measurement_white adds a white logged error (NoiseScale).
  const NoiseCorrelation& nc_model = model.noise_correlation();
  const bool ar = (nc_model.share.array() > 0).any();
  const bool measured = nc_model.has_measurement();
  const int c0 = kEkfStates, m0 = kEkfStates + (ar ? kBodyVars : 0);
  const int states = m0 + (measured ? kBodyVars : 0);
  const std::size_t sets = scales.size();
  // The windows are independent: they are filtered in parallel and visited in order, so that the visitor sees
  // the same steps in the same order for any number of threads.
  struct Step {
    std::size_t r0, t;
    BodyVec truth, mean;
    std::vector<BodyVec> bands;
  };
  std::vector<std::size_t> starts;
  const std::size_t stride =
      start_spacing_s > 0
          ? std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(start_spacing_s / model.dt())))
          : seg;
  for (std::size_t r0 = 0; r0 + k < test.rows(); r0 += stride * k) starts.push_back(r0);
  std::vector<std::vector<Step>> windows(starts.size());
  pool.parallel_for(starts.size(), [&](std::size_t w) {
    const std::size_t r0 = starts[w];
    std::vector<BodyVec> band_var(sets);
    SimState s = sim_state_at(test, lr, r0);
    Eigen::Index leave_begin = 0, leave_end = 0;
    if (leave_out_s > 0) {
      const std::vector<double>& times = model.data().time;
      const double first = test.time[r0], last = test.time[std::min(test.rows() - 1, r0 + seg * k)];
      leave_begin = std::lower_bound(times.begin(), times.end(), first - leave_out_s / 2) - times.begin();
      leave_end = std::upper_bound(times.begin(), times.end(), last + leave_out_s / 2) - times.begin();
    }
    // Full covariance of the EKF state, propagated P' = J P J' + Q with the model's noise Q diagonal (the
    // outputs' noises are independent, Eqs 5.5-5.6) and J the Jacobian of the mean step. Propagating only the
    // diagonal of P (dropping cross-covariances) would ignore that attitude errors integrate rate errors and
    // velocity errors integrate attitude errors: it shrinks the bands of the integrated variables.
    std::vector<EkfMat> p(sets, EkfMat::Zero());
    std::vector<Eigen::MatrixXd> pa(sets);  // the augmented filter's covariance (states x states)
    std::vector<BodyVec> white_logged(sets, BodyVec::Zero());  // sigma_w^2 of each set
    Eigen::MatrixXd scratch;
    if (ar || measured) {
      for (std::size_t q = 0; q < sets; ++q) {
        pa[q] = Eigen::MatrixXd::Zero(states, states);
        for (int j = 0; j < kBodyVars; ++j) {
          if (ar) pa[q](c0 + j, c0 + j) = nc_model.share[j] * model.sigma2()[j] * scales[q].process[j];
          if (measured) {
            const double vm = nc_model.measurement_variance(j, model.sigma2()[j]) * scales[q].measurement[j];
            pa[q](m0 + j, m0 + j) = pa[q](j, j) = vm;
            pa[q](j, m0 + j) = pa[q](m0 + j, j) = -vm;
            white_logged[q][j] =
                nc_model.measurement_white_variance(j, model.sigma2()[j]) * scales[q].measurement[j] +
                scales[q].measurement_white[j] * model.sigma2()[j];
            pa[q](j, j) += white_logged[q][j];
          }
        }
      }
    }
    for (std::size_t t = 0; t < seg && r0 + (t + 1) * k < test.rows(); ++t) {
      const auto a = mean_controls(test, r0 + t * k, k);
      const InputVec x = sim_input(s, a);
      const LocalFit fit = model.regression().fit(x, leave_begin, leave_end);
      if (fit.singular) break;
      const BodyVec var = model.predictive_variance(fit);
      EkfVec z;
      z.head<kBodyVars>() = x.head<kBodyVars>();
      z[kFlapLon] = s.flap_lon;
      z[kFlapLat] = s.flap_lat;
      z[kGyro] = s.gyro;
      EkfMat jac;
      for (int j = 0; j < kEkfStates; ++j) {
        const double h = 1e-6 * std::max(1.0, std::abs(z[j]));
        EkfVec zp = z, zm = z;
        zp[j] += h;
        zm[j] -= h;
        jac.col(j) = (mean_step(model, zp, a, fit) - mean_step(model, zm, a, fit)) / (2 * h);
      }
      if (!ar && !measured) {
        for (std::size_t q = 0; q < sets; ++q) {
          p[q] = jac * p[q] * jac.transpose();
          p[q].diagonal().head<kBodyVars>() += (var.array() * scales[q].process.array()).matrix();
          band_var[q] = p[q].diagonal().head<kBodyVars>();
        }
      } else {
        for (std::size_t q = 0; q < sets; ++q) {
          Eigen::MatrixXd& pq = pa[q];
          propagate_augmented(pq, scratch, jac, nc_model.rho, nc_model.measurement_rho, c0, m0, ar, measured);
          for (int j = 0; j < kBodyVars; ++j) {
            const double share = nc_model.share[j], process = scales[q].process[j];
            double body = nc_model.white_share(j) * var[j] * process;
            if (ar) {
              const double rho = nc_model.rho[j];
              const double eta = share * var[j] * (1 - rho * rho) * process;
              body += eta;
              pq(j, c0 + j) += eta;
              pq(c0 + j, j) += eta;
              pq(c0 + j, c0 + j) += eta;
            }
            pq(j, j) += body;
            if (measured) {
              const double rho_m = nc_model.measurement_rho[j];
              pq(m0 + j, m0 + j) += nc_model.measurement_variance(j, model.sigma2()[j]) *
                                    (1 - rho_m * rho_m) * scales[q].measurement[j];
            }
          }
          band_var[q] = pa[q].diagonal().head<kBodyVars>();
          if (measured)
            for (int j = 0; j < kBodyVars; ++j)
              band_var[q][j] += pa[q](m0 + j, m0 + j) + 2 * pa[q](j, m0 + j) + white_logged[q][j];
        }
      }
      s = sim_advance(m, s, a, model.mean_change(fit, x), model.dt());
      windows[w].push_back({r0, t, body_from_log_state(test.states[r0 + (t + 1) * k]),
                            body_from_log_state(s.world), band_var});
    }
  });
  for (const auto& window : windows)
    for (const Step& step : window) visit(step.r0, step.t, step.truth, step.mean, step.bands);
}

}  // namespace

NoiseCheck noise_check(const IdentifiedModel& model, const FlightLog& test, double reset_s,
                       double trace_seconds, ThreadPool& pool) {
  const auto seg = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(reset_s / model.dt())));
  const std::size_t k = log_at_rate(model, test).step;
  NoiseCheck out;
  out.outside_by_horizon.assign(seg, BodyVec::Zero());
  out.steps_by_horizon.assign(seg, 0);
  BodyVec outside = BodyVec::Zero();
  run_noise_filter(
      model, test, reset_s, 0.0, 0.0, {NoiseScale{}}, pool,
      [&](std::size_t r0, std::size_t t, const BodyVec& truth, const BodyVec& mean,
          const std::vector<BodyVec>& bands) {
        // The filter's band with the calibration's sd factor at this step after the reset.
        const BodyVec band_var = bands.front().cwiseProduct(model.horizon_sd_factor(t).cwiseAbs2());
        BodyVec normalized;
        for (int j = 0; j < kBodyVars; ++j)
          normalized[j] = band_var[j] > 0 ? std::abs(truth[j] - mean[j]) / std::sqrt(band_var[j]) : 0.0;
        out.normalized_errors.push_back(normalized);
        for (int j = 0; j < kBodyVars; ++j) {
          if (std::abs(truth[j] - mean[j]) > 2 * std::sqrt(band_var[j])) {
            outside[j] += 1;
            out.outside_by_horizon[t][j] += 1;
          }
        }
        ++out.steps;
        ++out.steps_by_horizon[t];
        const double time = test.time[r0 + (t + 1) * k] - test.time[0];
        if (time <= trace_seconds) {
          out.time.push_back(time);
          out.truth.push_back(truth[kV]);
          out.mean.push_back(mean[kV]);
          out.sd.push_back(std::sqrt(band_var[kV]));
        }
      });
  if (out.steps > 0) out.outside_fraction = outside / out.steps;
  for (std::size_t t = 0; t < seg; ++t)
    if (out.steps_by_horizon[t] > 0) out.outside_by_horizon[t] /= out.steps_by_horizon[t];
  return out;
}

NoiseCheck pooled_noise_check(const std::vector<NoiseCheck>& checks) {
  if (checks.empty()) throw std::invalid_argument("pooled_noise_check: no checks");
  NoiseCheck out = checks.front();  // its traces
  const std::size_t seg = out.steps_by_horizon.size();
  // Counts back from the fractions (each a count over the steps, so the rounding is exact).
  auto counts = [](const BodyVec& fraction, int steps) {
    return (fraction * steps).array().round().matrix().eval();
  };
  BodyVec outside = counts(out.outside_fraction, out.steps);
  std::vector<BodyVec> outside_by_horizon(seg);
  for (std::size_t t = 0; t < seg; ++t)
    outside_by_horizon[t] = counts(out.outside_by_horizon[t], out.steps_by_horizon[t]);
  for (std::size_t c = 1; c < checks.size(); ++c) {
    const NoiseCheck& more = checks[c];
    if (more.steps_by_horizon.size() != seg)
      throw std::invalid_argument("pooled_noise_check: the checks differ in their steps per reset");
    outside += counts(more.outside_fraction, more.steps);
    out.steps += more.steps;
    for (std::size_t t = 0; t < seg; ++t) {
      outside_by_horizon[t] += counts(more.outside_by_horizon[t], more.steps_by_horizon[t]);
      out.steps_by_horizon[t] += more.steps_by_horizon[t];
    }
    out.normalized_errors.insert(out.normalized_errors.end(), more.normalized_errors.begin(),
                                 more.normalized_errors.end());
  }
  out.outside_fraction = out.steps > 0 ? BodyVec(outside / out.steps) : BodyVec::Zero();
  for (std::size_t t = 0; t < seg; ++t)
    out.outside_by_horizon[t] = out.steps_by_horizon[t] > 0
                                    ? BodyVec(outside_by_horizon[t] / out.steps_by_horizon[t])
                                    : BodyVec::Zero();
  return out;
}

std::vector<BandMisses> band_misses(const NoiseCheck& check, double dt, const std::vector<double>& seconds) {
  std::vector<BandMisses> out;
  for (double s : seconds) {
    const long t = std::lround(s / dt) - 1;
    if (t < 0 || static_cast<std::size_t>(t) >= check.steps_by_horizon.size() ||
        check.steps_by_horizon[static_cast<std::size_t>(t)] == 0)
      continue;
    for (int k = 0; k < kBodyVars; ++k)
      out.push_back({k, s, check.outside_by_horizon[static_cast<std::size_t>(t)][k],
                     check.steps_by_horizon[static_cast<std::size_t>(t)]});
  }
  return out;
}

std::vector<BandMisses> band_misses_at_every_step(const NoiseCheck& check, double rate_hz) {
  std::vector<BandMisses> out;
  for (std::size_t t = 0; t < check.steps_by_horizon.size(); ++t)
    for (int k = 0; k < kBodyVars && check.steps_by_horizon[t] > 0; ++k)
      out.push_back({k, static_cast<double>(t + 1) / rate_hz, check.outside_by_horizon[t][k],
                     check.steps_by_horizon[t]});
  return out;
}

bool honest_misses(double outside) {
  // A relative tolerance, so that a count exactly at a limit is inside however its quotient rounds.
  return outside >= kHonestMissLow * (1 - 1e-9) && outside <= kHonestMissHigh * (1 + 1e-9);
}

bool misses_consistent_with_honest(int outside, int steps, double alpha) {
  if (steps <= 0) return true;  // nothing counted: no evidence either way
  using boost::math::binomial_distribution;
  const auto trials = static_cast<double>(steps), successes = static_cast<double>(outside);
  const double lower =
      outside == 0 ? 0.0 : binomial_distribution<>::find_lower_bound_on_p(trials, successes, alpha / 2);
  const double upper =
      outside == steps ? 1.0 : binomial_distribution<>::find_upper_bound_on_p(trials, successes, alpha / 2);
  return upper >= kHonestMissLow && lower <= kHonestMissHigh;
}

std::vector<BandMisses> cells_beyond_chance(const std::vector<BandMisses>& cells) {
  std::vector<BandMisses> out;
  const double alpha = kNoiseCheckAlpha / static_cast<double>(std::max<std::size_t>(cells.size(), 1));
  for (const BandMisses& m : cells) {
    const auto outside = static_cast<int>(std::lround(m.outside * m.steps));
    if (!misses_consistent_with_honest(outside, m.steps, alpha)) out.push_back(m);
  }
  return out;
}

NoiseBandTerms noise_band_terms(const IdentifiedModel& model, const FlightLog& test, double reset_s,
                                double leave_out_s, ThreadPool& pool, double start_spacing_s) {
  NoiseBandTerms out;
  const bool measured = model.noise_correlation().has_measurement();
  std::vector<NoiseScale> unit;
  for (int j = 0; j < kBodyVars; ++j) {
    NoiseScale process{.process = BodyVec::Zero(), .measurement = BodyVec::Zero()};
    process.process[j] = 1;
    unit.push_back(process);
  }
  if (measured) {
    for (int j = 0; j < kBodyVars; ++j) {
      NoiseScale measurement{.process = BodyVec::Zero(), .measurement = BodyVec::Zero()};
      measurement.measurement[j] = 1;
      unit.push_back(measurement);
    }
    // A white logged error of sigma2 each, which the calibration may add (NoiseScale::measurement_white).
    for (int j = 0; j < kBodyVars; ++j) {
      NoiseScale white{.process = BodyVec::Zero(), .measurement = BodyVec::Zero()};
      white.measurement_white[j] = 1;
      unit.push_back(white);
    }
  }
  out.sources = static_cast<int>(unit.size());
  run_noise_filter(model, test, reset_s, leave_out_s, start_spacing_s, unit, pool,
                   [&](std::size_t, std::size_t t, const BodyVec& truth, const BodyVec& mean,
                       const std::vector<BodyVec>& bands) {
                     out.horizon.push_back(static_cast<int>(t));
                     out.error.push_back((truth - mean).cwiseAbs());
                     Eigen::Matrix<double, kBodyVars, Eigen::Dynamic> b(kBodyVars, out.sources);
                     for (int q = 0; q < out.sources; ++q) b.col(q) = bands[static_cast<std::size_t>(q)];
                     out.band.push_back(std::move(b));
                   });
  return out;
}

}  // namespace pegasus::sysid
