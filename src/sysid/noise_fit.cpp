// The noise's correlation in time (identify.hpp: NoiseModel): the residuals' autocorrelation, the AR(1) and
// logged-error fits to it, and the closed-loop bias check that whitens with them.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "identify_windows.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid {

std::vector<BodyVec> residual_autocorrelation(const Dataset& data,
                                              const std::array<OutputTemplate, kBodyVars>& templates,
                                              const std::array<double, kInputs>& inv_bandwidth,
                                              double window_s, int max_lag, ThreadPool& pool) {
  const LocalRegression lwr(&data, templates, inv_bandwidth);
  const Eigen::Index n = data.rows();
  std::vector<BodyVec> residual(static_cast<std::size_t>(n), BodyVec::Zero());
  std::vector<char> usable(static_cast<std::size_t>(n), 0);
  pool.parallel_for(static_cast<std::size_t>(n), [&](std::size_t row) {
    const auto i = static_cast<Eigen::Index>(row);
    const auto [lo, hi] = detail::window_rows(data, i, window_s);
    const InputVec x = data.x.row(i).transpose();
    const LocalFit fit = lwr.fit(x, lo, hi);
    if (fit.singular) return;
    for (int k = 0; k < kBodyVars; ++k) residual[row][k] = data.y(i, k) - fit.predict(k, x);
    usable[row] = 1;
  });
  // Sums in row order: the same bits for any number of threads.
  std::vector<BodyVec> out;
  for (int lag = 1; lag <= max_lag; ++lag) {
    BodyVec cross = BodyVec::Zero(), first = BodyVec::Zero(), second = BodyVec::Zero();
    for (Eigen::Index i = 0; i + lag < n; ++i) {
      const auto a = static_cast<std::size_t>(i), b = static_cast<std::size_t>(i + lag);
      // Only rows exactly `lag` model steps apart (logs may be joined from several flights).
      if (!usable[a] || !usable[b] || std::abs(data.time[b] - data.time[a] - lag * data.dt) > 0.01 * data.dt)
        continue;
      cross += residual[a].cwiseProduct(residual[b]);
      first += residual[a].cwiseAbs2();
      second += residual[b].cwiseAbs2();
    }
    BodyVec r = BodyVec::Zero();
    for (int k = 0; k < kBodyVars; ++k)
      if (first[k] > 0 && second[k] > 0) r[k] = cross[k] / std::sqrt(first[k] * second[k]);
    out.push_back(r);
  }
  return out;
}

