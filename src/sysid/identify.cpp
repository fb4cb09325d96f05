#include "pegasus/sysid/identify.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

#include "identify_windows.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::sysid {

std::array<double, kInputs> BandwidthFloor::per_input() const {
  std::array<double, kInputs> f{};
  for (int j : {kRoll, kPitch}) f[static_cast<std::size_t>(j)] = angle_rad;
  for (int j : {kU, kV, kW}) f[static_cast<std::size_t>(j)] = velocity_mps;
  for (int j : {kRollRate, kPitchRate, kYawRate, kGyro}) f[static_cast<std::size_t>(j)] = rate_radps;
  for (int j : {kFlapLon, kFlapLat}) f[static_cast<std::size_t>(j)] = flap_rad;
  for (int j : {kA1, kA2, kA3, kA4}) f[static_cast<std::size_t>(j)] = control;
  return f;
}

const std::vector<NumberSetting>& BandwidthFloor::settings() {
  static const std::vector<NumberSetting> list = number_settings<BandwidthFloor>();
  return list;
}

bool BandwidthFloor::IsValid(std::string* error) const {
  const std::string out = numbers_out_of_bounds(*this);
  if (out.empty()) return true;
  if (error) *error = fmt::format("identify: {}{}", kBandwidthFloorPrefix, out);
  return false;
}

bool IdentifyOptions::IsValid(std::string* error) const {
  if (!min_bandwidth.IsValid(error)) return false;
  auto fail = [&](const std::string& what) {
    if (error) *error = "identify: " + what;
    return false;
  };
  if (const std::string out = numbers_out_of_bounds(structure); !out.empty()) return fail(out);
  if (const std::string out = numbers_out_of_bounds(*this); !out.empty()) return fail(out);
  if (scale_grid.empty()) return fail("scale_grid must not be empty");
  for (double s : scale_grid)
    if (!(s > 0)) return fail("scale_grid values must be positive");
  return true;
}

// ---------------------------------------------------------------- model

NoiseModel parse_noise_model(const std::string& name) {
  if (name == "white") return NoiseModel::kWhite;
  if (name == "ar1") return NoiseModel::kAr1;
  if (name == "ar1+measurement") return NoiseModel::kAr1Measurement;
  throw InputError(
      fmt::format("noise: expected \"white\", \"ar1\" or \"ar1+measurement\", got \"{}\"", printable(name)));
}

std::string to_string(NoiseModel model) {
  switch (model) {
    case NoiseModel::kAr1:
      return "ar1";
    case NoiseModel::kAr1Measurement:
      return "ar1+measurement";
    case NoiseModel::kWhite:
      break;
  }
  return "white";
}

IdentifiedModel::IdentifiedModel(ModelStructure structure, Dataset data,
                                 std::array<double, kInputs> inv_bandwidth, BodyVec sigma2,
                                 NoiseCorrelation correlation)
    : structure_(structure),
      data_(std::make_shared<const Dataset>(std::move(data))),
      sigma2_(std::move(sigma2)),
      correlation_(std::move(correlation)),
      templates_(output_templates(structure_)) {
  lwr_ = std::make_unique<LocalRegression>(data_.get(), templates_, inv_bandwidth);
}

BodyVec IdentifiedModel::horizon_sd_factor(std::size_t step) const {
  if (horizon_sd_factors_.empty()) return BodyVec::Ones();
  return horizon_sd_factors_[std::min(step, horizon_sd_factors_.size() - 1)];
}

std::optional<IdentifiedModel> IdentifiedModel::alternative() const {
  if (!alternative_inv_bandwidth_) return std::nullopt;
  IdentifiedModel other(structure_, *data_, *alternative_inv_bandwidth_, sigma2_, correlation_);
  other.set_vehicle(vehicle_);
  return other;
}

BodyVec IdentifiedModel::predictive_variance(const LocalFit& fit) const {
  BodyVec v;
  for (int k = 0; k < kBodyVars; ++k) v[k] = sigma2_[k] * (1 + fit.leverage[k]);
  return v;
}

BodyVec IdentifiedModel::mean_change(const LocalFit& fit, const InputVec& x) const {
  BodyVec d = known_change(structure_, x, dt());
  for (int k = 0; k < kBodyVars; ++k) d[k] += fit.predict(k, x);
  return d;
}

// ---------------------------------------------------------------- cross-validation

