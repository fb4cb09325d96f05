#pragma once
// The config sections of the shaping experiments (experiments/runs/shaping_runs.hpp,
// shaping/runs/shaping_audit_run.hpp; thesis ch. 3), as heli/runs/heli_config.hpp has the helicopter's: each
// section's fields with help, bounds and the Options structs' defaults, and their reading. The `shaping`
// commands are these sections and a call.
#include <cstdint>

#include "pegasus/experiments/shaping_experiment.hpp"
#include "pegasus/experiments/shaping_progress_bonus.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/shaping/runs/shaping_audit_run.hpp"

namespace pegasus {

// `shaping gridworld` and `shaping flags`: Sarsa with and without potential-based shaping (§3.4).
void declare_shaping_learning_config(ConfigSchema& s, ShapingWorld world);
ShapingExperimentOptions read_shaping_learning_config(const ConfigSchema& c, ShapingWorld world,
                                                      std::uint64_t seed, int threads);

// `shaping progress-bonus`: the §3.1 bug, shown by learning.
void declare_progress_bonus_config(ConfigSchema& s);
ProgressBonusOptions read_progress_bonus_config(const ConfigSchema& c, std::uint64_t seed);

// `shaping audit`: is a tabular shaping reward potential-based (§3.3)?
void declare_shaping_audit_config(ConfigSchema& s);
ShapingAuditRunOptions read_shaping_audit_config(const ConfigSchema& c);

}  // namespace pegasus
