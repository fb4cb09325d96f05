#pragma once
// PEGASUS U-hat of a built-in C++ model and policy class on fixed scenarios, on its own thread pool: the
// Objective behind BicycleProblem, PendulumProblem, the gridworlds and HoverProblem.
#include <fmt/format.h>

#include <memory>

#include "common.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/parallel/thread_pool.hpp"

namespace pegasus::python {

ScenarioSet make_scenario_set(SeedArg seed, std::int64_t count, std::int64_t horizon, std::int64_t noise_dim,
                              std::int64_t initial_noise_dim, const std::string& variant,
                              const char* count_name = "count");

// A pool of `threads` (ValueError naming `threads` outside [1, 1024], as --threads).
inline std::shared_ptr<ThreadPool> make_pool(std::int64_t threads) {
  if (threads < 1 || threads > 1024)
    throw py::value_error(fmt::format("threads: expected an integer in [1, 1024], got {}", threads));
  return std::make_shared<ThreadPool>(static_cast<int>(threads));
}

template <SimulativeModel M, class P>
class BuiltinProblem final : public Objective {
 public:
  BuiltinProblem(M model, P policy, SeedArg seed, std::int64_t scenarios, std::int64_t horizon, double gamma,
                 const std::string& variant, std::int64_t threads)
      : pool_(make_pool(threads)),
        evaluator_(model, std::move(policy),
                   make_scenario_set(seed, scenarios, horizon, model.noise_dim(), model.initial_noise_dim(),
                                     variant, "scenarios"),
                   checked_discounting(gamma, horizon)) {}
  BuiltinProblem(PegasusEvaluator<M, P> evaluator, std::shared_ptr<ThreadPool> pool)
      : pool_(std::move(pool)), evaluator_(std::move(evaluator)) {}
  const ParameterSpec& parameters() const override { return evaluator_.policy().parameters(); }
  double evaluate(std::span<const double> theta) override { return evaluator_.evaluate(theta, pool_.get()); }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    evaluator_.evaluate_batch(thetas, values, pool_.get());
  }
  std::vector<double> returns(const Theta& theta) const {
    std::vector<double> out(static_cast<std::size_t>(evaluator_.scenarios().size()));
    evaluator_.per_scenario(theta, out, pool_.get());
    return out;
  }
  const PegasusEvaluator<M, P>& evaluator() const { return evaluator_; }

 private:
  static Discounting checked_discounting(double gamma, std::int64_t horizon) {
    if (!(gamma >= 0.0 && gamma <= 1.0))
      throw py::value_error(fmt::format("gamma: expected a number in [0, 1], got {}", gamma));
    return Discounting{gamma, static_cast<int>(horizon)};
  }
  std::shared_ptr<ThreadPool> pool_;
  PegasusEvaluator<M, P> evaluator_;
};

// problem.returns(theta): the per-scenario returns, with the GIL released.
template <class Problem>
void bind_returns(py::class_<Problem, Objective>& c) {
  c.def(
      "returns",
      [](const Problem& p, ArrayLikeArg theta) {
        const Theta t = as_theta(theta, "theta", p.parameters());
        std::vector<double> r;
        {
          ReleaseGilInterruptibly release;
          r = p.returns(t);
        }
        return vector_array(r);
      },
      py::arg("theta"), "Per-scenario returns of one theta (U-hat is their mean, summed in scenario order).");
}

}  // namespace pegasus::python