namespace detail {

std::pair<Eigen::Index, Eigen::Index> window_rows(const Dataset& d, Eigen::Index i, double window_s) {
  const double t = d.time[static_cast<std::size_t>(i)];
  const auto lo = std::lower_bound(d.time.begin(), d.time.end(), t - window_s / 2) - d.time.begin();
  const auto hi = std::upper_bound(d.time.begin(), d.time.end(), t + window_s / 2) - d.time.begin();
  return {static_cast<Eigen::Index>(lo), static_cast<Eigen::Index>(hi)};
}

}  // namespace detail

double cv_error(const Dataset& data, const std::array<OutputTemplate, kBodyVars>& templates,
                const std::array<double, kInputs>& inv_bandwidth, const IdentifyOptions& o, ThreadPool& pool,
                BodyVec* sigma2) {
  const LocalRegression lwr(&data, templates, inv_bandwidth);
  const Eigen::Index n = data.rows();
  const int m = static_cast<int>(std::min<Eigen::Index>(o.cv_points, n));
  std::vector<BodyVec> sq(static_cast<std::size_t>(m)), scaled(static_cast<std::size_t>(m));
  pool.parallel_for(static_cast<std::size_t>(m), [&](std::size_t p) {
    const Eigen::Index i =
        static_cast<Eigen::Index>((static_cast<double>(p) + 0.5) * static_cast<double>(n) / m);
    const auto [lo, hi] = detail::window_rows(data, i, o.window_s);
    const InputVec x = data.x.row(i).transpose();
    const LocalFit fit = lwr.fit(x, lo, hi);
    for (int k = 0; k < kBodyVars; ++k) {
      const double y = data.y(i, k);
      const double r = fit.singular ? y : y - fit.predict(k, x);
      sq[p][k] = r * r;
      scaled[p][k] = fit.singular ? r * r : r * r / (1 + fit.leverage[k]);
    }
  });
  BodyVec sum = BodyVec::Zero(), sum_scaled = BodyVec::Zero();
  for (int p = 0; p < m; ++p) {
    sum += sq[static_cast<std::size_t>(p)];
    sum_scaled += scaled[static_cast<std::size_t>(p)];
  }
  // Normalise each output by its target variance so every output counts alike.
  double total = 0;
  for (int k = 0; k < kBodyVars; ++k) {
    if (templates[static_cast<std::size_t>(k)].free_count() == 0) continue;
    const double var = (data.y.col(k).array() - data.y.col(k).mean()).square().mean() + 1e-300;
    total += sum[k] / m / var;
  }
  // Footnotes 6-7: sigma^2 from the windowed leave-one-out residuals, each divided by its predictive
  // inflation 1 + x'(X'WX)^{-1}x, not the (biased) Bayesian estimate.
  if (sigma2) *sigma2 = sum_scaled / m;
  return total;
}

std::size_t min_training_log_rows(double log_dt, const ModelStructure& structure) {
  return 4 * kInputs * log_rows_per_model_step(log_dt, structure.rate_hz) + 1;
}

namespace {

// The kernel's inputs: everything the model regresses on except the constant, each by its inverse standard
// deviation over the data (0 where it does not vary).
struct KernelScales {
  std::array<double, kInputs> inv_std{};
  int inputs = 0;  // the inputs that vary
};

KernelScales kernel_scales(const Dataset& data, const ModelStructure& structure, bool extra_states) {
  KernelScales out;
  for (int j = 0; j < kInputs; ++j) {
    if (j == kOne) continue;
    if (!extra_states && (j == kFlapLon || j == kFlapLat || j == kGyro)) continue;
    if (structure.constant_inputs[static_cast<std::size_t>(j)]) continue;
    const double sd = std::sqrt((data.x.col(j).array() - data.x.col(j).mean()).square().mean());
    out.inv_std[static_cast<std::size_t>(j)] = sd > 0 ? 1 / sd : 0;
    out.inputs += sd > 0 ? 1 : 0;
  }
  return out;
}

// The floor as a ceiling on inverse bandwidths (infinity where there is none).
std::array<double, kInputs> inverse_bandwidth_ceiling(const BandwidthFloor& floor) {
  std::array<double, kInputs> max_inv{};
  const auto floors = floor.per_input();
  for (std::size_t j = 0; j < kInputs; ++j)
    max_inv[j] = floors[j] > 0 ? 1 / floors[j] : std::numeric_limits<double>::infinity();
  return max_inv;
}

// The bandwidth search's cross-validation errors in order: each computed, or replayed from the checkpoint it
// resumes (which must be the same search); each counted as a step for the progress hook and traced in the
// report, and the search's state (every evaluation so far) handed to the checkpoint hook.
class CvEvaluations {
 public:
  CvEvaluations(const Dataset& data, const std::array<OutputTemplate, kBodyVars>& templates,
                const IdentifyOptions& o, ThreadPool& pool, IdentifyReport* report,
                const IdentifyHooks& hooks, int total_steps)
      : data_(data),
        templates_(templates),
        o_(o),
        pool_(pool),
        report_(report),
        hooks_(hooks),
        total_steps_(total_steps) {
    if (hooks.resume_from.is_null()) return;
    try {
      for (const auto& e : hooks.resume_from.at("evaluations"))
        evaluated_.emplace_back(e.at("setting").get<std::string>(), e.at("cv_error").get<double>());
    } catch (const nlohmann::json::exception& e) {
      throw InputError(fmt::format("identify: unreadable checkpoint: {}", e.what()));
    }
  }