namespace {

// The measurement fit of one output: least squares of f rho^lag + mu m(lag) against the autocorrelations y,
// m(lag) = rho_m^(lag-1) (rho_m (1 + phi^2) - phi (1 + rho_m^2)) / (1 + phi^2 - 2 phi rho_m), over a grid of
// (rho, rho_m) in [0, 0.99] by 0.01, (f, mu) in closed form on the triangle f, mu >= 0, f + mu <= 1 (the
// interior optimum or, when it lies outside, the best of each edge's). A tiny cost on f + mu (1e-12 of y'y)
// settles the ties of equal fits (where rho_m's term is rho's, or a share is 0) for the smaller shares.
void fit_with_measurement(const std::vector<double>& y, double phi, int k, NoiseCorrelation& c) {
  const std::size_t lags = y.size();
  std::vector<double> a(lags), b(lags);
  double best = std::numeric_limits<double>::infinity();
  double yy = 0;
  for (const double v : y) yy += v * v;
  const double tie_cost = 1e-12 * yy;
  for (int gr = 0; gr < 100; ++gr) {
    const double rho = gr / 100.0;
    double power = 1;
    for (std::size_t l = 0; l < lags; ++l) a[l] = (power *= rho);
    for (int gm = 0; gm < 100; ++gm) {
      const double rho_m = gm / 100.0;
      const double lag1 =
          (rho_m * (1 + phi * phi) - phi * (1 + rho_m * rho_m)) / (1 + phi * phi - 2 * phi * rho_m);
      power = 1;
      for (std::size_t l = 0; l < lags; ++l) {
        b[l] = lag1 * power;
        power *= rho_m;
      }
      double aa = 0, bb = 0, ab = 0, ay = -tie_cost / 2, by = -tie_cost / 2;
      for (std::size_t l = 0; l < lags; ++l) {
        aa += a[l] * a[l];
        bb += b[l] * b[l];
        ab += a[l] * b[l];
        ay += a[l] * y[l];
        by += b[l] * y[l];
      }
      // Summed from the residuals, not expanded from the sums above: the expansion can come out below 0 by
      // rounding where the two terms are nearly collinear, and would win every tie.
      const auto error = [&](double f, double mu) {
        double e = tie_cost * (f + mu);
        for (std::size_t l = 0; l < lags; ++l) {
          const double r = y[l] - f * a[l] - mu * b[l];
          e += r * r;
        }
        return e;
      };
      const auto consider = [&](double f, double mu) {
        // A share within rounding of 0 is 0, so that its correlation is 0 too rather than any grid value.
        if (f < 1e-9) f = 0;
        if (mu < 1e-9) mu = 0;
        const double e = error(f, mu);
        if (e < best) {
          best = e;
          c.share[k] = f;
          c.rho[k] = f > 0 ? rho : 0;
          c.measurement_share[k] = mu;
          c.measurement_rho[k] = mu > 0 ? rho_m : 0;
          c.measurement_persistence[k] = phi;
        }
      };
      const double det = aa * bb - ab * ab;
      if (det > 1e-12 * aa * bb) {
        const double f = (ay * bb - by * ab) / det, mu = (by * aa - ay * ab) / det;
        if (f >= 0 && mu >= 0 && f + mu <= 1) {
          consider(f, mu);
          continue;
        }
      }
      consider(aa > 0 ? std::clamp(ay / aa, 0.0, 1.0) : 0.0, 0.0);  // mu = 0
      if (bb > 0) consider(0.0, std::clamp(by / bb, 0.0, 1.0));     // f = 0
      // f + mu = 1: f = t, mu = 1 - t.
      const double dd = aa - 2 * ab + bb, dy = (ay - by) - (ab - bb);
      if (dd > 0) {
        const double t = std::clamp(dy / dd, 0.0, 1.0);
        consider(t, 1 - t);
      }
    }
  }
}

}  // namespace

NoiseCorrelation fit_noise_correlation_with_measurement(const std::vector<BodyVec>& autocorrelation,
                                                        const BodyVec& persistence) {
  NoiseCorrelation c;
  for (int k = 0; k < kBodyVars; ++k) {
    std::vector<double> y;
    for (const auto& a : autocorrelation) y.push_back(a[k]);
    fit_with_measurement(y, std::clamp(persistence[k], 0.0, 1.0), k, c);
  }
  return c;
}

NoiseCorrelation fit_noise_correlation(const std::vector<BodyVec>& autocorrelation) {
  NoiseCorrelation c;
  // Least squares of f rho^lag against the autocorrelations over a grid of rho, f in closed form and clipped
  // to [0, 1]: robust to the noisy long lags, and deterministic.
  for (int k = 0; k < kBodyVars; ++k) {
    double best = INFINITY;
    for (int g = 1; g < 1000; ++g) {
      const double rho = g / 1000.0;
      double num = 0, den = 0, power = 1;
      for (const auto& a : autocorrelation) {
        power *= rho;
        num += a[k] * power;
        den += power * power;
      }
      const double share = std::clamp(num / den, 0.0, 1.0);
      double err = 0;
      power = 1;
      for (const auto& a : autocorrelation) {
        power *= rho;
        err += (a[k] - share * power) * (a[k] - share * power);
      }
      if (err < best) {
        best = err;
        c.share[k] = share;
        c.rho[k] = share > 0 ? rho : 0;
      }
    }
  }
  return c;
}

