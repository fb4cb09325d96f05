#include "pegasus/optimizers/cmaes.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>

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

void Solve(const CmaesOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("cmaes options: " + error);
  if (theta == nullptr || summary == nullptr) throw InputError("cmaes: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  const std::size_t n = spec.size();
  if (n == 0) throw InputError("cmaes: the policy class has no parameters");
  const Theta lower = spec.lower();
  const Theta upper = spec.upper();
  const Theta scale = spec.scales();
  const int first_population = CmaesPopulationSize(options, n);
  if ((static_cast<std::int64_t>(first_population) << options.restarts) > kMaxPointsPerIteration)
    throw InputError(
        fmt::format("cmaes options: restarts: {} restarts would double the population of {} past {}",
                    options.restarts, first_population, kMaxPointsPerIteration));
  const auto population_of_run = [&](std::int64_t restart) {
    return static_cast<int>(static_cast<std::int64_t>(first_population) << restart);
  };
  Strategy strategy = MakeStrategy(n, first_population);
  std::vector<BoxTransform> box;
  for (std::size_t i = 0; i < n; ++i) box.emplace_back(lower[i], upper[i], scale[i]);
  RunProgress run("cmaes", spec, options.callbacks);

  Distribution d;
  std::deque<double> recent_best;  // best U-hat of each of the last tolfun_window generations
  std::uint64_t stream_position = 0;
  std::int64_t restarts = 0;             // runs started after the first
  std::int64_t run_first_iteration = 0;  // the iteration count when this run started
  std::deque<double> run_best;           // this run's best U-hat after each of its last generations
  Theta start;                           // the first mean (search space), where every run starts
  if (options.resume_from) {
    const json& state = run.Resume(*options.resume_from);
    if (state.contains("restarts")) {
      restarts = StateInteger(state, "restarts");
      if (restarts < 0 || restarts > options.restarts)
        throw InputError(
            fmt::format("checkpoint state.restarts: expected 0 to {} (the options' restarts), got {}",
                        options.restarts, restarts));
      run_first_iteration = StateInteger(state, "run_first_iteration");
      for (const double v : VectorFromJson(StateField(state, "run_best"), "state.run_best"))
        run_best.push_back(v);
      start = VectorFromJson(StateField(state, "start"), "state.start");
      if (start.size() != n) throw InputError(fmt::format("checkpoint state.start: expected {} numbers", n));
    } else if (options.restarts > 0) {
      throw InputError("checkpoint state.restarts: missing (the checkpoint was written without restarts)");
    }
    strategy = MakeStrategy(n, population_of_run(restarts));
    if (StateInteger(state, "population") != strategy.lambda)
      throw InputError(
          fmt::format("checkpoint state.population: expected {} (the options' population), got {}",
                      strategy.lambda, StateInteger(state, "population")));
    d.mean = VectorFromJson(StateField(state, "mean"), "state.mean");
    if (d.mean.size() != n ||
        !std::all_of(d.mean.begin(), d.mean.end(), [](double v) { return std::isfinite(v); }))
      throw InputError(fmt::format("checkpoint state.mean: expected {} finite numbers", n));
    d.sigma = DoubleFromJson(StateField(state, "sigma"), "state.sigma");
    d.C = MatrixFromJson(StateField(state, "C"), "C", n);
    d.B = MatrixFromJson(StateField(state, "B"), "B", n);
    d.D = EigenFromJson(StateField(state, "D"), "D", n);
    d.p_sigma = EigenFromJson(StateField(state, "p_sigma"), "p_sigma", n);
    d.p_c = EigenFromJson(StateField(state, "p_c"), "p_c", n);
    d.eigen_iteration = StateInteger(state, "eigen_iteration");
    for (const double v : VectorFromJson(StateField(state, "recent_best"), "state.recent_best"))
      recent_best.push_back(v);
    stream_position = StateUnsigned(state, "stream_position");
  } else {
    const Theta first = StartingTheta(spec, *theta);
    const double value = objective.evaluate(first);
    run.AddEvaluations(1);
    run.set_initial_value(value);
    run.Offer(first, value);
    d.mean.resize(n);
    for (std::size_t i = 0; i < n; ++i) d.mean[i] = box[i].Inverse(first[i]);
    start = d.mean;
    StartDistribution(options.initial_step, &d);
  }
  d.RefreshInverseSquareRoot();
  UniformStream uniforms(options.seed, options.stream, stream_position);

  auto lambda = static_cast<std::size_t>(strategy.lambda);
  std::vector<Theta> candidates(lambda, Theta(n));
  std::vector<double> values(lambda);
  std::vector<Eigen::VectorXd> steps(lambda, Eigen::VectorXd(n));  // y_k, scaled units
  std::vector<std::size_t> order(lambda);
  // A stop that restarts (IPOP) when restarts remain: the next run from the first mean, twice the population.
  auto restart = [&]() {
    if (restarts >= options.restarts) return false;
    ++restarts;
    strategy = MakeStrategy(n, population_of_run(restarts));
    lambda = static_cast<std::size_t>(strategy.lambda);
    candidates.assign(lambda, Theta(n));
    values.assign(lambda, 0.0);
    steps.assign(lambda, Eigen::VectorXd(n));
    order.assign(lambda, 0);
    d.mean = start;
    StartDistribution(options.initial_step, &d);
    d.eigen_iteration = run.iterations();
    d.RefreshInverseSquareRoot();
    recent_best.clear();
    run_best.clear();
    run_first_iteration = run.iterations();
    return true;
  };
  Theta normals(n);
  Eigen::VectorXd scaled_normals(n), weighted_step(n), whitened(n);
  Eigen::MatrixXd rank_mu(n, n);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(static_cast<Eigen::Index>(n));

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations, static_cast<std::int64_t>(lambda),
                        &termination, &message, "a generation"))
      break;

    // Sample y_k = B D z_k (Eq 39) and evaluate the candidates, mapped into the bounds, in one batch.
    for (std::size_t k = 0; k < lambda; ++k) {
      FillStandardNormals(uniforms, normals);
      for (std::size_t i = 0; i < n; ++i) scaled_normals[i] = d.D[i] * normals[i];
      steps[k].noalias() = d.B * scaled_normals;
      for (std::size_t i = 0; i < n; ++i)
        candidates[k][i] = box[i](d.mean[i] + d.sigma * scale[i] * steps[k][i]);
    }
    objective.evaluate_batch(candidates, values);
    run.AddEvaluations(static_cast<std::int64_t>(lambda));
    for (std::size_t k = 0; k < lambda; ++k) run.Offer(candidates[k], values[k]);

    // Rank best first; ties keep index order, NaN last.
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return IsImprovement(values[a], values[b]); });

    // Recombination (Eq 41, c_m = 1): the mean moves by the weighted steps of the mu best.
    weighted_step.setZero();
    for (int r = 0; r < strategy.mu; ++r) weighted_step += strategy.weights[r] * steps[order[r]];
    for (std::size_t i = 0; i < n; ++i) d.mean[i] += d.sigma * scale[i] * weighted_step[i];

    // Cumulative step-size adaptation (Eqs 43-44).
    whitened.noalias() = d.inv_sqrt_C * weighted_step;
    d.p_sigma = (1.0 - strategy.c_sigma) * d.p_sigma +
                std::sqrt(strategy.c_sigma * (2.0 - strategy.c_sigma) * strategy.mueff) * whitened;
    const double p_sigma_norm = d.p_sigma.norm();
    const auto generation = static_cast<double>(run.iterations() + 1 - run_first_iteration);
    const bool h_sigma = p_sigma_norm / std::sqrt(1.0 - std::pow(1.0 - strategy.c_sigma, 2.0 * generation)) <
                         (1.4 + 2.0 / (static_cast<double>(n) + 1.0)) * strategy.chi_n;
    d.sigma *= std::exp(strategy.c_sigma / strategy.d_sigma * (p_sigma_norm / strategy.chi_n - 1.0));

    // Covariance matrix adaptation (Eqs 45-47): rank-one update from the path, rank-mu from all
    // candidates, the negative weights rescaled by n / ||C^-1/2 y||^2 (Eq 46).
    d.p_c = (1.0 - strategy.c_c) * d.p_c;
    if (h_sigma) d.p_c += std::sqrt(strategy.c_c * (2.0 - strategy.c_c) * strategy.mueff) * weighted_step;
    rank_mu.setZero();
    for (std::size_t r = 0; r < lambda; ++r) {
      const Eigen::VectorXd& y = steps[order[r]];
      double w = strategy.weights[static_cast<Eigen::Index>(r)];
      if (w < 0.0) {
        whitened.noalias() = d.inv_sqrt_C * y;
        const double squared = whitened.squaredNorm();
        w = squared > 0.0 ? w * static_cast<double>(n) / squared : 0.0;
      }
      if (w != 0.0) rank_mu.noalias() += w * y * y.transpose();
    }
    const double delta_h = h_sigma ? 0.0 : strategy.c_c * (2.0 - strategy.c_c);
    d.C = (1.0 + strategy.c_1 * delta_h - strategy.c_1 - strategy.c_mu * strategy.weight_sum) * d.C +
          strategy.c_1 * d.p_c * d.p_c.transpose() + strategy.c_mu * rank_mu;

    const bool go_on = run.EndIteration();

    recent_best.push_back(values[order[0]]);
    if (recent_best.size() > strategy.tolfun_window) recent_best.pop_front();
    if (options.stall_generations > 0) {
      // NaN never raises the run's best (IsImprovement ranks it last).
      const double best = run_best.empty() || IsImprovement(values[order[0]], run_best.back())
                              ? values[order[0]]
                              : run_best.back();
      run_best.push_back(best);
      if (run_best.size() > static_cast<std::size_t>(options.stall_generations) + 1) run_best.pop_front();
    }
    if (!go_on) {
      termination = TerminationType::kUserRequested;
      message = "an iteration callback asked to stop";
      break;
    }

    if (!std::isfinite(d.sigma) || !d.C.allFinite()) {
      termination = TerminationType::kFailure;
      message = fmt::format("sigma ({}) or the covariance matrix became non-finite", d.sigma);
      break;
    }
    if (run.iterations() - d.eigen_iteration >= strategy.eigen_interval) {
      d.C = (0.5 * (d.C + d.C.transpose())).eval();
      eigen.compute(d.C);
      if (eigen.info() != Eigen::Success || !(eigen.eigenvalues().minCoeff() > 0.0)) {
        termination = TerminationType::kFailure;
        message = "the covariance matrix lost positive definiteness";
        break;
      }
      d.B = eigen.eigenvectors();
      d.D = eigen.eigenvalues().cwiseSqrt();
      d.eigen_iteration = run.iterations();
      d.RefreshInverseSquareRoot();
    }

    const double condition = (d.D.maxCoeff() / d.D.minCoeff()) * (d.D.maxCoeff() / d.D.minCoeff());
    if (condition > options.max_condition) {
      termination = TerminationType::kFailure;
      message = fmt::format("the condition number of C, {:.3g}, passed max_condition = {:.3g}", condition,
                            options.max_condition);
      break;
    }
    double spread = 0.0;
    for (std::size_t i = 0; i < n; ++i) spread = std::max({spread, std::abs(d.p_c[i]), std::sqrt(d.C(i, i))});
    if (d.sigma * spread < options.x_tolerance) {
      if (restart()) continue;
      termination = TerminationType::kConvergence;
      message = fmt::format("sigma * max(|p_c|, sqrt(diag C)) = {:.3g} fell below x_tolerance = {:.3g}",
                            d.sigma * spread, options.x_tolerance);
      break;
    }
    if (recent_best.size() == strategy.tolfun_window) {
      // Over the recent best values and this generation's values; a non-finite one never stops the run.
      double lo = values[0], hi = values[0];
      for (const double v : recent_best) lo = std::min(lo, v), hi = std::max(hi, v);
      for (const double v : values) lo = std::min(lo, v), hi = std::max(hi, v);
      bool finite = std::isfinite(hi - lo);
      for (const double v : values) finite = finite && std::isfinite(v);
      for (const double v : recent_best) finite = finite && std::isfinite(v);
      if (finite && hi - lo < options.function_tolerance) {
        if (restart()) continue;
        termination = TerminationType::kConvergence;
        message = fmt::format("U-hat ranged by {:.3g} < function_tolerance = {:.3g} over {} generations",
                              hi - lo, options.function_tolerance, strategy.tolfun_window);
        break;
      }
    }
    if (run_best.size() == static_cast<std::size_t>(options.stall_generations) + 1 &&
        !(run_best.back() - run_best.front() > options.stall_tolerance)) {
      if (restart()) continue;
      termination = TerminationType::kConvergence;
      message =
          fmt::format("the best U-hat rose by {:.3g} <= stall_tolerance = {:.3g} over {} generations",
                      run_best.back() - run_best.front(), options.stall_tolerance, options.stall_generations);
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every)) {
      options.on_checkpoint(run.Checkpoint(
          json{{"population", strategy.lambda},
               {"mean", VectorToJson(d.mean)},
               {"sigma", DoubleToJson(d.sigma)},
               {"C", MatrixToJson(d.C)},
               {"B", MatrixToJson(d.B)},
               {"D", VectorToJson(std::span<const double>(d.D.data(), n))},
               {"p_sigma", VectorToJson(std::span<const double>(d.p_sigma.data(), n))},
               {"p_c", VectorToJson(std::span<const double>(d.p_c.data(), n))},
               {"eigen_iteration", d.eigen_iteration},
               {"recent_best", VectorToJson(std::vector<double>(recent_best.begin(), recent_best.end()))},
               {"stream_position", uniforms.position()},
               {"restarts", restarts},
               {"run_first_iteration", run_first_iteration},
               {"run_best", VectorToJson(std::vector<double>(run_best.begin(), run_best.end()))},
               {"start", VectorToJson(start)}}));
    }
  }

  if (restarts > 0)
    message += fmt::format(" (after {} restart{}, population {})", restarts, restarts == 1 ? "" : "s",
                           strategy.lambda);
  run.Finish(termination, std::move(message), summary);
  summary->final_step = d.sigma;
  *theta = summary->best_theta;
}

}  // namespace pegasus
