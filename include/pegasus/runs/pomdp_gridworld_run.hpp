#pragma once
// `pomdp-gridworld` as a library function: the POMDP gridworld experiment of thesis §4.6 (Fig 4.5b;
// experiments/pomdp_gridworld_experiment.hpp) written to a run directory: trials.csv, results.csv, the value
// and uniform-deviation charts, summary.json; checkpointed after every trial and resumed from it.
#include "pegasus/experiments/pomdp_gridworld_experiment.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

void run_pomdp_gridworld_study(const PomdpGridworldOptions& options, RunSink& sink);

}  // namespace pegasus
