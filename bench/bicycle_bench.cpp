// The bicycle simulator (thesis §4.6): steps per second on one core.
//   BM_BicycleStep_Fast_1M            Bicycle::step, 1e6 consecutive steps under a fixed linear controller
//   BM_BicycleStep_Reference_1M       the plain transcription of bike.c kept in tests/bicycle, same workload
//   BM_BicycleStep_ScenarioNoise_1M   Bicycle::step as PEGASUS uses it: p drawn from a scenario set (the
//                                     counter-based generator, ScenarioSet::step_noise) before every step
//   BM_BicycleRollout_Policy15_H500   scenario_return: the 15-feature sigmoid policy, counter-based noise,
//                                     shaping, 500 steps; one scenario per iteration
//   BM_BicycleUhat_m30_H500/threads   one PEGASUS U-hat (30 scenarios x 500 steps) on 1 or 2 threads, as the
//                                     training computes it (bicycle_uhat: rollouts four at a time in
//                                     lockstep)
//   BM_BicycleUhat_OneAtATime_m30_H500  the same U-hat by PegasusEvaluator, one rollout at a time (1 thread)
//   BM_BicycleUhatBatch_31x30_H500    a gradient's batch: 31 thetas (the balancing policy and +-0.05 on each
//   of
//                                     its first 15 weights) x 30 scenarios x 500 steps, PegasusEvaluator's
//                                     evaluate_batch on 1 thread; the C++ side of bench/python_bench.py's
//                                     numpy-bicycle comparison
// Every benchmark reports steps_per_s (simulated bicycle steps per wall second).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>

#include "../tests/bicycle/bicycle_reference.hpp"
#include "pegasus/envs/bicycle.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

constexpr int kSteps = 1'000'000;

double control(const BicycleState& s) {
  return std::clamp(10 * s.omega + 5 * s.omega_dot - 5 * s.theta - 0.3 * s.theta_dot, -2.0, 2.0);
}

