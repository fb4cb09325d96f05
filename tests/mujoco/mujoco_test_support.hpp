#pragma once
// The shipped cart-pole (experiments/mujoco/) as a test environment, and small MJCF/task files written on the
// fly (into TempDirTest's folder, support/cli_runner.hpp) for the bad-input and crash tests.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "pegasus/mujoco/mujoco_env.hpp"

namespace pegasus::test_support {

inline std::filesystem::path mujoco_experiments() {
  return std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "mujoco";
}

// The environment of an MJCF file and a task file for it.
inline std::shared_ptr<const MujocoEnvironment> environment_of(const std::filesystem::path& mjcf,
                                                               const std::filesystem::path& task_file) {
  MujocoModel model = MujocoModel::load(mjcf);
  MujocoTask task = load_mujoco_task(task_file, model);
  return std::make_shared<const MujocoEnvironment>(std::move(model), std::move(task));
}

inline std::shared_ptr<const MujocoEnvironment> cartpole_environment() {
  return environment_of(mujoco_experiments() / "cartpole.xml",
                        mujoco_experiments() / "cartpole_swingup.toml");
}

inline std::filesystem::path write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

}  // namespace pegasus::test_support
