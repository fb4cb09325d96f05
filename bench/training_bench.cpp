// End-to-end training time of the experiments (BENCHMARKS.md, "End-to-end training"): each shipped config's
// training through the library, once, on one thread. Where the shipped config runs for minutes, a stated
// fraction of it runs (the name says which; the time scales linearly with independent trials).
#include <benchmark/benchmark.h>

#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/experiments/pomdp_gridworld_experiment.hpp"
#include "pegasus/experiments/shaping_experiment.hpp"

namespace {

using namespace pegasus;

// experiments/pomdp-gridworld-demo.toml (m = 1 .. 64, PEGASUS, hashed model, Monte Carlo) with 2 of its 20
// trials: the demo takes 10 times as long (the trials are independent and equally sized).
void BM_Train_PomdpGridworld_Demo_2of20Trials(benchmark::State& state) {
  PomdpGridworldOptions o;
  o.trials = 2;
  o.montecarlo_max_m = 8;
  for (auto _ : state) benchmark::DoNotOptimize(run_pomdp_gridworld(o).records.size());
  state.counters["training_seconds"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Train_PomdpGridworld_Demo_2of20Trials)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// experiments/shaping-gridworld-10.toml (Fig 3.2a): Sarsa, 40 runs x 10000 trials x 3 potentials.
void BM_Train_ShapingGridworld10(benchmark::State& state) {
  ShapingExperimentOptions o;
  o.size = 10;
  o.trials = 10000;
  for (auto _ : state) benchmark::DoNotOptimize(run_shaping_experiment(o).runs.size());
  state.counters["training_seconds"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Train_ShapingGridworld10)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// One of the 10 trainings of experiments/bicycle.toml (seed 1; m = 30, H = 500, gradient ascent of at most
// 200 iterations, which stops earlier by its step-size test; optimizer_iterations says how many ran).
void BM_Train_Bicycle_OnePolicy(benchmark::State& state) {
  const BicycleTrainingOptions o;
  std::int64_t iterations = 0;
  for (auto _ : state) iterations += train_bicycle(o).summary.iterations;
  state.counters["training_seconds"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["optimizer_iterations"] = static_cast<double>(iterations);
}
BENCHMARK(BM_Train_Bicycle_OnePolicy)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
