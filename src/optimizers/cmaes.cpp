#include "pegasus/optimizers/cmaes.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <optional>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/hill_climbing.hpp"  // FillStandardNormals
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

using nlohmann::json;

namespace {

// The strategy parameters of the tutorial's Table 1, a function of n and lambda only, so a resumed run
// recomputes them instead of storing them.
struct Strategy {
  int lambda = 0;
  int mu = 0;
  Eigen::VectorXd weights;  // w_1..w_lambda: positive for the mu best, negative (active CMA) for the rest
  double weight_sum = 0.0;  // sum of all w_i, for the decay factor of Eq 47
  double mueff = 0.0;
  double c_sigma = 0.0, d_sigma = 0.0;
  double c_c = 0.0, c_1 = 0.0, c_mu = 0.0;
  double chi_n = 0.0;               // E||N(0, I)||
  std::int64_t eigen_interval = 1;  // generations between eigendecompositions of C
  std::size_t tolfun_window = 1;    // generations of best values the function tolerance looks at
};

Strategy MakeStrategy(std::size_t parameter_count, int lambda) {
  const double n = static_cast<double>(parameter_count);
  Strategy s;
  s.lambda = lambda;
  s.mu = lambda / 2;
  Eigen::VectorXd prime(lambda);
  for (int i = 0; i < lambda; ++i) prime[i] = std::log((lambda + 1) / 2.0) - std::log(i + 1.0);
  const Eigen::VectorXd positive = prime.head(s.mu);
  const Eigen::VectorXd negative = prime.tail(lambda - s.mu);
  s.mueff = positive.sum() * positive.sum() / positive.squaredNorm();
  const double mueff_minus =
      negative.squaredNorm() > 0 ? negative.sum() * negative.sum() / negative.squaredNorm() : 0.0;

  constexpr double alpha_cov = 2.0;
  s.c_c = (4.0 + s.mueff / n) / (n + 4.0 + 2.0 * s.mueff / n);
  s.c_1 = alpha_cov / ((n + 1.3) * (n + 1.3) + s.mueff);
  s.c_mu = std::min(1.0 - s.c_1, alpha_cov * (s.mueff - 2.0 + 1.0 / s.mueff) /
                                     ((n + 2.0) * (n + 2.0) + alpha_cov * s.mueff / 2.0));
  s.c_sigma = (s.mueff + 2.0) / (n + s.mueff + 5.0);
  s.d_sigma = 1.0 + 2.0 * std::max(0.0, std::sqrt((s.mueff - 1.0) / (n + 1.0)) - 1.0) + s.c_sigma;
  s.chi_n = std::sqrt(n) * (1.0 - 1.0 / (4.0 * n) + 1.0 / (21.0 * n * n));

  s.weights.resize(lambda);
  s.weights.head(s.mu) = positive / positive.sum();
  // Negative weights scaled so that C stays positive definite (Eqs 50-53); without a rank-mu update
  // (c_mu = 0, a population of 2 or 3) they would multiply nothing.
  const double negative_mass = -negative.sum();
  if (s.c_mu > 0.0 && negative_mass > 0.0) {
    const double alpha_mu_minus = 1.0 + s.c_1 / s.c_mu;
    const double alpha_mueff_minus = 1.0 + 2.0 * mueff_minus / (s.mueff + 2.0);
    const double alpha_posdef_minus = (1.0 - s.c_1 - s.c_mu) / (n * s.c_mu);
    s.weights.tail(lambda - s.mu) =
        std::min({alpha_mu_minus, alpha_mueff_minus, alpha_posdef_minus}) / negative_mass * negative;
  } else {
    s.weights.tail(lambda - s.mu).setZero();
  }
  s.weight_sum = s.weights.sum();

  s.eigen_interval =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(1.0 / (10.0 * n * (s.c_1 + s.c_mu))));
  s.tolfun_window = 10 + static_cast<std::size_t>(std::ceil(30.0 * n / lambda));
  return s;
}

Eigen::VectorXd EigenFromJson(const json& values, const char* field, std::size_t size) {
  const std::vector<double> v = VectorFromJson(values, fmt::format("state.{}", field));
  if (v.size() != size)
    throw InputError(fmt::format("checkpoint state.{}: expected {} numbers, got {}", field, size, v.size()));
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// A square matrix row by row, as one flat array.
json MatrixToJson(const Eigen::MatrixXd& m) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = m;
  return VectorToJson(std::span<const double>(rows.data(), static_cast<std::size_t>(rows.size())));
}