  double evaluate(const std::string& what, const std::array<double, kInputs>& inv) {
    double e = 0;
    const bool replayed = next_ < evaluated_.size();
    if (replayed) {
      if (evaluated_[next_].first != what)
        throw InputError(
            fmt::format("identify: the checkpoint's step {} is '{}', this search's is '{}': not the same "
                        "search (start afresh with --force)",
                        next_ + 1, evaluated_[next_].first, what));
      e = evaluated_[next_].second;
    } else {
      e = cv_error(data_, templates_, inv, o_, pool_);
      evaluated_.emplace_back(what, e);
      if (hooks_.checkpoint) {
        nlohmann::json list = nlohmann::json::array();
        for (const auto& [setting, value] : evaluated_)
          list.push_back({{"setting", setting}, {"cv_error", value}});
        hooks_.checkpoint({{"evaluations", list}});
      }
    }
    ++next_;
    if (report_) report_->cv_trace.emplace_back(what, e);
    ++steps_;
    if (hooks_.progress) hooks_.progress(steps_, total_steps_, replayed);
    return e;
  }

  // Counts k steps the search had no need to evaluate.
  void skip(int k) {
    steps_ += k;
    if (hooks_.progress && k > 0) hooks_.progress(steps_, total_steps_, true);
  }

 private:
  const Dataset& data_;
  const std::array<OutputTemplate, kBodyVars>& templates_;
  const IdentifyOptions& o_;
  ThreadPool& pool_;
  IdentifyReport* report_;
  const IdentifyHooks& hooks_;
  int total_steps_;
  int steps_ = 0;
  std::vector<std::pair<std::string, double>> evaluated_;
  std::size_t next_ = 0;  // evaluations consumed
};

// The inverse bandwidths of least cross-validation error, each at most max_inv: the scale grid over the
// inputs' inverse standard deviations, then coordinate passes that try each input's x2, x0.5 and x0 in turn
// and keep the first that improves.
std::array<double, kInputs> search_inverse_bandwidths(const std::array<double, kInputs>& inv_std,
                                                      const std::array<double, kInputs>& max_inv,
                                                      const IdentifyOptions& o, CvEvaluations& evaluations) {
  auto floored = [&](std::array<double, kInputs> inv) {
    for (std::size_t j = 0; j < kInputs; ++j) inv[j] = std::min(inv[j], max_inv[j]);
    return inv;
  };
  std::array<double, kInputs> best_inv{};
  double best = INFINITY;
  for (double c : o.scale_grid) {
    std::array<double, kInputs> inv{};
    for (int j = 0; j < kInputs; ++j)
      inv[static_cast<std::size_t>(j)] = inv_std[static_cast<std::size_t>(j)] / c;
    inv = floored(inv);
    const double e = evaluations.evaluate(fmt::format("scale {}", c), inv);
    if (e < best) {
      best = e;
      best_inv = inv;
    }
  }
  for (int pass = 0; pass < o.coordinate_passes; ++pass) {
    for (int j = 0; j < kInputs; ++j) {
      if (inv_std[static_cast<std::size_t>(j)] == 0) continue;
      if (best_inv[static_cast<std::size_t>(j)] == 0) {
        evaluations.skip(3);
        continue;
      }
      int tried = 0;
      for (double f : {2.0, 0.5, 0.0}) {
        auto inv = best_inv;
        inv[static_cast<std::size_t>(j)] *= f;
        inv = floored(inv);
        ++tried;
        if (inv == best_inv) continue;  // narrower than the floor allows: nothing new to evaluate
        const double e =
            evaluations.evaluate(fmt::format("{} x{}", kInputNames[static_cast<std::size_t>(j)], f), inv);
        if (e < best) {
          best = e;
          best_inv = inv;
          break;
        }
      }
      evaluations.skip(3 - tried);
    }
  }
  return best_inv;
}

}  // namespace

