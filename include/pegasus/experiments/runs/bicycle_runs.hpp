#pragma once
// The bicycle experiments of thesis §4.6-4.7 written to a run directory through a RunSink (the `bicycle`
// commands map their options onto these; experiments/bicycle_experiment.hpp computes):
//   run_bicycle_study     trials of PEGASUS training, each policy ridden to the goal, and the two lessons;
//   run_bicycle_training  one training (policy.json), its rides when rides_after is given;
//   run_bicycle_rides     a policy ridden to the goal;
//   run_bicycle_variance  U-hat of one policy over independent scenario sets of each variant (§4.7).
#include <cstdint>

#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

void run_bicycle_study(const BicycleExperimentOptions& options, RunSink& sink, ThreadPool& pool);
void run_bicycle_training(const BicycleTrainingOptions& options, const BicycleRideOptions* rides_after,
                          RunSink& sink, ThreadPool& pool);
void run_bicycle_rides(const Theta& theta, const BicycleRideOptions& riding, RunSink& sink, ThreadPool& pool);
void run_bicycle_variance(const Theta& theta, BicycleTrainingOptions options, int sets, std::uint64_t seed,
                          RunSink& sink, ThreadPool& pool);

}  // namespace pegasus