template <class Step>
void run_steps(benchmark::State& state, Step&& step) {
  const Bicycle bike;
  const std::array<double, 5> p0 = {0.7, 0.4, 0.6, 0.5, 0.3};
  const BicycleState start = bike.initial_state(p0);
  std::uint64_t steps = 0;
  for (auto _ : state) {
    BicycleState s = start;
    double p = 0.5;
    for (int t = 0; t < kSteps; ++t) {
      p = p < 0.9 ? p + 0.013 : p - 0.85;  // a cheap deterministic noise sequence
      s = step(bike, s, control(s), p);
      if (bike.terminal(s)) s = start;
    }
    benchmark::DoNotOptimize(s);
    steps += kSteps;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}

void BM_BicycleStep_Fast_1M(benchmark::State& state) {
  run_steps(state, [](const Bicycle& bike, const BicycleState& s, double T, double p) {
    return bike.step(s, {T, 0.0}, std::span<const double>(&p, 1));
  });
}
BENCHMARK(BM_BicycleStep_Fast_1M)->Unit(benchmark::kMillisecond);

void BM_BicycleStep_Reference_1M(benchmark::State& state) {
  run_steps(state, [](const Bicycle& bike, const BicycleState& s, double T, double p) {
    return bicycle_reference::step(bike, s, T, 0.0, p);
  });
}
BENCHMARK(BM_BicycleStep_Reference_1M)->Unit(benchmark::kMillisecond);

// The same stepping with each step's p drawn from the scenario set (one counter-based draw per step, as
// scenario_return does), so the figure includes the noise draw of the deterministic simulative model.
void BM_BicycleStep_ScenarioNoise_1M(benchmark::State& state) {
  const Bicycle bike;
  const std::array<double, 5> p0 = {0.7, 0.4, 0.6, 0.5, 0.3};
  const BicycleState start = bike.initial_state(p0);
  constexpr int kHorizon = 1000;
  const ScenarioSet scenarios(
      {.seed = 3, .count = kSteps / kHorizon, .horizon = kHorizon, .noise_dim = 1, .initial_noise_dim = 5});
  std::uint64_t steps = 0;
  for (auto _ : state) {
    BicycleState s = start;
    double p = 0.0;
    for (int i = 0; i < scenarios.size(); ++i) {
      for (int t = 0; t < kHorizon; ++t) {
        scenarios.step_noise(i, t, std::span<double>(&p, 1));
        s = bike.step(s, {control(s), 0.0}, std::span<const double>(&p, 1));
        if (bike.terminal(s)) s = start;
      }
    }
    benchmark::DoNotOptimize(s);
    steps += kSteps;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BicycleStep_ScenarioNoise_1M)->Unit(benchmark::kMillisecond);

void BM_BicycleRollout_Policy15_H500(benchmark::State& state) {
  const Bicycle bike(BicycleTrainingOptions::default_bicycle());
  const auto model = shape(bike, BicycleProgressPotential{bike, 1.0}, 0.998);
  const BicyclePolicy policy = make_bicycle_policy();
  const Theta theta = bicycle_balancing_theta();
  const ScenarioSet scenarios(
      {.seed = 1, .count = 64, .horizon = 500, .noise_dim = 1, .initial_noise_dim = 5});
  const Discounting d{.gamma = 0.998, .horizon = 500};
  std::uint64_t steps = 0;
  int i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(scenario_return(model, policy, theta, scenarios, i, d));
    i = (i + 1) % scenarios.size();
    steps += 500;  // the balancing policy never falls within 5 s
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BicycleRollout_Policy15_H500)->Unit(benchmark::kMicrosecond);

void BM_BicycleUhat_m30_H500(benchmark::State& state) {
  BicycleTrainingOptions o;
  o.threads = static_cast<int>(state.range(0));
  ThreadPool pool(o.threads);
  const Theta theta = bicycle_balancing_theta();
  std::uint64_t steps = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(bicycle_uhat(o, theta, &pool));
    steps += 30 * 500;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BicycleUhat_m30_H500)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_BicycleUhat_OneAtATime_m30_H500(benchmark::State& state) {
  const BicycleTrainingOptions o;
  const Bicycle bike(o.bicycle);
  const PegasusEvaluator evaluator(shape(bike, BicycleProgressPotential{bike, o.shaping_per_metre}, o.gamma),
                                   make_bicycle_policy(),
                                   ScenarioSet({.seed = o.seed,
                                                .count = o.scenarios,
                                                .horizon = o.horizon,
                                                .noise_dim = 1,
                                                .initial_noise_dim = 5}),
                                   Discounting{.gamma = o.gamma, .horizon = o.horizon});
  const Theta theta = bicycle_balancing_theta();
  std::uint64_t steps = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(evaluator.evaluate(theta));
    steps += 30 * 500;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BicycleUhat_OneAtATime_m30_H500)->Unit(benchmark::kMillisecond);

void BM_BicycleUhatBatch_31x30_H500(benchmark::State& state) {
  const BicycleTrainingOptions o;
  const Bicycle bike(o.bicycle);
  const PegasusEvaluator evaluator(
      shape(bike, BicycleProgressPotential{bike, o.shaping_per_metre}, o.gamma), make_bicycle_policy(),
      ScenarioSet({.seed = 1, .count = 30, .horizon = 500, .noise_dim = 1, .initial_noise_dim = 5}),
      Discounting{.gamma = o.gamma, .horizon = 500});
  std::vector<Theta> thetas(31, bicycle_balancing_theta());
  for (std::size_t k = 0; k < 15; ++k) {
    thetas[1 + 2 * k][k] += 0.05;
    thetas[2 + 2 * k][k] -= 0.05;
  }
  std::vector<double> values(thetas.size());
  std::uint64_t steps = 0;
  for (auto _ : state) {
    evaluator.evaluate_batch(thetas, values);
    benchmark::DoNotOptimize(values.data());
    steps += 31 * 30 * 500;  // an upper bound: rollouts that fall stop early
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BicycleUhatBatch_31x30_H500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pegasus