IdentifiedModel identify_mean(const FlightLog& train, const IdentifyOptions& o, ThreadPool& pool,
                              IdentifyReport* report, const IdentifyHooks& hooks) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  const auto start = std::chrono::steady_clock::now();
  Dataset data = build_dataset(train, o.structure);
  const auto min_rows = 4 * kInputs;
  if (data.rows() < min_rows)
    throw InputError(fmt::format("identify: the training log gives {} rows at {} Hz; need at least {}",
                                 data.rows(), o.structure.rate_hz, min_rows));
  ModelStructure structure = o.structure;
  structure.constant_inputs = constant_inputs(data);
  const auto templates = output_templates(structure);
  const KernelScales kernel = kernel_scales(data, structure, o.structure.extra_states);
  CvEvaluations evaluations(data, templates, o, pool, report, hooks,
                            static_cast<int>(o.scale_grid.size()) + 3 * kernel.inputs * o.coordinate_passes);
  const std::array<double, kInputs> max_inv = inverse_bandwidth_ceiling(o.min_bandwidth);
  std::array<double, kInputs> best_inv{};
  BodyVec sigma2;
  if (!o.local) {
    const double e = cv_error(data, templates, best_inv, o, pool, &sigma2);
    if (report) report->cv_trace.emplace_back("global", e);
  } else {
    best_inv = search_inverse_bandwidths(kernel.inv_std, max_inv, o, evaluations);
    cv_error(data, templates, best_inv, o, pool, &sigma2);
    if (report)
      for (std::size_t j = 0; j < kInputs; ++j)
        if (best_inv[j] > 0 && best_inv[j] == max_inv[j]) report->floored_inputs.emplace_back(kInputNames[j]);
  }
  // Outputs fixed by the template: sigma^2 is the mean square of what the template leaves.
  for (int k = 0; k < kBodyVars; ++k)
    if (templates[static_cast<std::size_t>(k)].free_count() == 0)
      sigma2[k] = data.y.col(k).squaredNorm() / data.rows();
  if (report)
    report->cv_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return IdentifiedModel(structure, std::move(data), best_inv, sigma2);
}

IdentifiedModel with_noise_model(const IdentifiedModel& mean, const FlightLog& train,
                                 const IdentifyOptions& o, ThreadPool& pool, IdentifyReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const ModelStructure& structure = mean.structure();
  const Dataset& data = mean.data();
  const auto& templates = mean.regression().templates();
  const std::array<double, kInputs>& best_inv = mean.inv_bandwidth();
  BodyVec sigma2 = mean.sigma2();
  NoiseCorrelation correlation;
  if (o.noise != NoiseModel::kWhite)
    correlation = estimate_noise_correlation(data, templates, best_inv, o.window_s, pool,
                                             o.noise == NoiseModel::kAr1Measurement);
  std::vector<BodyVec> sd_factors;
  if (o.calibrate_noise) {
    // The noise check on the training log with the model as identified, its bands split by noise source, and
    // the scales that put the errors' 95.45th percentiles at 2 sd at each model step of the reset window.
    // Each window is predicted by fits that leave out its rows and calibration_leave_out_s / 2 on either side
    // (on data it was fitted to, a locally weighted model's errors are too small), and the windows overlap
    // (calibration_spacing_s) so that a short log still gives enough of them (IdentifyOptions).
    constexpr double kReset = 2.0;
    const IdentifiedModel current(structure, data, best_inv, sigma2, correlation);
    const NoiseBandTerms terms =
        noise_band_terms(current, train, kReset, o.calibration_leave_out_s, pool, o.calibration_spacing_s);
    const NoiseScale scale = fit_noise_scale(terms, current.dt(), kReset, &pool);
    // What the scaled bands still misstate at each step after a reset, on the same windows.
    if (o.horizon_sd_factors) sd_factors = fit_horizon_sd_factors(terms, scale, current.dt(), kReset);
    const BodyVec before = sigma2;
    std::tie(sigma2, correlation) = scaled_noise(sigma2, correlation, scale);
    if (report) {
      report->noise_scale = scale;
      for (int k = 0; k < kBodyVars; ++k)
        report->noise_inflation[k] = before[k] > 0 ? std::sqrt(sigma2[k] / before[k]) : 1.0;
    }
  }
  if (report)
    report->cv_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  IdentifiedModel model(structure, data, best_inv, sigma2, correlation);
  model.set_horizon_sd_factors(std::move(sd_factors));
  return model;
}

IdentifiedModel identify(const FlightLog& train, const IdentifyOptions& o, ThreadPool& pool,
                         IdentifyReport* report, const IdentifyHooks& hooks) {
  return with_noise_model(identify_mean(train, o, pool, report, hooks), train, o, pool, report);
}

}  // namespace pegasus::sysid
