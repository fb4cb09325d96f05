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

inline std::shared_ptr<const MujocoEnvironment> cartpole_environment() {
  MujocoModel model = MujocoModel::load(mujoco_experiments() / "cartpole.xml");
  MujocoTask task = load_mujoco_task(mujoco_experiments() / "cartpole_swingup.toml", model);
  return std::make_shared<const MujocoEnvironment>(std::move(model), std::move(task));
}

inline std::filesystem::path write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

}  // namespace pegasus::test_support
