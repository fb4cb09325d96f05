// Exhaustive search over all 4^8 = 65536 table policies of the POMDP gridworld at m = 32 (thesis §4.6),
// and U-hat evaluation throughput with 1 and 2 threads.
//   BM_ExhaustiveNaiveLoop      the plain nested loop (policies x scenarios x steps), noise pre-drawn,
//                               the step inlined: the reference the shared-trajectory search must beat.
//   BM_ExhaustiveSharedSearch   TablePolicyValues (shared trajectories, branch only on visited
//                               observations) with 1 or 2 threads.
// Both report naive_steps_per_s: the naive loop's step count divided by the wall time, so the ratio of the
// two counters is the speed-up at equal work.
#include <benchmark/benchmark.h>

#include <vector>

#include "pegasus/envs/pomdp_gridworld.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/evaluators/table_policy_values.hpp"

namespace pegasus {
namespace {

constexpr int kM = 32;
const Discounting kD{.gamma = 0.99, .horizon = 100};

ScenarioSet scenarios() {
  return ScenarioSet({.seed = 2024, .count = kM, .horizon = 100, .noise_dim = 1, .initial_noise_dim = 0});
}

// Returns the number of simulated steps; writes U-hat of every policy.
std::uint64_t naive_loop(const PomdpGridworld& g, const std::vector<double>& noise,
                         std::vector<double>& values) {
  std::uint64_t steps = 0;
  const int policies = 65536;
  int table[8];
  for (int k = 0; k < policies; ++k) {
    for (int o = 0, r = k; o < 8; ++o, r /= 4) table[o] = r % 4;
    double sum = 0.0;
    for (int i = 0; i < kM; ++i) {
      int s = g.start();
      double ret = 0.0, weight = 1.0;
      const double* p = noise.data() + static_cast<std::size_t>(i) * 100;
      for (int t = 0; t < 100 && !g.terminal(s); ++t) {
        s = g.step(s, table[g.observe(s)], std::span<const double>(p + t, 1));
        ret -= weight;
        weight *= kD.gamma;
        ++steps;
      }
      sum += ret;
    }
    values[static_cast<std::size_t>(k)] = sum / kM;
  }
  return steps;
}

std::vector<double> noise_table(const ScenarioSet& set) {
  std::vector<double> noise(static_cast<std::size_t>(kM) * 100);
  for (int i = 0; i < kM; ++i)
    for (int t = 0; t < 100; ++t)
      set.step_noise(i, t, std::span<double>(&noise[static_cast<std::size_t>(i * 100 + t)], 1));
  return noise;
}

std::uint64_t naive_step_count() {
  static const std::uint64_t steps = [] {
    PomdpGridworld g;
    std::vector<double> values(65536);
    return naive_loop(g, noise_table(scenarios()), values);
  }();
  return steps;
}

void BM_ExhaustiveNaiveLoop(benchmark::State& state) {
  PomdpGridworld g;
  const auto noise = noise_table(scenarios());
  std::vector<double> values(65536);
  std::uint64_t steps = 0;
  for (auto _ : state) {
    steps = naive_loop(g, noise, values);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["naive_steps_per_s"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ExhaustiveNaiveLoop)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_ExhaustiveSharedSearch(benchmark::State& state) {
  PomdpGridworld g;
  const ScenarioSet set = scenarios();
  ThreadPool pool(static_cast<int>(state.range(0)));
  std::vector<double> values(65536);
  std::uint64_t leaves = 0;
  for (auto _ : state) {
    TablePolicyValues search(g, 8, set, kD);  // includes reading the scenarios' noise
    leaves = search.compute(values, &pool);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["leaves"] = static_cast<double>(leaves);
  state.counters["naive_steps_per_s"] = benchmark::Counter(static_cast<double>(naive_step_count()),
                                                           benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ExhaustiveSharedSearch)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// U-hat of 256 policies on 32 scenarios through the generic evaluator (the path every optimizer uses).
void BM_UhatBatchGridworld(benchmark::State& state) {
  PomdpGridworld g;
  TablePolicy pi(8, 4);
  PegasusEvaluator ev(g, pi, scenarios(), kD);
  ThreadPool pool(static_cast<int>(state.range(0)));
  std::vector<Theta> thetas;
  for (std::uint64_t k = 0; k < 256; ++k) thetas.push_back(pi.theta_of_index(k * 251));
  std::vector<double> values(thetas.size());
  for (auto _ : state) {
    ev.evaluate_batch(thetas, values, &pool);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["policies_per_s"] =
      benchmark::Counter(static_cast<double>(thetas.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_UhatBatchGridworld)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace
}  // namespace pegasus
