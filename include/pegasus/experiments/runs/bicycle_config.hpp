#pragma once
// The config sections of the bicycle experiments (experiments/runs/bicycle_runs.hpp, thesis §4.6-4.7), as
// heli/runs/heli_config.hpp has the helicopter's: each section's fields with help, bounds and the Options
// structs' defaults, and their reading. The `bicycle` commands are these sections and a call.
#include <cstdint>

#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus {

// `bicycle experiment`: trials of training, each policy ridden, and the two lessons.
void declare_bicycle_experiment_config(ConfigSchema& s);
BicycleExperimentOptions read_bicycle_experiment_config(const ConfigSchema& c, std::uint64_t seed,
                                                        int threads);

// `bicycle train`: the objective, the optimizer and the rides after training (`rides` 0: none).
void declare_bicycle_train_config(ConfigSchema& s);
BicycleTrainingOptions read_bicycle_training_config(const ConfigSchema& c, std::uint64_t seed, int threads);
BicycleRideOptions read_bicycle_ride_config(const ConfigSchema& c, std::uint64_t seed);

// `bicycle ride`: a policy file ridden (read with read_bicycle_policy_config and read_bicycle_ride_config).
void declare_bicycle_ride_config(ConfigSchema& s);

// `bicycle variance`: a policy file's U-hat over scenario sets (`sets`); the objective alone.
void declare_bicycle_variance_config(ConfigSchema& s);
BicycleTrainingOptions read_bicycle_objective_config(const ConfigSchema& c, std::uint64_t seed, int threads);

// The `policy` field's bicycle policy; none or a bad file is bad input naming it.
Theta read_bicycle_policy_config(const ConfigSchema& c);

}  // namespace pegasus
