// Fig 5.3's noise check (thesis §5.2): an extended Kalman filter along a log with the model's noise, its
// bands of +-2 sd against the logged states, and the band terms of each noise source that the calibration
// scales (identify.hpp: NoiseCheck, NoiseBandTerms).
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "log_at_rate.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::sysid {

using heli::Euler;
using heli::Vec3;

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

// The filter's states: the EKF's, then the AR parts and the logged errors when the model has them.
//
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
struct FilterLayout {
  bool ar = false, measured = false;
  int c0 = kEkfStates, m0 = kEkfStates;  // where the AR parts and the logged errors start
  int states = kEkfStates;
};

FilterLayout filter_layout(const NoiseCorrelation& nc) {
  FilterLayout l;
  l.ar = (nc.share.array() > 0).any();
  l.measured = nc.has_measurement();
  l.c0 = kEkfStates;
  l.m0 = kEkfStates + (l.ar ? kBodyVars : 0);
  l.states = l.m0 + (l.measured ? kBodyVars : 0);
  return l;
}

// The EKF state at the simulation's state s with regression input x.
EkfVec ekf_state(const InputVec& x, const SimState& s) {
  EkfVec z;
  z.head<kBodyVars>() = x.head<kBodyVars>();
  z[kFlapLon] = s.flap_lon;
  z[kFlapLat] = s.flap_lat;
  z[kGyro] = s.gyro;
  return z;
}

// The Jacobian of the mean step at z, by central differences.
EkfMat mean_step_jacobian(const IdentifiedModel& model, const EkfVec& z, const std::array<double, 4>& a,
                          const LocalFit& fit) {
  EkfMat jac;
  for (int j = 0; j < kEkfStates; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(z[j]));
    EkfVec zp = z, zm = z;
    zp[j] += h;
    zm[j] -= h;
    jac.col(j) = (mean_step(model, zp, a, fit) - mean_step(model, zm, a, fit)) / (2 * h);
  }
  return jac;
}

// One window's covariances per set of noise scales, from the reset on. Full covariance of the EKF state,
// propagated P' = J P J' + Q with the model's noise Q diagonal (the outputs' noises are independent, Eqs
// 5.5-5.6) and J the Jacobian of the mean step. Propagating only the diagonal of P (dropping
// cross-covariances) would ignore that attitude errors integrate rate errors and velocity errors integrate
// attitude errors: it shrinks the bands of the integrated variables.
class WindowCovariances {
 public:
  WindowCovariances(const IdentifiedModel& model, const FilterLayout& layout,
                    const std::vector<NoiseScale>& scales)
      : model_(model),
        nc_(model.noise_correlation()),
        l_(layout),
        scales_(scales),
        p_(scales.size(), EkfMat::Zero()),
        pa_(scales.size()),
        white_logged_(scales.size(), BodyVec::Zero()) {
    if (l_.ar || l_.measured)
      for (std::size_t q = 0; q < scales_.size(); ++q) start_augmented(q);
  }

  // One step with the Jacobian jac and the one-step predictive variances var: each set's band variances of
  // the body variables (the logged values' with a logged error) into band_var.
  void propagate(const EkfMat& jac, const BodyVec& var, std::vector<BodyVec>& band_var) {
    for (std::size_t q = 0; q < scales_.size(); ++q) {
      if (!l_.ar && !l_.measured) {
        p_[q] = jac * p_[q] * jac.transpose();
        p_[q].diagonal().head<kBodyVars>() += (var.array() * scales_[q].process.array()).matrix();
        band_var[q] = p_[q].diagonal().head<kBodyVars>();
      } else {
        propagate_augmented_set(q, jac, var);
        band_var[q] = pa_[q].diagonal().head<kBodyVars>();
        if (l_.measured)
          for (int j = 0; j < kBodyVars; ++j)
            band_var[q][j] += pa_[q](l_.m0 + j, l_.m0 + j) + 2 * pa_[q](j, l_.m0 + j) + white_logged_[q][j];
      }
    }
  }

 private:
  // The augmented covariance at a reset: the AR parts at their stationary variance, the body's error the
  // logged error's negative.
  void start_augmented(std::size_t q) {
    const int c0 = l_.c0, m0 = l_.m0;
    pa_[q] = Eigen::MatrixXd::Zero(l_.states, l_.states);
    for (int j = 0; j < kBodyVars; ++j) {
      if (l_.ar) pa_[q](c0 + j, c0 + j) = nc_.share[j] * model_.sigma2()[j] * scales_[q].process[j];
      if (l_.measured) {
        const double vm = nc_.measurement_variance(j, model_.sigma2()[j]) * scales_[q].measurement[j];
        pa_[q](m0 + j, m0 + j) = pa_[q](j, j) = vm;
        pa_[q](j, m0 + j) = pa_[q](m0 + j, j) = -vm;
        white_logged_[q][j] =
            nc_.measurement_white_variance(j, model_.sigma2()[j]) * scales_[q].measurement[j] +
            scales_[q].measurement_white[j] * model_.sigma2()[j];
        pa_[q](j, j) += white_logged_[q][j];
      }
    }
  }

  void propagate_augmented_set(std::size_t q, const EkfMat& jac, const BodyVec& var) {
    const int c0 = l_.c0, m0 = l_.m0;
    Eigen::MatrixXd& pq = pa_[q];
    propagate_augmented(pq, scratch_, jac, nc_.rho, nc_.measurement_rho, c0, m0, l_.ar, l_.measured);
    for (int j = 0; j < kBodyVars; ++j) {
      const double share = nc_.share[j], process = scales_[q].process[j];
      double body = nc_.white_share(j) * var[j] * process;
      if (l_.ar) {
        const double rho = nc_.rho[j];
        const double eta = share * var[j] * (1 - rho * rho) * process;
        body += eta;
        pq(j, c0 + j) += eta;
        pq(c0 + j, j) += eta;
        pq(c0 + j, c0 + j) += eta;
      }
      pq(j, j) += body;
      if (l_.measured) {
        const double rho_m = nc_.measurement_rho[j];
        pq(m0 + j, m0 + j) +=
            nc_.measurement_variance(j, model_.sigma2()[j]) * (1 - rho_m * rho_m) * scales_[q].measurement[j];
      }
    }
  }