NoiseCorrelation estimate_noise_correlation(const Dataset& data,
                                            const std::array<OutputTemplate, kBodyVars>& templates,
                                            const std::array<double, kInputs>& inv_bandwidth, double window_s,
                                            ThreadPool& pool, bool measurement) {
  const int max_lag = std::max(2, static_cast<int>(std::lround(2.0 / data.dt)));
  const std::vector<BodyVec> autocorrelation =
      residual_autocorrelation(data, templates, inv_bandwidth, window_s, max_lag, pool);
  if (!measurement) return fit_noise_correlation(autocorrelation);
  // Each output's persistence over a model step: 1 + its own coefficient in the global linear fit.
  const LocalRegression global(&data, templates, std::array<double, kInputs>{});
  const LocalFit fit = global.fit(data.x.row(0).transpose());
  BodyVec persistence = BodyVec::Ones();
  if (!fit.singular)
    for (int k = 0; k < kBodyVars; ++k) persistence[k] = 1 + fit.beta[static_cast<std::size_t>(k)][k];
  return fit_noise_correlation_with_measurement(autocorrelation, persistence);
}

std::vector<ControlGainBias> closed_loop_bias(const Dataset& data,
                                              const std::array<OutputTemplate, kBodyVars>& templates,
                                              const NoiseCorrelation& correlation) {
  const std::array<double, kInputs> global{};
  const LocalRegression plain(&data, templates, global);
  const InputVec any = data.x.row(0).transpose();
  const LocalFit ls = plain.fit(any);
  std::vector<ControlGainBias> out;
  if (ls.singular) return out;
  const Eigen::Index n = data.rows();
  for (int k = 0; k < kBodyVars; ++k) {
    const double f = correlation.share[k], rho = correlation.rho[k];
    if (!(f > 0 && rho > 0)) continue;
    // e_t - rho e_{t-1} is MA(1), u_t + theta u_{t-1}: its lag-1 autocorrelation fixes the invertible theta.
    const double var = (1 - f) * (1 + rho * rho) + f * (1 - rho * rho), cov = -rho * (1 - f);
    const double r1 = cov / var;  // in (-1/2, 0]
    const double theta = r1 == 0 ? 0.0 : (1 - std::sqrt(std::max(0.0, 1 - 4 * r1 * r1))) / (2 * r1);
    // The whitening filter u_t = (e_t - rho e_{t-1}) - theta u_{t-1} on every column, restarted where the
    // rows are not one model step apart.
    Dataset w = data;
    for (Eigen::Index i = 0; i < n; ++i) {
      const bool follows =
          i > 0 && std::abs(data.time[static_cast<std::size_t>(i)] -
                            data.time[static_cast<std::size_t>(i - 1)] - data.dt) <= 0.01 * data.dt;
      if (!follows) continue;
      w.x.row(i) = data.x.row(i) - rho * data.x.row(i - 1) - theta * w.x.row(i - 1);
      w.y.row(i) = data.y.row(i) - rho * data.y.row(i - 1) - theta * w.y.row(i - 1);
    }
    const LocalRegression whitened(&w, templates, global);
    const LocalFit gls = whitened.fit(any);
    if (gls.singular) continue;
    const double y_sd = std::sqrt((data.y.col(k).array() - data.y.col(k).mean()).square().mean());
    // Each free control's effect, |whitened gain| x its spread: the largest is the output's own control.
    std::array<double, kInputs> effect{};
    double largest = 0;
    for (int c = kA1; c <= kA4; ++c) {
      if (!templates[static_cast<std::size_t>(k)].free[static_cast<std::size_t>(c)]) continue;
      const double x_sd = std::sqrt((data.x.col(c).array() - data.x.col(c).mean()).square().mean());
      effect[static_cast<std::size_t>(c)] = std::abs(gls.beta[static_cast<std::size_t>(k)][c]) * x_sd;
      largest = std::max(largest, effect[static_cast<std::size_t>(c)]);
    }
    for (int c = kA1; c <= kA4; ++c) {
      if (!templates[static_cast<std::size_t>(k)].free[static_cast<std::size_t>(c)]) continue;
      const double b_ls = ls.beta[static_cast<std::size_t>(k)][c],
                   b_w = gls.beta[static_cast<std::size_t>(k)][c];
      const double e = effect[static_cast<std::size_t>(c)];
      if (!(e >= 0.1 * y_sd) || b_w == 0) continue;
      out.push_back({kBodyVarNames[static_cast<std::size_t>(k)], kInputNames[static_cast<std::size_t>(c)],
                     b_ls, b_w, b_ls / b_w - 1, e / largest});
    }
  }
  return out;
}