Eigen::MatrixXd MatrixFromJson(const json& values, const char* field, std::size_t n) {
  const Eigen::VectorXd flat = EigenFromJson(values, field, n * n);
  const auto size = static_cast<Eigen::Index>(n);
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(flat.data(),
                                                                                                  size, size);
}

// The distribution N(mean, sigma^2 S C S) with S = diag(scale), and what sampling and the update need of
// it; B and D are refreshed lazily, so they are state too, not a function of C.
struct Distribution {
  Theta mean;
  double sigma = 0.0;
  Eigen::MatrixXd C, B;
  Eigen::VectorXd D;  // square roots of the eigenvalues of C, the columns of B their eigenvectors
  Eigen::VectorXd p_sigma, p_c;
  std::int64_t eigen_iteration = 0;  // the iteration whose C was last decomposed
  Eigen::MatrixXd inv_sqrt_C;        // B D^-1 B^T, from B and D only

  void RefreshInverseSquareRoot() { inv_sqrt_C = B * D.cwiseInverse().asDiagonal() * B.transpose(); }
};

// sigma = initial_step, C = I (decomposed), no evolution paths: the start of every run.
void StartDistribution(double initial_step, Distribution* d) {
  const auto size = static_cast<Eigen::Index>(d->mean.size());
  d->sigma = initial_step;
  d->C = d->B = Eigen::MatrixXd::Identity(size, size);
  d->D = Eigen::VectorXd::Ones(size);
  d->p_sigma = d->p_c = Eigen::VectorXd::Zero(size);
}

// Maps the search space onto the box [lower, upper] of one parameter, continuously differentiable: the
// identity on [lower + margin, upper - margin], quadratic within `margin` of a bound (reaching the bound
// with zero slope at bound -/+ margin), mirrored beyond, periodic for a two-sided box (the shape of pycma's
// BoxConstraintsLinQuadTransformation). The margin is min(width / 20, scale): small against the box,
// and at most one typical useful change. Points of the identity part map to themselves bit for bit.
class BoxTransform {
 public:
  BoxTransform(double lower, double upper, double scale) : lower_(lower), upper_(upper) {
    const double width = upper - lower;
    margin_ = std::isfinite(width) ? std::min(width / 20.0, scale) : scale;
  }

  double operator()(double x) const {
    const bool has_lower = std::isfinite(lower_), has_upper = std::isfinite(upper_);
    if ((!has_lower || x >= lower_ + margin_) && (!has_upper || x <= upper_ - margin_)) return x;
    if (margin_ == 0.0) return lower_;  // a fixed parameter (lower == upper)
    const double a = margin_;
    if (has_lower && has_upper) {
      // Fold x into [lower - a, upper + a]: period 2 (upper - lower + 2a), mirrored in its second half.
      const double span = upper_ - lower_ + 2.0 * a;
      double y = x - (lower_ - a);
      y -= 2.0 * span * std::floor(y / (2.0 * span));
      if (y > span) y = 2.0 * span - y;
      x = (lower_ - a) + y;
    } else if (has_lower) {
      if (x < lower_ - a) x = 2.0 * (lower_ - a) - x;
    } else if (x > upper_ + a) {
      x = 2.0 * (upper_ + a) - x;
    }
    if (has_lower && x < lower_ + a)
      return std::max(lower_, lower_ + (x - (lower_ - a)) * (x - (lower_ - a)) / (4.0 * a));
    if (has_upper && x > upper_ - a)
      return std::min(upper_, upper_ - (x - (upper_ + a)) * (x - (upper_ + a)) / (4.0 * a));
    return x;
  }

  // A point the transformation maps to theta (inside the box), for the first mean.
  double Inverse(double theta) const {
    const double a = margin_;
    if (a == 0.0) return theta;
    if (std::isfinite(lower_) && theta < lower_ + a)
      return (lower_ - a) + std::sqrt(4.0 * a * (theta - lower_));
    if (std::isfinite(upper_) && theta > upper_ - a)
      return (upper_ + a) - std::sqrt(4.0 * a * (upper_ - theta));
    return theta;
  }