  const IdentifiedModel& model_;
  const NoiseCorrelation& nc_;
  FilterLayout l_;
  const std::vector<NoiseScale>& scales_;
  std::vector<EkfMat> p_;
  std::vector<Eigen::MatrixXd> pa_;    // the augmented filter's covariance (states x states)
  std::vector<BodyVec> white_logged_;  // sigma_w^2 of each set
  Eigen::MatrixXd scratch_;
};

// One step counted by the filter: t model steps after the reset at log row r0 (0-based), the logged and the
// predicted body variables, and the band variances of each set of scales.
struct FilterStep {
  std::size_t r0, t;
  BodyVec truth, mean;
  std::vector<BodyVec> bands;
};

// The data rows [begin, end) the window from r0 leaves out of its fits: with leave_out_s > 0 the log is the
// model's training log, and each window's fits leave out its training rows within leave_out_s / 2 of the
// window, as cross-validation leaves out a window around each point.
std::pair<Eigen::Index, Eigen::Index> window_left_out(const IdentifiedModel& model, const FlightLog& test,
                                                      std::size_t r0, std::size_t log_rows,
                                                      double leave_out_s) {
  if (!(leave_out_s > 0)) return {0, 0};
  const std::vector<double>& times = model.data().time;
  const double first = test.time[r0], last = test.time[std::min(test.rows() - 1, r0 + log_rows)];
  return {std::lower_bound(times.begin(), times.end(), first - leave_out_s / 2) - times.begin(),
          std::upper_bound(times.begin(), times.end(), last + leave_out_s / 2) - times.begin()};
}

// The window of at most seg model steps from the reset at log row r0.
std::vector<FilterStep> filter_window(const IdentifiedModel& model, const FlightLog& test,
                                      const detail::LogAtRate& lr, std::size_t r0, std::size_t seg,
                                      double leave_out_s, const FilterLayout& layout,
                                      const std::vector<NoiseScale>& scales) {
  const auto k = lr.step;
  std::vector<FilterStep> steps;
  std::vector<BodyVec> band_var(scales.size());
  SimState s = detail::sim_state_at(test, lr, r0);
  const auto [leave_begin, leave_end] = window_left_out(model, test, r0, seg * k, leave_out_s);
  WindowCovariances covariances(model, layout, scales);
  for (std::size_t t = 0; t < seg && r0 + (t + 1) * k < test.rows(); ++t) {
    const auto a = detail::mean_controls(test, r0 + t * k, k);
    const InputVec x = sim_input(s, a);
    const LocalFit fit = model.regression().fit(x, leave_begin, leave_end);
    if (fit.singular) break;
    const BodyVec var = model.predictive_variance(fit);
    covariances.propagate(mean_step_jacobian(model, ekf_state(x, s), a, fit), var, band_var);
    s = sim_advance(model.structure(), s, a, model.mean_change(fit, x), model.dt());
    steps.push_back(
        {r0, t, body_from_log_state(test.states[r0 + (t + 1) * k]), body_from_log_state(s.world), band_var});
  }
  return steps;
}

// Fig 5.3's filter over the log, reset every reset_s (or windows every start_spacing_s when > 0): each
// window's steps, in order. The windows are independent: they are filtered in parallel and returned in
// order, so that a visitor sees the same steps in the same order for any number of threads.
std::vector<std::vector<FilterStep>> filter_windows(const IdentifiedModel& model, const FlightLog& test,
                                                    double reset_s, double leave_out_s,
                                                    double start_spacing_s,
                                                    const std::vector<NoiseScale>& scales, ThreadPool& pool) {
  const detail::LogAtRate lr = detail::log_at_rate(model, test);
  const auto k = lr.step;
  const auto seg = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(reset_s / model.dt())));
  const FilterLayout layout = filter_layout(model.noise_correlation());
  std::vector<std::size_t> starts;
  const std::size_t stride =
      start_spacing_s > 0
          ? std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(start_spacing_s / model.dt())))
          : seg;
  for (std::size_t r0 = 0; r0 + k < test.rows(); r0 += stride * k) starts.push_back(r0);
  std::vector<std::vector<FilterStep>> windows(starts.size());
  pool.parallel_for(starts.size(), [&](std::size_t w) {
    windows[w] = filter_window(model, test, lr, starts[w], seg, leave_out_s, layout, scales);
  });
  return windows;
}

// Calls visit(r0, t, truth, mean, band variances of each set) after every step the filter counts.
template <typename Visit>
void run_noise_filter(const IdentifiedModel& model, const FlightLog& test, double reset_s, double leave_out_s,
                      double start_spacing_s, const std::vector<NoiseScale>& scales, ThreadPool& pool,
                      Visit&& visit) {
  for (const auto& window : filter_windows(model, test, reset_s, leave_out_s, start_spacing_s, scales, pool))
    for (const FilterStep& step : window) visit(step.r0, step.t, step.truth, step.mean, step.bands);
}

}  // namespace

NoiseCheck noise_check(const IdentifiedModel& model, const FlightLog& test, double reset_s,
                       double trace_seconds, ThreadPool& pool) {
  const auto seg = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(reset_s / model.dt())));
  const std::size_t k = detail::log_at_rate(model, test).step;
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