const ControlGainBias* largest_large_gain_bias(const std::vector<ControlGainBias>& biases) {
  const ControlGainBias* worst = nullptr;
  for (const auto& b : biases)
    if (b.effect_share >= kLargeGainShare && (!worst || std::abs(b.relative) > std::abs(worst->relative)))
      worst = &b;
  return worst;
}

namespace {

constexpr double kCoverage = 0.9545;  // of a Gaussian within +-2 sd
// The rank (0-based) of the kCoverage percentile among n values.
std::size_t coverage_rank(std::size_t n) {
  return static_cast<std::size_t>(std::ceil(kCoverage * static_cast<double>(n))) - 1;
}

}  // namespace

Eigen::VectorXd NoiseBandTerms::scales(const NoiseScale& scale) const {
  Eigen::VectorXd out(sources);
  for (int q = 0; q < sources; ++q) {
    const int k = q % kBodyVars;
    out[q] = q < kBodyVars       ? scale.process[k]
             : q < 2 * kBodyVars ? scale.measurement[k]
                                 : scale.measurement_white[k];
  }
  return out;
}

namespace {

constexpr double kLogScaleLimit = 4.605170185988091;  // log(100)
// A source scaled x2 costs what one cell's percentile 4% off does. Without it the scales the errors hardly
// constrain drifted to the bounds (the Crazyflie's pitch process noise x16 beside roll's x0.03); with it
// they stay near 1, and the hold-out cells within 3-7% moved by at most 2 of 24 (README, Calibrated noise).
// Chosen against three spans' 24 terms; against every step's 160 it weighs less, and scaling it with them
// (0.02) left more hold-out cells outside (611 against 553, README, The fit at every step).
constexpr double kLogScalePenalty = 0.003;
// The scales of the model's own sources start at 1 and are kept near it; the white logged errors the terms
// may add start at none (their lower bound) and are free. Over the seven training flights of README's The
// fit at every step, the X-Cell left 324 hold-out cells outside 3-7% with them, 410 without (README, A
// white logged error).
constexpr double kLogScaleOff = 2 * -kLogScaleLimit;  // 1e-4: read as none
// Each step size of the coordinate search is tried until no move improves, or for at most this many passes
// over the sources: with the white logged errors the finest steps crept along the valleys where two sources
// trade off (185 of the fit's 290 passes, at x2^(1/16), in BM_IdentifyTenMinutes).
constexpr int kScalePassesPerStep = 20;

// The terms' steps ordered by horizon, and each variable's bands by source as one column-major matrix over
// them, so that a horizon's bands under any scales are one contiguous matrix-vector product.
struct HorizonOrderedTerms {
  int steps = 0, sources = 0;
  std::vector<Eigen::Index> first;  // the first row of each horizon, then the number of rows
  std::array<Eigen::MatrixXd, kBodyVars> band;
  std::array<Eigen::VectorXd, kBodyVars> error;  // squared: percentiles of error^2 / band need no root
  Eigen::Index rows() const { return first.back(); }
};

HorizonOrderedTerms horizon_ordered_terms(const NoiseBandTerms& terms, int steps) {
  HorizonOrderedTerms out;
  out.steps = steps;
  out.sources = terms.sources;
  out.first.assign(static_cast<std::size_t>(steps) + 1, 0);
  std::vector<std::size_t> order;
  for (int h = 0; h < steps; ++h) {
    out.first[static_cast<std::size_t>(h)] = static_cast<Eigen::Index>(order.size());
    for (std::size_t i = 0; i < terms.horizon.size(); ++i)
      if (terms.horizon[i] == h) order.push_back(i);
  }
  out.first[static_cast<std::size_t>(steps)] = static_cast<Eigen::Index>(order.size());
  const auto n = static_cast<Eigen::Index>(order.size());
  for (int k = 0; k < kBodyVars; ++k) {
    out.band[static_cast<std::size_t>(k)].resize(n, out.sources);
    out.error[static_cast<std::size_t>(k)].resize(n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const std::size_t i = order[static_cast<std::size_t>(r)];
      out.band[static_cast<std::size_t>(k)].row(r) = terms.band[i].row(k);
      out.error[static_cast<std::size_t>(k)][r] = terms.error[i][k] * terms.error[i][k];
    }
  }
  return out;
}

// Which variables each source reaches: a move of one source changes only those variables' percentiles
// (any nonzero entry, a band's rounding below 0 included). Only sources that widen some band are searched
// (a variable fixed by nothing widens none).
struct SourceReach {
  std::vector<std::vector<int>> reaches;
  std::vector<char> searched;
};

SourceReach source_reach(const HorizonOrderedTerms& h) {
  SourceReach out{std::vector<std::vector<int>>(static_cast<std::size_t>(h.sources)),
                  std::vector<char>(static_cast<std::size_t>(h.sources), 0)};
  for (int q = 0; q < h.sources; ++q)
    for (int k = 0; k < kBodyVars; ++k) {
      const auto column = h.band[static_cast<std::size_t>(k)].col(q).array();
      if ((column != 0).any()) out.reaches[static_cast<std::size_t>(q)].push_back(k);
      if ((column > 0).any()) out.searched[static_cast<std::size_t>(q)] = 1;
    }
  return out;
}

// The squared log misses of a variable's percentiles over the horizons with its bands under some scales.
// Each variable has its own scratch, so that the variables a move touches are evaluated in parallel (each
// the same bits on any thread; their sum is taken in variable order).
class PercentileMisses {
 public:
  explicit PercentileMisses(const HorizonOrderedTerms& h) : h_(h) {}

