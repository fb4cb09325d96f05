#pragma once
// Naive Monte Carlo evaluation (thesis §4.2.2, Eq 4.10): every evaluation draws fresh randomness, so two
// policies never share trajectories. The estimate is stochastic in theta, which is the point of
// Proposition 8; it is still reproducible: evaluation number c, rollout i draws from the stream
// (mix(seed, c), i), and a batch numbers its thetas consecutively.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {

template <GenerativeModel M, class P>
class MonteCarloEvaluator {
 public:
  MonteCarloEvaluator(M model, P policy, int rollouts, Discounting discounting, std::uint64_t seed)
      : model_(std::move(model)),
        policy_(std::move(policy)),
        rollouts_(rollouts),
        d_(discounting),
        seed_(seed) {
    validate(d_);
    if (rollouts < 1) throw InputError("monte carlo: expected m >= 1 rollouts per evaluation");
  }

  const P& policy() const { return policy_; }
  std::uint64_t evaluations() const { return calls_; }

  // The estimate that evaluation number `call` gives theta (pure: no counter advanced).
  double evaluate_at(std::span<const double> theta, std::uint64_t call) const {
    double sum = 0.0;
    for (int i = 0; i < rollouts_; ++i) sum += rollout(theta, call, i);
    return sum / static_cast<double>(rollouts_);
  }

  // Under mpirun the work is split across ranks like PegasusEvaluator's (parallel/mpi.hpp): the rollouts of
  // a single evaluation, the thetas of a batch. Each estimate is the rollout-order sum of evaluate_at, so the
  // numbers are the same for any number of ranks and threads.
  double evaluate(std::span<const double> theta, const ExecutionContext& where = {}) {
    std::vector<double> returns(static_cast<std::size_t>(rollouts_));
    const std::uint64_t call = calls_++;
    mpi::distributed_fill(std::span<double>(returns), where,
                          [&](std::size_t i) { return rollout(theta, call, static_cast<int>(i)); });
    double sum = 0.0;
    for (double r : returns) sum += r;
    return sum / static_cast<double>(rollouts_);
  }

  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values,
                      const ExecutionContext& where = {}) {
    const std::uint64_t first = calls_;
    mpi::distributed_fill(values.first(thetas.size()), where,
                          [&](std::size_t k) { return evaluate_at(thetas[k], first + k); });
    calls_ += thetas.size();
  }

 private:
  double rollout(std::span<const double> theta, std::uint64_t call, int i) const {
    UniformStream rng(mix_seed(seed_, call), static_cast<std::uint32_t>(i));
    return sampled_return(model_, policy_, theta, rng, d_);
  }

  M model_;
  P policy_;
  int rollouts_;
  Discounting d_;
  std::uint64_t seed_;
  std::uint64_t calls_ = 0;
};

template <GenerativeModel M, class P>
class MonteCarloObjective final : public Objective {
 public:
  // The evaluations run on `pool` (null: the calling thread) and are split among `ranks`.
  MonteCarloObjective(MonteCarloEvaluator<M, P> evaluator, std::shared_ptr<ThreadPool> pool,
                      mpi::Communicator ranks = mpi::Communicator::job())
      : evaluator_(std::move(evaluator)), pool_(std::move(pool)), ranks_(ranks) {}
  const ParameterSpec& parameters() const override { return evaluator_.policy().parameters(); }
  double evaluate(std::span<const double> theta) override { return evaluator_.evaluate(theta, where()); }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    evaluator_.evaluate_batch(thetas, values, where());
  }

 private:
  MonteCarloEvaluator<M, P> evaluator_;
  ExecutionContext where() const { return {pool_.get(), ranks_}; }

  std::shared_ptr<ThreadPool> pool_;
  mpi::Communicator ranks_;
};

}  // namespace pegasus
