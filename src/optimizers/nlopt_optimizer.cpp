#include "pegasus/optimizers/nlopt_optimizer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <nlopt.hpp>

#include "pegasus/core/error.hpp"

namespace pegasus {

using nlohmann::json;

std::string_view NloptAlgorithmName(NloptAlgorithm algorithm) {
  switch (algorithm) {
    case NloptAlgorithm::kBobyqa:
      return "bobyqa";
    case NloptAlgorithm::kSbplx:
      return "sbplx";
    case NloptAlgorithm::kCrs2:
      return "crs2";
    case NloptAlgorithm::kEsch:
      return "esch";
  }
  return "unknown";
}

std::optional<NloptAlgorithm> NloptAlgorithmFromName(std::string_view name) {
  for (const auto algorithm :
       {NloptAlgorithm::kBobyqa, NloptAlgorithm::kSbplx, NloptAlgorithm::kCrs2, NloptAlgorithm::kEsch})
    if (NloptAlgorithmName(algorithm) == name) return algorithm;
  return std::nullopt;
}

NloptOptions NloptOptions::ForMethod(std::string_view method) const {
  NloptOptions options = *this;
  if (const auto chosen = NloptAlgorithmFromName(method)) options.algorithm = *chosen;
  return options;
}

bool NloptOptions::IsValid(std::string* error) const {
  if (NloptAlgorithmName(algorithm) == "unknown")
    return RejectOption(error, "algorithm", "one of bobyqa, sbplx, crs2, esch", static_cast<int>(algorithm));
  if (max_evaluations < 1 || max_evaluations > std::numeric_limits<int>::max())
    return RejectOption(error, "max_evaluations", "1 .. 2147483647", static_cast<double>(max_evaluations));
  if (!(initial_step > 0.0 && std::isfinite(initial_step)))
    return RejectOption(error, "initial_step", "a finite value > 0", initial_step);
  if (!(x_tolerance >= 0.0 && std::isfinite(x_tolerance)))
    return RejectOption(error, "x_tolerance", "a finite value >= 0 (0 = off)", x_tolerance);
  if (!(function_tolerance >= 0.0 && std::isfinite(function_tolerance)))
    return RejectOption(error, "function_tolerance", "a finite value >= 0 (0 = off)", function_tolerance);
  if (population < 0 || population > kMaxPointsPerIteration)
    return RejectOption(error, "population",
                        fmt::format("in [0, {}] (0 = NLopt's default)", kMaxPointsPerIteration), population);
  return IsValidFor(NloptAlgorithmName(algorithm), error);
}

namespace {

nlopt::algorithm ToNlopt(NloptAlgorithm algorithm) {
  switch (algorithm) {
    case NloptAlgorithm::kBobyqa:
      return nlopt::LN_BOBYQA;
    case NloptAlgorithm::kSbplx:
      return nlopt::LN_SBPLX;
    case NloptAlgorithm::kCrs2:
      return nlopt::GN_CRS2_LM;
    case NloptAlgorithm::kEsch:
      return nlopt::GN_ESCH;
  }
  return nlopt::LN_BOBYQA;
}

bool IsGlobal(NloptAlgorithm algorithm) {
  return algorithm == NloptAlgorithm::kCrs2 || algorithm == NloptAlgorithm::kEsch;
}

struct LoggedEvaluation {
  Theta theta;
  double value = 0.0;
  double seconds = 0.0;
};

bool SameBits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Everything the NLopt callback touches. The callback must not throw through NLopt's C code, so an
// exception is parked here, NLopt is asked to stop, and Solve rethrows it.
struct NloptRun {
  const NloptOptions& options;
  Objective& objective;
  RunProgress& progress;
  Theta start;
  std::vector<LoggedEvaluation> replay;  // from the checkpoint being resumed
  std::size_t replay_next = 0;
  std::vector<LoggedEvaluation> log;  // every evaluation of this run, replayed ones included
  Theta clamped;                      // scratch: the theta actually evaluated
  const ParameterSpec* spec = nullptr;
  nlopt::opt* optimizer = nullptr;
  std::exception_ptr error;
  bool hit_max_evaluations = false;
  bool stopped_by_callback = false;

  json State() const {
    json entries = json::array();
    for (const auto& e : log)
      entries.push_back(json::array({VectorToJson(e.theta), DoubleToJson(e.value), DoubleToJson(e.seconds)}));
    return json{{"algorithm", NloptAlgorithmName(options.algorithm)},
                {"seed", options.seed},
                {"start", VectorToJson(start)},
                {"log", std::move(entries)}};
  }

