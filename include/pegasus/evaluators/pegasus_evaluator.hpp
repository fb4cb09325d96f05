#pragma once
// PEGASUS evaluation on fixed scenarios (thesis §4.4.2, Eq 4.22):
//   U-hat(theta) = (1/m) sum_i  return of scenario i under pi_theta.
// Work is parallel over (theta, scenario) pairs; each pair writes its own slot and the sum over scenarios
// is taken in scenario order afterwards, so U-hat is bit-identical for any number of threads. Under mpirun
// the pairs are also split across ranks (parallel/mpi.hpp: rank r owns pairs r, r + N, ...; every rank gets
// every pair's return by an allgather and sums in the same order), so it is bit-identical for any number of
// ranks too. Every rank must make the same calls in the same order (they all run the same program).
#include <memory>
#include <span>
#include <vector>

#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/optimizers/objective.hpp"
#include "pegasus/parallel/mpi.hpp"
#include "pegasus/parallel/thread_pool.hpp"

namespace pegasus {

// The fixed-order mean of per-scenario returns.
inline double ordered_mean(std::span<const double> returns) {
  double sum = 0.0;
  for (double r : returns) sum += r;
  return sum / static_cast<double>(returns.size());
}

template <SimulativeModel M, class P>
class PegasusEvaluator {
 public:
  PegasusEvaluator(M model, P policy, ScenarioSet scenarios, Discounting discounting)
      : model_(std::move(model)),
        policy_(std::move(policy)),
        scenarios_(std::move(scenarios)),
        d_(discounting) {
    validate(d_);
    check_noise_dims(model_);
    if (scenarios_.noise_dim() != model_.noise_dim() ||
        scenarios_.initial_noise_dim() != model_.initial_noise_dim())
      throw InputError("scenarios: noise dimensions differ from the model's");
    if (scenarios_.horizon() < d_.horizon) throw InputError("scenarios: hold fewer steps than the horizon");
  }

  const M& model() const { return model_; }
  const P& policy() const { return policy_; }
  const ScenarioSet& scenarios() const { return scenarios_; }
  const Discounting& discounting() const { return d_; }

  double scenario_value(std::span<const double> theta, int i) const {
    return scenario_return(model_, policy_, theta, scenarios_, i, d_);
  }

  // Per-scenario returns of one theta (out.size() == scenarios().size()), on every rank.
  void per_scenario(std::span<const double> theta, std::span<double> out,
                    const ExecutionContext& where = {}) const {
    mpi::distributed_fill(out.first(static_cast<std::size_t>(scenarios_.size())), where,
                          [&](std::size_t i) { return scenario_value(theta, static_cast<int>(i)); });
  }

  double evaluate(std::span<const double> theta, const ExecutionContext& where = {}) const {
    std::vector<double> returns(static_cast<std::size_t>(scenarios_.size()));
    per_scenario(theta, returns, where);
    return ordered_mean(returns);
  }

  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values,
                      const ExecutionContext& where = {}) const {
    const auto m = static_cast<std::size_t>(scenarios_.size());
    std::vector<double> returns(thetas.size() * m);
    mpi::distributed_fill(std::span<double>(returns), where, [&](std::size_t k) {
      return scenario_value(thetas[k / m], static_cast<int>(k % m));
    });
    for (std::size_t k = 0; k < thetas.size(); ++k)
      values[k] = ordered_mean(std::span<const double>(returns.data() + k * m, m));
  }

 private:
  M model_;
  P policy_;
  ScenarioSet scenarios_;
  Discounting d_;
};

// The type-erased theta -> U-hat(theta) that optimizers see.
template <SimulativeModel M, class P>
class PegasusObjective final : public Objective {
 public:
  // The evaluations run on `pool` (null: the calling thread) and are split among `ranks`.
  PegasusObjective(PegasusEvaluator<M, P> evaluator, std::shared_ptr<ThreadPool> pool,
                   mpi::Communicator ranks = mpi::Communicator::job())
      : evaluator_(std::move(evaluator)), pool_(std::move(pool)), ranks_(ranks) {}
  const ParameterSpec& parameters() const override { return evaluator_.policy().parameters(); }
  double evaluate(std::span<const double> theta) override { return evaluator_.evaluate(theta, where()); }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    evaluator_.evaluate_batch(thetas, values, where());
  }
  const PegasusEvaluator<M, P>& evaluator() const { return evaluator_; }

 private:
  PegasusEvaluator<M, P> evaluator_;
  ExecutionContext where() const { return {pool_.get(), ranks_}; }

  std::shared_ptr<ThreadPool> pool_;
  mpi::Communicator ranks_;
};

}  // namespace pegasus
