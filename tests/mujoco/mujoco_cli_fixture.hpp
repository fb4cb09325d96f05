#pragma once
// What the end-to-end tests of `pegasus mujoco` share (mujoco_cli_test.cpp, mujoco_robustness_cli_test.cpp):
// the fixture and a small training run.
#include <filesystem>
#include <string>

#include "mujoco_test_support.hpp"
#include "support/cli_runner.hpp"

namespace pegasus::mujoco_cli_test {

inline std::string small_train(const std::filesystem::path& out, int threads) {
  const auto dir = test_support::mujoco_experiments();
  return "mujoco train --model " + (dir / "cartpole.xml").string() + " --task " +
         (dir / "cartpole_swingup.toml").string() +
         " --policy mlp --hidden 4 --scenarios 3 --optimizer.ars.max-iterations 3 --optimizer.ars.directions "
         "2 --optimizer.ars.top-directions 1 "
         "--evaluation-episodes 4 --checkpoint-every 1 --seed 7 --quiet --threads " +
         std::to_string(threads) + " --out " + out.string();
}

class MujocoCli : public test_support::TempDirTest {};

}  // namespace pegasus::mujoco_cli_test