 private:
  double lower_, upper_, margin_ = 0.0;
};

}  // namespace

bool CmaesOptions::IsValid(std::string* error) const {
  if (max_iterations < 0)
    return RejectOption(error, "max_iterations", ">= 0", static_cast<double>(max_iterations));
  if (max_evaluations < 1)
    return RejectOption(error, "max_evaluations", ">= 1", static_cast<double>(max_evaluations));
  if (population_size != 0 && (population_size < 2 || population_size > kMaxPointsPerIteration))
    return RejectOption(error, "population_size",
                        fmt::format("0 (automatic) or in [2, {}]", kMaxPointsPerIteration), population_size);
  if (!(initial_step > 0.0 && std::isfinite(initial_step)))
    return RejectOption(error, "initial_step", "a finite value > 0", initial_step);
  if (!(x_tolerance >= 0.0 && std::isfinite(x_tolerance)))
    return RejectOption(error, "x_tolerance", "a finite value >= 0", x_tolerance);
  if (!(function_tolerance >= 0.0 && std::isfinite(function_tolerance)))
    return RejectOption(error, "function_tolerance", "a finite value >= 0", function_tolerance);
  if (!(max_condition > 1.0)) return RejectOption(error, "max_condition", "a value > 1", max_condition);
  if (stall_generations < 0)
    return RejectOption(error, "stall_generations", ">= 0", static_cast<double>(stall_generations));
  if (!(stall_tolerance >= 0.0 && std::isfinite(stall_tolerance)))
    return RejectOption(error, "stall_tolerance", "a finite value >= 0", stall_tolerance);
  // 2^restarts times the population must stay an int.
  if (restarts < 0 || restarts > kCmaesMaxRestarts)
    return RejectOption(error, "restarts", fmt::format("in [0, {}]", kCmaesMaxRestarts), restarts);
  return IsValidFor("cmaes", error);
}

int CmaesPopulationSize(const CmaesOptions& options, std::size_t parameter_count) {
  if (options.population_size > 0) return options.population_size;
  return 4 + static_cast<int>(
                 std::floor(3.0 * std::log(static_cast<double>(std::max<std::size_t>(parameter_count, 1)))));
}

namespace {

// Why a generation ends the search. A convergence stop (x_tolerance, function_tolerance, a stall) starts
// the next run instead while restarts remain.
struct Stop {
  TerminationType termination = TerminationType::kFailure;
  std::string message;
  bool restartable = false;
};

// One CMA-ES search: the strategy and distribution of the current run, what the stopping rules remember,
// and the buffers a generation fills (allocated when a run starts, so a generation allocates nothing). Its
// members are the steps of one generation, in the order Solve calls them.
class Search {
 public:
  Search(const CmaesOptions& options, const ParameterSpec& spec, int first_population)
      : options_(options),
        n_(spec.size()),
        scale_(spec.scales()),
        first_population_(first_population),
        strategy_(MakeStrategy(n_, first_population)),
        normals_(n_),
        scaled_normals_(n_),
        weighted_step_(n_),
        whitened_(n_),
        rank_mu_(n_, n_),
        eigen_(static_cast<Eigen::Index>(n_)) {
    const Theta lower = spec.lower();
    const Theta upper = spec.upper();
    for (std::size_t i = 0; i < n_; ++i) box_.emplace_back(lower[i], upper[i], scale_[i]);
  }

  // The first run from *theta, evaluated first: the mean starts at the point the box maps onto it.
  void Start(const Theta& first, Objective& objective, RunProgress& run) {
    const double value = objective.evaluate(first);
    run.AddEvaluations(1);
    run.set_initial_value(value);
    run.Offer(first, value);
    d_.mean.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) d_.mean[i] = box_[i].Inverse(first[i]);
    start_ = d_.mean;
    StartDistribution(options_.initial_step, &d_);
    Prepare();
  }

