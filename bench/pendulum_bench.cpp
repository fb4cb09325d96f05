// Pendulum-v1 (envs/pendulum.hpp): the speed of the model and of PEGASUS's U-hat, and the Pegasus side of
// the race against RLtools (issue 7): wall time until the mean return over 100 fresh starts reaches -200,
// and the final policy's mean return, for the shipped default search on one thread.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"

namespace {

using namespace pegasus;

// A trained swing-up (seed 2 of the shipped search, rounded): gain, energy, angle, rate, region, lead, skew.
const Theta kSwingUp = {0.19, 3.9, 7.1, 1.9, 0.6, 1.44, 0.18};

// One 200-step episode under the swing-up policy (observe, act, step, reward), from varied starts.
void BM_PendulumRollout_SwingUp_H200(benchmark::State& state) {
  const Pendulum pendulum;
  const PendulumSwingUpPolicy policy;
  std::int64_t steps = 0;
  double total = 0.0, start = -3.0;
  for (auto _ : state) {
    PendulumState s{start, 0.5};
    start = start > 3.0 ? -3.0 : start + 0.1;
    double ret = 0.0;
    for (int t = 0; t < PendulumConstants::episode_steps; ++t) {
      const double u = policy.act(kSwingUp, pendulum.observe(s));
      ret += pendulum.reward(s, u);
      s = pendulum.step(s, u, {});
    }
    total += ret;
    steps += PendulumConstants::episode_steps;
  }
  // The returns feed a counter, which keeps the rollouts from being optimised away (DoNotOptimize on a
  // double can hand GCC a general register and report garbage).
  state.counters["mean_return"] = total / static_cast<double>(state.iterations());
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PendulumRollout_SwingUp_H200)->Unit(benchmark::kMicrosecond);

// U-hat of the training problem (m = 32 start states, H = 200), on 1 or 2 threads.
void BM_PendulumUhat_m32_H200(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  ThreadPool pool(threads);
  const PegasusEvaluator<Pendulum, PendulumSwingUpPolicy> evaluator(
      Pendulum{}, PendulumSwingUpPolicy{},
      ScenarioSet({.seed = 1, .count = 32, .horizon = 200, .noise_dim = 0, .initial_noise_dim = 2}),
      Discounting{.gamma = 1.0, .horizon = 200});
  double uhat = 0.0;
  for (auto _ : state) uhat = evaluator.evaluate(kSwingUp, &pool);
  state.counters["uhat"] = uhat;
  state.counters["steps_per_s"] =
      benchmark::Counter(32.0 * 200.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PendulumUhat_m32_H200)
    ->Arg(1)
    ->Arg(2)
    ->ArgName("threads")
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// The race: the default search of `pegasus pendulum train` (the race: five numbers on m = 32 stratified
// starts, hill climbing, 150 x 8 proposals, from all gains zero; then the refinement of all seven numbers
// on m = 256, 60 x 8) on one thread, for training seeds 1, 2, 3. Counters: seconds_to_bar (wall time until
// the mean return over 100 fresh starts first reached -200, those checks included; cpu_seconds_to_bar the
// processor time until then, robust on a shared machine), race_mean_return_100 (the race's policy on
// those starts), mean_return_100 (final policy, same starts), mean_return_5000 (final policy on 5000
// other starts, those of summary.json), training_seconds (both stages).
void BM_PendulumRaceToBar(benchmark::State& state) {
  PendulumTrainingOptions options;
  options.seed = static_cast<std::uint64_t>(state.range(0));
  options.threads = 1;
  double to_bar = 0.0, cpu_to_bar = 0.0, race_mean = 0.0, mean = 0.0, training = 0.0, evaluations = 0.0;
  Theta theta;
  for (auto _ : state) {
    const PendulumTrainingResult r = train_pendulum(options);
    theta = r.theta;
    to_bar += r.seconds_to_bar;
    cpu_to_bar += r.cpu_seconds_to_bar;
    race_mean += r.race_mean_return_100;
    mean += r.mean_return_100;
    training += r.summary.wall_seconds + r.refine_summary.wall_seconds;
    evaluations += static_cast<double>(r.evaluations_to_bar);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["seconds_to_bar"] = to_bar / n;
  state.counters["cpu_seconds_to_bar"] = cpu_to_bar / n;
  state.counters["race_mean_return_100"] = race_mean / n;
  state.counters["mean_return_100"] = mean / n;
  state.counters["training_seconds"] = training / n;
  state.counters["evaluations_to_bar"] = evaluations / n;
  // The final policy on 5000 other starts (untimed): a 100-start mean carries about +-8 of sampling noise.
  state.counters["mean_return_5000"] =
      ordered_mean(pendulum_episode_returns(theta, 5000, pendulum_large_evaluation_seed(options.seed)));
}
BENCHMARK(BM_PendulumRaceToBar)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->ArgName("seed")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