  double operator()(int k, const Eigen::VectorXd& bands) {
    std::vector<double>& z2 = scratch_[static_cast<std::size_t>(k)];
    double total = 0;
    for (int hz = 0; hz < h_.steps; ++hz) {
      const Eigen::Index from = h_.first[static_cast<std::size_t>(hz)],
                         to = h_.first[static_cast<std::size_t>(hz) + 1];
      if (to - from < 20) continue;  // too few for a 95th percentile
      z2.clear();
      for (Eigen::Index r = from; r < to; ++r)
        if (bands[r] > 0) z2.push_back(h_.error[static_cast<std::size_t>(k)][r] / bands[r]);
      if (z2.size() < 20) continue;
      const std::size_t at = coverage_rank(z2.size());
      std::nth_element(z2.begin(), z2.begin() + static_cast<std::ptrdiff_t>(at), z2.end());
      if (z2[at] <= 0) continue;
      const double miss = 0.5 * std::log(z2[at] / 4);
      total += miss * miss;
    }
    return total;
  }

 private:
  const HorizonOrderedTerms& h_;
  std::array<std::vector<double>, kBodyVars> scratch_;
};

// Coordinate search on the log scales from log_scale with steps x2, x2^(1/2), ... x2^(1/16), the first
// `penalized` sources kept near 1 by kLogScalePenalty. Each variable's bands are kept under the scales
// accepted so far; a move of one source changes them by its column times the change of its scale (one
// column, not the whole matrix-vector product: the fit's most frequent operation).
Eigen::VectorXd search_log_scales(const HorizonOrderedTerms& h, const SourceReach& reach,
                                  Eigen::VectorXd log_scale, int penalized, ThreadPool* pool) {
  PercentileMisses variable_loss(h);
  std::array<Eigen::VectorXd, kBodyVars> bands, trial_bands;
  BodyVec misses;
  {
    const Eigen::VectorXd scale = log_scale.array().exp();
    for (int k = 0; k < kBodyVars; ++k) {
      bands[static_cast<std::size_t>(k)].noalias() = h.band[static_cast<std::size_t>(k)] * scale;
      misses[k] = variable_loss(k, bands[static_cast<std::size_t>(k)]);
    }
  }
  double best = misses.sum();  // the penalty is 0 at the start
  for (double step = std::log(2.0); step > std::log(2.0) / 17; step /= 2) {
    int passes = 0;
    for (bool moved = true; moved && passes < kScalePassesPerStep; ++passes) {
      moved = false;
      for (int q = 0; q < h.sources; ++q) {
        if (!reach.searched[static_cast<std::size_t>(q)]) continue;
        const std::vector<int>& touched = reach.reaches[static_cast<std::size_t>(q)];
        for (double direction : {1.0, -1.0}) {
          Eigen::VectorXd trial = log_scale;
          trial[q] = std::clamp(trial[q] + direction * step, q < penalized ? -kLogScaleLimit : kLogScaleOff,
                                kLogScaleLimit);
          if (trial[q] == log_scale[q]) continue;
          const double change = std::exp(trial[q]) - std::exp(log_scale[q]);
          BodyVec trial_misses = misses;
          const auto evaluate = [&](std::size_t i) {
            const auto k = static_cast<std::size_t>(touched[i]);
            trial_bands[k].noalias() = bands[k] + change * h.band[k].col(q);
            trial_misses[touched[i]] = variable_loss(touched[i], trial_bands[k]);
          };
          if (pool && touched.size() > 1)
            pool->parallel_for(touched.size(), evaluate, 1);
          else
            for (std::size_t i = 0; i < touched.size(); ++i) evaluate(i);
          const double l = trial_misses.sum() + kLogScalePenalty * trial.head(penalized).squaredNorm();
          if (l < best) {
            best = l;
            log_scale = trial;
            misses = trial_misses;
            for (const int k : touched)
              std::swap(bands[static_cast<std::size_t>(k)], trial_bands[static_cast<std::size_t>(k)]);
            moved = true;
            break;
          }
        }
      }
    }
  }
  return log_scale;
}

}  // namespace