  double Evaluate(std::span<const double> theta) {
    if (progress.evaluations() >= options.max_evaluations) {
      hit_max_evaluations = true;
      optimizer->force_stop();
      return HUGE_VAL;
    }
    double value = 0.0;
    double seconds = 0.0;
    const bool replaying = replay_next < replay.size();
    if (replaying) {
      const LoggedEvaluation& logged = replay[replay_next];
      if (!SameBits(logged.theta, theta))
        throw InputError(fmt::format(
            "checkpoint state.log: NLopt's evaluation {} asked for a theta other than the logged one; the "
            "checkpoint was written with other options or another objective",
            replay_next + 1));
      value = logged.value;
      seconds = logged.seconds;
      ++replay_next;
    }
    // NLopt keeps to the bounds; clamping guards the promise that every theta evaluated or returned lies
    // inside them. The log keeps NLopt's own request, which is what a replay compares.
    std::copy(theta.begin(), theta.end(), clamped.begin());
    spec->clamp(clamped);
    if (!replaying) {
      value = objective.evaluate(clamped);
      seconds = progress.Seconds();
    }
    progress.AddEvaluations(1);
    log.push_back({Theta(theta.begin(), theta.end()), value, seconds});
    if (log.size() == 1 && SameBits(theta, start)) progress.set_initial_value(value);
    progress.Offer(clamped, value);
    const bool go_on = progress.EndIteration(seconds);
    if (!replaying && progress.CheckpointDue(options.checkpoint_every))
      options.on_checkpoint(progress.Checkpoint(State(), /*include_history=*/false));
    if (!go_on) {
      stopped_by_callback = true;
      optimizer->force_stop();
    }
    // NLopt minimises; NaN becomes the worst value so that it never attracts the search.
    return std::isnan(value) ? HUGE_VAL : -value;
  }
};

double NloptCallback(unsigned n, const double* x, double* /*gradient*/, void* data) {
  auto& run = *static_cast<NloptRun*>(data);
  try {
    return run.Evaluate(std::span<const double>(x, n));
  } catch (...) {
    run.error = std::current_exception();
    run.optimizer->force_stop();
    return HUGE_VAL;
  }
}

std::vector<LoggedEvaluation> ParseLog(const json& log, std::size_t n) {
  if (!log.is_array()) throw InputError("checkpoint state.log: expected an array");
  std::vector<LoggedEvaluation> entries;
  entries.reserve(log.size());
  for (const auto& row : log) {
    if (!row.is_array() || row.size() != 3)
      throw InputError("checkpoint state.log: expected rows [theta, value, seconds]");
    LoggedEvaluation entry{VectorFromJson(row[0], "state.log theta"),
                           DoubleFromJson(row[1], "state.log value"),
                           DoubleFromJson(row[2], "state.log seconds")};
    if (entry.theta.size() != n)
      throw InputError(fmt::format("checkpoint state.log: expected thetas of size {}", n));
    entries.push_back(std::move(entry));
  }
  return entries;
}

// The global methods sample the whole box, so every bound must be finite.
void CheckGlobalBounds(const NloptOptions& options, const ParameterSpec& spec) {
  if (!IsGlobal(options.algorithm)) return;
  const Theta lower = spec.lower();
  const Theta upper = spec.upper();
  for (std::size_t i = 0; i < spec.size(); ++i)
    if (!std::isfinite(lower[i]) || !std::isfinite(upper[i]))
      throw InputError(fmt::format("parameter {}: the global method {} needs finite bounds, got [{}, {}]",
                                   spec[i].name, NloptAlgorithmName(options.algorithm), lower[i], upper[i]));
}

// The start and the evaluations to replay from a checkpoint's state, which must be this algorithm's and
// this seed's.
void ResumeRun(const json& state, const ParameterSpec& spec, NloptRun* run) {
  const std::string_view name = NloptAlgorithmName(run->options.algorithm);
  const json& algorithm = StateField(state, "algorithm");
  if (!algorithm.is_string() || algorithm.get<std::string>() != name)
    throw InputError(fmt::format("checkpoint state.algorithm: expected \"{}\"", name));
  const auto seed = StateUnsigned(state, "seed");
  if (seed != run->options.seed)
    throw InputError(
        fmt::format("checkpoint state.seed: expected this run's seed {}, got {}", run->options.seed, seed));
  run->start = VectorFromJson(StateField(state, "start"), "state.start");
  if (!spec.contains(run->start))
    throw InputError("checkpoint state.start: expected a theta inside the bounds");
  run->replay = ParseLog(StateField(state, "log"), spec.size());
  run->progress.set_replayed_evaluations(static_cast<std::int64_t>(run->replay.size()));
}

// Bounds, the local methods' first steps, the tolerances (scaled units), the budget and the population.
void Configure(const NloptOptions& options, const ParameterSpec& spec, nlopt::opt* optimizer) {
  const std::size_t n = spec.size();
  const Theta lower = spec.lower();
  const Theta upper = spec.upper();
  const Theta scale = spec.scales();
  optimizer->set_lower_bounds(lower);
  optimizer->set_upper_bounds(upper);
  if (!IsGlobal(options.algorithm)) {
    Theta steps(n);
    for (std::size_t i = 0; i < n; ++i) {
      steps[i] = options.initial_step * scale[i];
      // BOBYQA refuses a trust region wider than half the gap between the bounds. A fixed parameter
      // (lower == upper) is removed by NLopt, and any positive step will do for it.
      if (upper[i] > lower[i]) steps[i] = std::min(steps[i], 0.5 * (upper[i] - lower[i]));
    }
    optimizer->set_initial_step(steps);
  }
  if (options.x_tolerance > 0.0) {
    Theta tolerances(n);
    for (std::size_t i = 0; i < n; ++i) tolerances[i] = options.x_tolerance * scale[i];
    optimizer->set_xtol_abs(tolerances);
  }
  if (options.function_tolerance > 0.0) optimizer->set_ftol_rel(options.function_tolerance);
  optimizer->set_maxeval(static_cast<int>(options.max_evaluations));
  if (options.population > 0 && IsGlobal(options.algorithm))
    optimizer->set_population(static_cast<unsigned>(options.population));
}

// Runs NLopt from the start and says why it stopped, in NLopt's own terms; a stop the callback forced is
// told by the run's flags, read afterwards.
void Optimize(const NloptOptions& options, NloptRun& run, nlopt::opt& optimizer, TerminationType* termination,
              std::string* message) {
  Theta x = run.start;
  double minimum = 0.0;
  nlopt::srand(static_cast<unsigned long>(options.seed));
  try {
    switch (optimizer.optimize(x, minimum)) {
      case nlopt::MAXEVAL_REACHED:
        *termination = TerminationType::kMaxEvaluations;
        *message = fmt::format("used max_evaluations = {}", options.max_evaluations);
        break;
      case nlopt::FTOL_REACHED:
        *termination = TerminationType::kConvergence;
        *message = fmt::format("NLopt: relative change of U-hat below function_tolerance = {:.3g}",
                               options.function_tolerance);
        break;
      case nlopt::XTOL_REACHED:
        *termination = TerminationType::kConvergence;
        *message = fmt::format("NLopt: step below x_tolerance = {:.3g} (scaled units)", options.x_tolerance);
        break;
      default:
        *termination = TerminationType::kConvergence;
        *message = "NLopt reported success";
        break;
    }
  } catch (const nlopt::forced_stop&) {
    if (!run.error && !run.hit_max_evaluations && !run.stopped_by_callback)
      *message = "NLopt was stopped for an unknown reason";
  } catch (const nlopt::roundoff_limited&) {
    *termination = TerminationType::kConvergence;
    *message = "NLopt: progress limited by roundoff";
  } catch (const std::invalid_argument& e) {
    throw InputError(
        fmt::format("{}: NLopt rejected the problem: {}", NloptAlgorithmName(options.algorithm), e.what()));
  } catch (const std::runtime_error& e) {
    *message = fmt::format("NLopt failed: {}", e.what());
  }
}

// What the callback recorded overrides NLopt's reason: its error is rethrown, a callback's stop and the
// evaluation budget are named, and a replay NLopt did not finish means a foreign checkpoint.
void SettleStop(const NloptOptions& options, const NloptRun& run, TerminationType* termination,
                std::string* message) {
  if (run.error) std::rethrow_exception(run.error);
  if (run.stopped_by_callback) {
    *termination = TerminationType::kUserRequested;
    *message = "an iteration callback asked to stop";
  } else if (run.hit_max_evaluations) {
    *termination = TerminationType::kMaxEvaluations;
    *message = fmt::format("used max_evaluations = {}", options.max_evaluations);
  }
  if (run.replay_next < run.replay.size())
    throw InputError(
        fmt::format("checkpoint state.log: NLopt stopped after {} evaluations but the log holds {}; "
                    "the checkpoint was written with other options",
                    run.replay_next, run.replay.size()));
}

}  // namespace

void Solve(const NloptOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary) {
  std::string error;
  const std::string_view name = NloptAlgorithmName(options.algorithm);
  if (!options.IsValid(&error)) throw InputError(fmt::format("{} options: {}", name, error));
  if (theta == nullptr || summary == nullptr)
    throw InputError(fmt::format("{}: theta and summary must be non-null", name));

  const ParameterSpec& spec = objective.parameters();
  const std::size_t n = spec.size();
  if (n == 0) throw InputError(fmt::format("{}: NLopt needs at least one parameter", name));
  CheckGlobalBounds(options, spec);

  RunProgress progress(std::string(name), spec, options.callbacks);
  NloptRun run{options, objective, progress, {}, {}, 0, {}, Theta(n), &spec, nullptr, nullptr, false};
  if (options.resume_from)
    ResumeRun(progress.Resume(*options.resume_from, /*restore_counters=*/false), spec, &run);
  else
    run.start = StartingTheta(spec, *theta);
  run.log.reserve(std::max<std::size_t>(run.replay.size(), 1024));

  nlopt::opt optimizer(ToNlopt(options.algorithm), static_cast<unsigned>(n));
  run.optimizer = &optimizer;
  Configure(options, spec, &optimizer);
  optimizer.set_min_objective(NloptCallback, &run);

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  Optimize(options, run, optimizer, &termination, &message);
  SettleStop(options, run, &termination, &message);
  progress.Finish(termination, std::move(message), summary);
  *theta = summary->best_theta;
}

}  // namespace pegasus
