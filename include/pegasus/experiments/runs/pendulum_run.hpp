#pragma once
// `pendulum train` as a library function: PEGASUS on Gymnasium's Pendulum-v1 (experiments/
// pendulum_experiment.hpp), timed to its bar, written to a run directory: learning_curve.csv, bar_checks.csv,
// episode_returns.csv, the chart, policy.json, summary.json (and the wall times to the bar as timings).
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

void run_pendulum_training(const PendulumTrainingOptions& options, RunSink& sink, ThreadPool& pool);

// Its config section (the `pendulum train` command's fields).
void declare_pendulum_training_config(ConfigSchema& s);
PendulumTrainingOptions read_pendulum_training_config(const ConfigSchema& c, std::uint64_t seed, int threads);

}  // namespace pegasus