  // Continues the run a checkpoint's state describes; returns the position of its uniform stream.
  std::uint64_t Resume(const json& state) {
    if (state.contains("restarts")) {
      ResumeRestarts(state);
    } else if (options_.restarts > 0) {
      throw InputError("checkpoint state.restarts: missing (the checkpoint was written without restarts)");
    }
    strategy_ = MakeStrategy(n_, PopulationOfRun(restarts_));
    if (StateInteger(state, "population") != strategy_.lambda)
      throw InputError(
          fmt::format("checkpoint state.population: expected {} (the options' population), got {}",
                      strategy_.lambda, StateInteger(state, "population")));
    ResumeDistribution(state);
    for (const double v : VectorFromJson(StateField(state, "recent_best"), "state.recent_best"))
      recent_best_.push_back(v);
    Prepare();
    return StateUnsigned(state, "stream_position");
  }

  std::int64_t population() const { return strategy_.lambda; }
  double sigma() const { return d_.sigma; }
  std::int64_t restarts() const { return restarts_; }

  // Samples y_k = B D z_k (Eq 39) and evaluates the candidates, mapped into the bounds, in one batch.
  void SampleAndEvaluate(UniformStream& uniforms, Objective& objective, RunProgress& run) {
    const std::size_t lambda = candidates_.size();
    for (std::size_t k = 0; k < lambda; ++k) {
      FillStandardNormals(uniforms, normals_);
      for (std::size_t i = 0; i < n_; ++i) scaled_normals_[i] = d_.D[i] * normals_[i];
      steps_[k].noalias() = d_.B * scaled_normals_;
      for (std::size_t i = 0; i < n_; ++i)
        candidates_[k][i] = box_[i](d_.mean[i] + d_.sigma * scale_[i] * steps_[k][i]);
    }
    objective.evaluate_batch(candidates_, values_);
    run.AddEvaluations(static_cast<std::int64_t>(lambda));
    for (std::size_t k = 0; k < lambda; ++k) run.Offer(candidates_[k], values_[k]);
  }

  // Ranks best first; ties keep index order, NaN last.
  void Rank() {
    std::iota(order_.begin(), order_.end(), std::size_t{0});
    std::stable_sort(order_.begin(), order_.end(),
                     [&](std::size_t a, std::size_t b) { return IsImprovement(values_[a], values_[b]); });
  }

  // The update of Eqs 41-47 from the ranked generation; `iteration` is the count before it ends.
  void Update(std::int64_t iteration) {
    MoveMean();
    const bool h_sigma = AdaptStepSize(iteration);
    AdaptCovariance(h_sigma);
  }

  // What the function tolerance and the stall rule remember of the generation just ended.
  void RecordBest() {
    const double generation_best = values_[order_[0]];
    recent_best_.push_back(generation_best);
    if (recent_best_.size() > strategy_.tolfun_window) recent_best_.pop_front();
    if (options_.stall_generations > 0) {
      // NaN never raises the run's best (IsImprovement ranks it last).
      const double best = run_best_.empty() || IsImprovement(generation_best, run_best_.back())
                              ? generation_best
                              : run_best_.back();
      run_best_.push_back(best);
      if (run_best_.size() > static_cast<std::size_t>(options_.stall_generations) + 1) run_best_.pop_front();
    }
  }

  // A distribution that can no longer be sampled: non-finite, no longer positive definite, or
  // ill-conditioned. Refreshes B and D first when they are due, so the condition is C's current one.
  std::optional<Stop> Degenerated(std::int64_t iteration) {
    if (!std::isfinite(d_.sigma) || !d_.C.allFinite())
      return Stop{TerminationType::kFailure,
                  fmt::format("sigma ({}) or the covariance matrix became non-finite", d_.sigma), false};
    if (iteration - d_.eigen_iteration >= strategy_.eigen_interval && !Decompose(iteration))
      return Stop{TerminationType::kFailure, "the covariance matrix lost positive definiteness", false};
    const double condition = (d_.D.maxCoeff() / d_.D.minCoeff()) * (d_.D.maxCoeff() / d_.D.minCoeff());
    if (condition > options_.max_condition)
      return Stop{TerminationType::kFailure,
                  fmt::format("the condition number of C, {:.3g}, passed max_condition = {:.3g}", condition,
                              options_.max_condition),
                  false};
    return std::nullopt;
  }

