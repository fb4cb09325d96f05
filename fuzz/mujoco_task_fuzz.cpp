// libFuzzer harness: MuJoCo task files (mujoco/mujoco_task: parse_mujoco_task), the TOML that `pegasus mujoco
// train --task` reads, checked against the shipped cart-pole model (names of its joints, bodies, sites and
// actuators). Any bytes are accepted or refused with one InputError line naming the file; an accepted task
// has a positive horizon and frame skip. Built only where MuJoCo is (fuzz/CMakeLists.txt).
#include "fuzz_contract.hpp"
#include "pegasus/mujoco/mujoco_task.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const pegasus::MujocoModel model =
      pegasus::MujocoModel::load(PEGASUS_SOURCE_DIR "/experiments/mujoco/cartpole.xml");
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("task.toml", [&] {
    const pegasus::MujocoTask task = pegasus::parse_mujoco_task(text, "task.toml", model);
    if (task.horizon < 1 || task.frame_skip < 1)
      pegasus::fuzz::violation("an accepted task without a positive horizon and frame skip", text);
  });
  return 0;
}