NoiseScale fit_noise_scale(const NoiseBandTerms& terms, double dt, double reset_s, ThreadPool* pool) {
  // One percentile per model step since the reset: the bands are to hold at every horizon. Fitting three
  // spans of the reset window instead let the rates' bands be too wide at a span's first steps and too narrow
  // at its last; over seven training flights, 724 hold-out cells outside 3-7% against 553 (README, The fit at
  // every step).
  const int steps = std::max(1, static_cast<int>(std::lround(reset_s / dt)));
  const int sources = terms.sources;
  const HorizonOrderedTerms ordered = horizon_ordered_terms(terms, steps);
  if (ordered.rows() == 0)
    return {};  // no step counted (every window's first fit singular): nothing to scale by
  const int penalized = std::min(sources, 2 * kBodyVars);
  Eigen::VectorXd log_scale = Eigen::VectorXd::Zero(sources);
  log_scale.tail(sources - penalized).setConstant(kLogScaleOff);
  log_scale = search_log_scales(ordered, source_reach(ordered), log_scale, penalized, pool);
  NoiseScale out;
  for (int j = 0; j < kBodyVars; ++j) {
    out.process[j] = std::exp(log_scale[j]);
    out.measurement[j] = sources > kBodyVars ? std::exp(log_scale[kBodyVars + j]) : 1.0;
    if (sources > 2 * kBodyVars) {
      const double white = log_scale[2 * kBodyVars + j];
      out.measurement_white[j] = white > kLogScaleOff ? std::exp(white) : 0.0;
    }
  }
  return out;
}