  // The convergence rules, in order: x_tolerance, function_tolerance, a stall.
  std::optional<Stop> Converged() const {
    double spread = 0.0;
    for (std::size_t i = 0; i < n_; ++i)
      spread = std::max({spread, std::abs(d_.p_c[i]), std::sqrt(d_.C(i, i))});
    if (d_.sigma * spread < options_.x_tolerance)
      return Stop{TerminationType::kConvergence,
                  fmt::format("sigma * max(|p_c|, sqrt(diag C)) = {:.3g} fell below x_tolerance = {:.3g}",
                              d_.sigma * spread, options_.x_tolerance),
                  true};
    if (std::optional<Stop> flat = FunctionFlat()) return flat;
    if (run_best_.size() == static_cast<std::size_t>(options_.stall_generations) + 1 &&
        !(run_best_.back() - run_best_.front() > options_.stall_tolerance))
      return Stop{TerminationType::kConvergence,
                  fmt::format("the best U-hat rose by {:.3g} <= stall_tolerance = {:.3g} over {} generations",
                              run_best_.back() - run_best_.front(), options_.stall_tolerance,
                              options_.stall_generations),
                  true};
    return std::nullopt;
  }

  // IPOP: when restarts remain, the next run from the first mean, with twice the population; false when
  // none remain. `iteration` is the count the new run starts at.
  bool Restart(std::int64_t iteration) {
    if (restarts_ >= options_.restarts) return false;
    ++restarts_;
    strategy_ = MakeStrategy(n_, PopulationOfRun(restarts_));
    d_.mean = start_;
    StartDistribution(options_.initial_step, &d_);
    d_.eigen_iteration = iteration;
    recent_best_.clear();
    run_best_.clear();
    run_first_iteration_ = iteration;
    Prepare();
    return true;
  }

  // Everything the next generation reads (the header lists it).
  json State(std::uint64_t stream_position) const {
    return json{{"population", strategy_.lambda},
                {"mean", VectorToJson(d_.mean)},
                {"sigma", DoubleToJson(d_.sigma)},
                {"C", MatrixToJson(d_.C)},
                {"B", MatrixToJson(d_.B)},
                {"D", VectorToJson(std::span<const double>(d_.D.data(), n_))},
                {"p_sigma", VectorToJson(std::span<const double>(d_.p_sigma.data(), n_))},
                {"p_c", VectorToJson(std::span<const double>(d_.p_c.data(), n_))},
                {"eigen_iteration", d_.eigen_iteration},
                {"recent_best", VectorToJson(std::vector<double>(recent_best_.begin(), recent_best_.end()))},
                {"stream_position", stream_position},
                {"restarts", restarts_},
                {"run_first_iteration", run_first_iteration_},
                {"run_best", VectorToJson(std::vector<double>(run_best_.begin(), run_best_.end()))},
                {"start", VectorToJson(start_)}};
  }

 private:
  int PopulationOfRun(std::int64_t restart) const {
    return static_cast<int>(static_cast<std::int64_t>(first_population_) << restart);
  }

  // The restart state a checkpoint written with restarts carries.
  void ResumeRestarts(const json& state) {
    restarts_ = StateInteger(state, "restarts");
    if (restarts_ < 0 || restarts_ > options_.restarts)
      throw InputError(
          fmt::format("checkpoint state.restarts: expected 0 to {} (the options' restarts), got {}",
                      options_.restarts, restarts_));
    run_first_iteration_ = StateInteger(state, "run_first_iteration");
    for (const double v : VectorFromJson(StateField(state, "run_best"), "state.run_best"))
      run_best_.push_back(v);
    start_ = VectorFromJson(StateField(state, "start"), "state.start");
    if (start_.size() != n_) throw InputError(fmt::format("checkpoint state.start: expected {} numbers", n_));
  }

  void ResumeDistribution(const json& state) {
    d_.mean = VectorFromJson(StateField(state, "mean"), "state.mean");
    if (d_.mean.size() != n_ ||
        !std::all_of(d_.mean.begin(), d_.mean.end(), [](double v) { return std::isfinite(v); }))
      throw InputError(fmt::format("checkpoint state.mean: expected {} finite numbers", n_));
    d_.sigma = DoubleFromJson(StateField(state, "sigma"), "state.sigma");
    d_.C = MatrixFromJson(StateField(state, "C"), "C", n_);
    d_.B = MatrixFromJson(StateField(state, "B"), "B", n_);
    d_.D = EigenFromJson(StateField(state, "D"), "D", n_);
    d_.p_sigma = EigenFromJson(StateField(state, "p_sigma"), "p_sigma", n_);
    d_.p_c = EigenFromJson(StateField(state, "p_c"), "p_c", n_);
    d_.eigen_iteration = StateInteger(state, "eigen_iteration");
  }

