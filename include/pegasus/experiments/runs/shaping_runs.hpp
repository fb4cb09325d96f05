#pragma once
// The shaping experiments of thesis chapter 3 written to a run directory (the `shaping gridworld`, `shaping
// flags` and `shaping progress-bonus` commands map their options onto these; experiments/ computes):
//   run_shaping_learning        Sarsa's learning curves with each potential (Figs 3.2, 3.3): curves.csv,
//                               runs.csv, the binned charts, summary.json; each finished run is checkpointed
//                               and a resumed run reads them back;
//   run_shaping_progress_bonus  the §3.1 bug shown by learning: the greedy policies printed to `out`, and
//                               summary.json and learning_curves.csv in `run_dir` when one is given.
#include <ostream>

#include "pegasus/experiments/shaping_experiment.hpp"
#include "pegasus/experiments/shaping_progress_bonus.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

void run_shaping_learning(const ShapingExperimentOptions& options, RunSink& sink);
void run_shaping_progress_bonus(const ProgressBonusOptions& options, std::ostream& out,
                                const RunDirectory* run_dir);

}  // namespace pegasus
