#pragma once
// The config sections of the MuJoCo experiments (mujoco/runs/mujoco_runs.hpp), as heli/runs/heli_config.hpp
// has the helicopter's: each section's fields with help, bounds and the Options structs' defaults, and their
// reading. The `mujoco` commands are these sections and a call. Only with PEGASUS_HAVE_MUJOCO.
#ifdef PEGASUS_HAVE_MUJOCO
#include <cstdint>

#include "pegasus/mujoco/runs/mujoco_runs.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus {

// `mujoco train`: PEGASUS policy search on an MJCF model and a task file.
void declare_mujoco_train_config(ConfigSchema& s);
MujocoTrainingRunOptions read_mujoco_train_config(const ConfigSchema& c, std::uint64_t seed);

// `mujoco rollout`: a trained policy rolled out.
void declare_mujoco_rollout_config(ConfigSchema& s);
MujocoRolloutRunOptions read_mujoco_rollout_config(const ConfigSchema& c, std::uint64_t seed);

}  // namespace pegasus
#endif  // PEGASUS_HAVE_MUJOCO