  // C^-1/2 from the run's B and D, and the generation's buffers sized for its population.
  void Prepare() {
    d_.RefreshInverseSquareRoot();
    const auto lambda = static_cast<std::size_t>(strategy_.lambda);
    candidates_.assign(lambda, Theta(n_));
    values_.assign(lambda, 0.0);
    steps_.assign(lambda, Eigen::VectorXd(n_));
    order_.assign(lambda, 0);
  }

  // Recombination (Eq 41, c_m = 1): the mean moves by the weighted steps of the mu best.
  void MoveMean() {
    weighted_step_.setZero();
    for (int r = 0; r < strategy_.mu; ++r) weighted_step_ += strategy_.weights[r] * steps_[order_[r]];
    for (std::size_t i = 0; i < n_; ++i) d_.mean[i] += d_.sigma * scale_[i] * weighted_step_[i];
  }

  // Cumulative step-size adaptation (Eqs 43-44); returns h_sigma, whether p_c takes this step.
  bool AdaptStepSize(std::int64_t iteration) {
    const Strategy& s = strategy_;
    whitened_.noalias() = d_.inv_sqrt_C * weighted_step_;
    d_.p_sigma =
        (1.0 - s.c_sigma) * d_.p_sigma + std::sqrt(s.c_sigma * (2.0 - s.c_sigma) * s.mueff) * whitened_;
    const double p_sigma_norm = d_.p_sigma.norm();
    const auto generation = static_cast<double>(iteration + 1 - run_first_iteration_);
    const bool h_sigma = p_sigma_norm / std::sqrt(1.0 - std::pow(1.0 - s.c_sigma, 2.0 * generation)) <
                         (1.4 + 2.0 / (static_cast<double>(n_) + 1.0)) * s.chi_n;
    d_.sigma *= std::exp(s.c_sigma / s.d_sigma * (p_sigma_norm / s.chi_n - 1.0));
    return h_sigma;
  }

  // Covariance matrix adaptation (Eqs 45-47): rank-one update from the path, rank-mu from all
  // candidates, the negative weights rescaled by n / ||C^-1/2 y||^2 (Eq 46).
  void AdaptCovariance(bool h_sigma) {
    const Strategy& s = strategy_;
    d_.p_c = (1.0 - s.c_c) * d_.p_c;
    if (h_sigma) d_.p_c += std::sqrt(s.c_c * (2.0 - s.c_c) * s.mueff) * weighted_step_;
    rank_mu_.setZero();
    for (std::size_t r = 0; r < order_.size(); ++r) {
      const Eigen::VectorXd& y = steps_[order_[r]];
      double w = s.weights[static_cast<Eigen::Index>(r)];
      if (w < 0.0) {
        whitened_.noalias() = d_.inv_sqrt_C * y;
        const double squared = whitened_.squaredNorm();
        w = squared > 0.0 ? w * static_cast<double>(n_) / squared : 0.0;
      }
      if (w != 0.0) rank_mu_.noalias() += w * y * y.transpose();
    }
    const double delta_h = h_sigma ? 0.0 : s.c_c * (2.0 - s.c_c);
    d_.C = (1.0 + s.c_1 * delta_h - s.c_1 - s.c_mu * s.weight_sum) * d_.C +
           s.c_1 * d_.p_c * d_.p_c.transpose() + s.c_mu * rank_mu_;
  }

  // B and D from the symmetrised C; false when C is no longer positive definite.
  bool Decompose(std::int64_t iteration) {
    d_.C = (0.5 * (d_.C + d_.C.transpose())).eval();
    eigen_.compute(d_.C);
    if (eigen_.info() != Eigen::Success || !(eigen_.eigenvalues().minCoeff() > 0.0)) return false;
    d_.B = eigen_.eigenvectors();
    d_.D = eigen_.eigenvalues().cwiseSqrt();
    d_.eigen_iteration = iteration;
    d_.RefreshInverseSquareRoot();
    return true;
  }

