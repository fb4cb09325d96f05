#pragma once
// The one optimizer section of every training command. A section `PREFIX` declares `PREFIX.method` (every
// method of OptimizerMethodNames(), or the subset a command allows) and each method's options under
// `PREFIX.<method section>.<field>`, named as the Options structs name them:
//
//   [optimizer]                       # or --optimizer.method hill-climb on the command line
//   method = "hill-climb"
//   hill_climbing.proposals_per_iteration = 8
//
// The defaults are the values of the OptimizerOptions the command passes in (its trainer's Options struct
// holds them: defaults live once). Seeds and checkpointing are not options: the trainer derives seeds from
// the run's --seed, and the run directory owns checkpoints. Each field is range-checked when it is set;
// the selected method's cross-field checks (OptimizerOptions::IsValid) run in ConfigSchema::validate() and
// name the field as the user wrote it (`--optimizer.gradient.max-step` or `config.toml:4`).
#include <string>
#include <vector>

#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus {

// The methods a continuous policy class can run (every method but exhaustive search, which needs a finite
// class); without finite bounds on every parameter (a network's weights, a linear policy's gains) not the
// global crs2 and esch either, which need them.
std::vector<std::string> continuous_class_methods(bool finite_bounds);

// Declares section `prefix` with `defaults`' values. `methods` limits `prefix.method`'s choices (empty: all);
// every method's options are declared (a resolved config.toml lists them all, and stays a valid input for any
// command). With `allow_none`, `prefix.method` may also be "none" (a stage that does not run).
void declare_optimizer_options(ConfigSchema& schema, const std::string& prefix,
                               const OptimizerOptions& defaults, std::vector<std::string> methods = {},
                               bool allow_none = false);

// The section's values over `options` (fields the section does not declare, such as seeds, are kept).
void read_optimizer_options(const ConfigSchema& schema, const std::string& prefix, OptimizerOptions* options);

}  // namespace pegasus
