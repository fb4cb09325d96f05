#include "pegasus/optimizers/optimizer.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {

constexpr std::array<std::string_view, 9> kMethodNames = {
    "exhaustive", "gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch", "cmaes", "ars"};

// The NLopt options with the algorithm named by `method`.
NloptOptions NloptOptionsFor(const OptimizerOptions& options, NloptAlgorithm algorithm) {
  NloptOptions nlopt = options.nlopt;
  nlopt.algorithm = algorithm;
  return nlopt;
}

}  // namespace

std::span<const std::string_view> OptimizerMethodNames() { return kMethodNames; }

void OptimizerOptions::SetCheckpointing(std::int64_t checkpoint_every, CheckpointCallback on_checkpoint,
                                        std::optional<nlohmann::json> resume_from) {
  exhaustive.checkpoint_every = gradient.checkpoint_every = hill_climbing.checkpoint_every =
      nlopt.checkpoint_every = cmaes.checkpoint_every = ars.checkpoint_every = checkpoint_every;
  exhaustive.on_checkpoint = gradient.on_checkpoint = hill_climbing.on_checkpoint = nlopt.on_checkpoint =
      cmaes.on_checkpoint = ars.on_checkpoint = std::move(on_checkpoint);
  exhaustive.resume_from = gradient.resume_from = hill_climbing.resume_from = nlopt.resume_from =
      cmaes.resume_from = ars.resume_from = std::move(resume_from);
}

std::int64_t OptimizerOptions::IterationLimit() const {
  if (method == "gradient") return gradient.max_iterations;
  if (method == "hill-climb") return hill_climbing.max_iterations;
  if (method == "cmaes") return cmaes.max_iterations;
  if (method == "ars") return ars.max_iterations;
  if (method == "exhaustive")
    return (exhaustive.max_policies + exhaustive.block_size - 1) / exhaustive.block_size;
  return nlopt.max_evaluations;
}

void OptimizerOptions::SetCallbacks(const IterationCallbacks& callbacks) {
  exhaustive.callbacks = gradient.callbacks = hill_climbing.callbacks = nlopt.callbacks = cmaes.callbacks =
      ars.callbacks = callbacks;
}

bool OptimizerOptions::IsValid(std::string* error) const {
  std::string inner;
  auto prefixed = [&](bool valid, std::string_view prefix) {
    if (!valid && error) *error = fmt::format("{}.{}", prefix, inner);
    return valid;
  };
  if (method == "exhaustive") return prefixed(exhaustive.IsValid(&inner), "exhaustive");
  if (method == "gradient") return prefixed(gradient.IsValid(&inner), "gradient");
  if (method == "hill-climb") return prefixed(hill_climbing.IsValid(&inner), "hill_climbing");
  if (method == "cmaes") return prefixed(cmaes.IsValid(&inner), "cmaes");
  if (method == "ars") return prefixed(ars.IsValid(&inner), "ars");
  if (const auto algorithm = NloptAlgorithmFromName(method))
    return prefixed(NloptOptionsFor(*this, *algorithm).IsValid(&inner), "nlopt");
  if (error)
    *error = fmt::format("method: expected one of {}, got \"{}\"", fmt::join(kMethodNames, ", "), method);
  return false;
}

void Solve(const OptimizerOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("optimizer options: " + error);
  // Every method but exhaustive search moves theta by real steps: an integer parameter (a table's action)
  // would come back as a fraction.
  const ParameterSpec& spec = objective.parameters();
  if (const std::size_t i = spec.first_integer(); i < spec.size() && options.method != "exhaustive")
    throw InputError(fmt::format(
        "optimizer method {}: searches real numbers, but parameter '{}' is an integer (a table entry); "
        "expected exhaustive",
        options.method, spec[i].name));
  if (options.method == "exhaustive") return Solve(options.exhaustive, objective, theta, summary);
  if (options.method == "gradient") return Solve(options.gradient, objective, theta, summary);
  if (options.method == "hill-climb") return Solve(options.hill_climbing, objective, theta, summary);
  if (options.method == "cmaes") return Solve(options.cmaes, objective, theta, summary);
  if (options.method == "ars") return Solve(options.ars, objective, theta, summary);
  Solve(NloptOptionsFor(options, *NloptAlgorithmFromName(options.method)), objective, theta, summary);
}

}  // namespace pegasus