  // U-hat ranged by less than function_tolerance over the recent best values and this generation's
  // values; a non-finite one never stops the run.
  std::optional<Stop> FunctionFlat() const {
    if (recent_best_.size() != strategy_.tolfun_window) return std::nullopt;
    double lo = values_[0], hi = values_[0];
    for (const double v : recent_best_) lo = std::min(lo, v), hi = std::max(hi, v);
    for (const double v : values_) lo = std::min(lo, v), hi = std::max(hi, v);
    bool finite = std::isfinite(hi - lo);
    for (const double v : values_) finite = finite && std::isfinite(v);
    for (const double v : recent_best_) finite = finite && std::isfinite(v);
    if (!(finite && hi - lo < options_.function_tolerance)) return std::nullopt;
    return Stop{TerminationType::kConvergence,
                fmt::format("U-hat ranged by {:.3g} < function_tolerance = {:.3g} over {} generations",
                            hi - lo, options_.function_tolerance, strategy_.tolfun_window),
                true};
  }

  const CmaesOptions& options_;
  const std::size_t n_;
  const Theta scale_;
  const int first_population_;
  std::vector<BoxTransform> box_;
  Strategy strategy_;
  Distribution d_;
  std::deque<double> recent_best_;        // best U-hat of each of the last tolfun_window generations
  std::int64_t restarts_ = 0;             // runs started after the first
  std::int64_t run_first_iteration_ = 0;  // the iteration count when this run started
  std::deque<double> run_best_;           // this run's best U-hat after each of its last generations
  Theta start_;                           // the first mean (search space), where every run starts

  // The generation's buffers and scratch.
  std::vector<Theta> candidates_;
  std::vector<double> values_;
  std::vector<Eigen::VectorXd> steps_;  // y_k, scaled units
  std::vector<std::size_t> order_;      // candidate indices, best first
  Theta normals_;
  Eigen::VectorXd scaled_normals_, weighted_step_, whitened_;
  Eigen::MatrixXd rank_mu_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen_;
};

// The first run's population; throws when the restarts would double it past kMaxPointsPerIteration.
int FirstPopulation(const CmaesOptions& options, std::size_t n) {
  const int first_population = CmaesPopulationSize(options, n);
  if ((static_cast<std::int64_t>(first_population) << options.restarts) > kMaxPointsPerIteration)
    throw InputError(
        fmt::format("cmaes options: restarts: {} restarts would double the population of {} past {}",
                    options.restarts, first_population, kMaxPointsPerIteration));
  return first_population;
}

}  // namespace

void Solve(const CmaesOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("cmaes options: " + error);
  if (theta == nullptr || summary == nullptr) throw InputError("cmaes: theta and summary must be non-null");
  const ParameterSpec& spec = objective.parameters();
  if (spec.size() == 0) throw InputError("cmaes: the policy class has no parameters");

  Search search(options, spec, FirstPopulation(options, spec.size()));
  RunProgress run("cmaes", spec, options.callbacks);
  std::uint64_t stream_position = 0;
  if (options.resume_from)
    stream_position = search.Resume(run.Resume(*options.resume_from));
  else
    search.Start(StartingTheta(spec, *theta), objective, run);
  UniformStream uniforms(options.seed, options.stream, stream_position);

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations, search.population(), &termination,
                        &message, "a generation"))
      break;
    search.SampleAndEvaluate(uniforms, objective, run);
    search.Rank();
    search.Update(run.iterations());
    const bool go_on = run.EndIteration();
    search.RecordBest();
    std::optional<Stop> stop;
    if (!go_on) stop = Stop{TerminationType::kUserRequested, "an iteration callback asked to stop", false};
    if (!stop) stop = search.Degenerated(run.iterations());
    if (!stop) stop = search.Converged();
    if (stop) {
      if (stop->restartable && search.Restart(run.iterations())) continue;
      termination = stop->termination;
      message = std::move(stop->message);
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every))
      options.on_checkpoint(run.Checkpoint(search.State(uniforms.position())));
  }

  if (search.restarts() > 0)
    message += fmt::format(" (after {} restart{}, population {})", search.restarts(),
                           search.restarts() == 1 ? "" : "s", search.population());
  run.Finish(termination, std::move(message), summary);
  summary->final_step = search.sigma();
  *theta = summary->best_theta;
}

}  // namespace pegasus