std::vector<BodyVec> fit_horizon_sd_factors(const NoiseBandTerms& terms, const NoiseScale& scale, double dt,
                                            double reset_s) {
  const int steps = std::max(1, static_cast<int>(std::lround(reset_s / dt)));
  const Eigen::VectorXd scales = terms.scales(scale);
  // Each counted step's errors over its scaled sd, by horizon.
  std::vector<std::vector<BodyVec>> z(static_cast<std::size_t>(steps));
  for (std::size_t i = 0; i < terms.horizon.size(); ++i) {
    if (terms.horizon[i] < 0 || terms.horizon[i] >= steps) continue;
    const BodyVec band = terms.band[i] * scales;
    BodyVec zi;
    for (int k = 0; k < kBodyVars; ++k)
      zi[k] = band[k] > 0 ? terms.error[i][k] / std::sqrt(band[k]) : -1;  // -1: no band to measure
    z[static_cast<std::size_t>(terms.horizon[i])].push_back(zi);
  }
  std::vector<BodyVec> out(static_cast<std::size_t>(steps), BodyVec::Ones());
  std::vector<double> pooled;
  for (int h = 0; h < steps; ++h) {
    const int from = h == 0 ? 0 : std::max(1, h - 1), to = h == 0 ? 0 : std::min(steps - 1, h + 1);
    for (int k = 0; k < kBodyVars; ++k) {
      pooled.clear();
      for (int g = from; g <= to; ++g)
        for (const BodyVec& zi : z[static_cast<std::size_t>(g)])
          if (zi[k] >= 0) pooled.push_back(zi[k]);
      if (pooled.size() < 20) continue;  // too few for a 95th percentile
      std::sort(pooled.begin(), pooled.end());
      const std::size_t n = pooled.size(), at = coverage_rank(n);
      const auto spread = static_cast<std::size_t>(std::ceil(std::sqrt(n * kCoverage * (1 - kCoverage))));
      const double low = pooled[at >= spread ? at - spread : 0], high = pooled[std::min(n - 1, at + spread)];
      if (!(low > 0)) continue;  // errors of exactly 0 (a band no error reaches): nothing to measure
      double log_factor = std::log(pooled[at] / 2);
      const double se = std::log(high / low) / 2;
      log_factor *= log_factor * log_factor > se * se ? 1 - se * se / (log_factor * log_factor) : 0.0;
      out[static_cast<std::size_t>(h)][k] = std::exp(log_factor);
    }
  }
  return out;
}

std::pair<BodyVec, NoiseCorrelation> scaled_noise(const BodyVec& sigma2, const NoiseCorrelation& correlation,
                                                  const NoiseScale& scale) {
  // sigma2 splits into the logged error's shares, mu (AR(1)) and nu (white), and the process rest (of which
  // `share` is AR(1)): scaling each part moves both sigma2 and the shares.
  BodyVec out_sigma2;
  NoiseCorrelation out = correlation;
  for (int j = 0; j < kBodyVars; ++j) {
    const double mu = correlation.measurement_share[j], nu = correlation.measurement_white_share[j];
    const double phi = correlation.measurement_persistence[j];
    const double process = scale.process[j] * (1 - mu - nu) * sigma2[j];
    const double measurement = scale.measurement[j] * mu * sigma2[j];
    // The white logged error's variance, scaled and added to, and its share of the one-step variance.
    const double white_logged = scale.measurement[j] * correlation.measurement_white_variance(j, sigma2[j]) +
                                scale.measurement_white[j] * sigma2[j];
    const double white = white_logged * (1 + phi * phi);
    out_sigma2[j] = process + measurement + white;
    if (out_sigma2[j] > 0) {
      out.share[j] = scale.process[j] * correlation.share[j] * sigma2[j] / out_sigma2[j];
      // Never above what is left of 1, so that the white process part is not below 0 by rounding.
      out.measurement_share[j] = std::min(measurement / out_sigma2[j], 1 - out.share[j]);
      out.measurement_white_share[j] =
          std::min(white / out_sigma2[j], 1 - out.share[j] - out.measurement_share[j]);
    }
  }
  return {out_sigma2, out};
}

}  // namespace pegasus::sysid
