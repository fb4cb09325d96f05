// The MuJoCo experiments' config sections (mujoco/runs/mujoco_config.hpp).
#include "pegasus/mujoco/runs/mujoco_config.hpp"

#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>

#include <string>
#include <vector>

#include "pegasus/mujoco/mujoco_policy.hpp"
#include "pegasus/mujoco/mujoco_task.hpp"
#include "pegasus/runs/optimizer_config.hpp"

namespace pegasus {
namespace {

// "policy class (linear: ...; mlp: ...)", from the registry as it is when the command is declared.
std::string policy_class_help() {
  std::string classes;
  for (const MujocoPolicyClass& c : mujoco_policy_classes())
    classes += fmt::format("{}{}: {}", classes.empty() ? "" : "; ", c.name, c.doc);
  return fmt::format("policy class ({})", classes);
}

}  // namespace

void declare_mujoco_train_config(ConfigSchema& s) {
  const MujocoTrainingRunOptions d;
  s.add_string("model", "", "MJCF model file").input_file([](const std::string& file) {
    return MujocoModel::load(file).digest();  // with the files it includes
  });
  s.add_string("task", "", "task file (TOML) naming the model's joints, bodies, sites, sensors, actuators")
      .input_file();
  s.add_string("policy", d.policy_class, policy_class_help()).choices(mujoco_policy_class_names());
  s.add_int_list("hidden", std::vector<std::int64_t>(d.hidden.begin(), d.hidden.end()),
                 "hidden layer widths of the mlp policy")
      .min(1)
      .max(4096)
      .min_size(1);
  s.add_string("phase_observation", "",
               "make the policy phased: two policies of the class, switched by this raw observation number "
               "(KIND.NAME or KIND.NAME[k] as the task's [observation] names it, e.g. sensors.foot_touch)");
  s.add_double("phase_above", d.phase_above,
               "the phased policy's second half acts while that number exceeds this");
  s.add_bool("normalize", d.normalize,
             "normalise observations by running statistics frozen per iteration (ARS V2)");
  declare_optimizer_options(s, "optimizer", d.optimizer, continuous_class_methods(false));
  s.add_int("scenarios", d.scenarios, "PEGASUS scenarios m per evaluation of U-hat").min(1).max(1000000);
  s.add_string("variant", to_string(d.variant), "scenario variant").choices(scenario_variant_names());
  s.add_int("evaluation_episodes", d.evaluation_episodes,
            "held-out scenarios for the final return and success rate")
      .min(1)
      .max(1000000);
  s.add_int("checkpoint_every", d.checkpoint_every, "iterations between checkpoints").min(1).max(1000000);
  s.add_string("initial_policy", "",
               "start from this policy.json's theta instead of the class's initial values (same policy class "
               "and hidden widths, normalize = false): to continue a search on a longer horizon or another "
               "task")
      .input_file();
  s.add_double(
       "time_budget", d.time_budget_seconds,
       "stop the search after this many wall seconds, at the end of an iteration, with the best policy "
       "so far (0: no budget; the result then depends on the machine's speed)")
      .min(0.0)
      .max(1e9);
}

namespace {

std::vector<int> hidden_widths(const ConfigSchema& c) {
  std::vector<int> out;
  for (const auto w : c.get_int_list("hidden")) out.push_back(static_cast<int>(w));
  return out;
}

}  // namespace

MujocoTrainingRunOptions read_mujoco_train_config(const ConfigSchema& c, std::uint64_t seed) {
  MujocoTrainingRunOptions o{.model_file = c.get_path("model"),
                             .task_file = c.get_path("task"),
                             .policy_class = c.get_string("policy"),
                             .hidden = hidden_widths(c),
                             .phase_observation = c.get_string("phase_observation"),
                             .phase_above = c.get_double("phase_above"),
                             .normalize = c.get_bool("normalize"),
                             .scenarios = static_cast<int>(c.get_int("scenarios")),
                             .variant = parse_scenario_variant(c.get_string("variant")),
                             .evaluation_episodes = static_cast<int>(c.get_int("evaluation_episodes")),
                             .checkpoint_every = c.get_int("checkpoint_every"),
                             .initial_policy_file = c.get_path("initial_policy"),
                             .time_budget_seconds = c.get_double("time_budget"),
                             .seed = seed};
  read_optimizer_options(c, "optimizer", &o.optimizer);
  return o;
}

void declare_mujoco_rollout_config(ConfigSchema& s) {
  s.add_string("policy", "", "policy.json written by `pegasus mujoco train`").input_file();
  s.add_string("task", "",
               "roll out under this task file for the policy's model instead of the one it was trained on "
               "(same observation)")
      .input_file();
  s.add_int("episodes", MujocoRolloutRunOptions{}.episodes,
            "scenarios rolled out (the first is recorded step by step)")
      .min(1)
      .max(1000000);
}

MujocoRolloutRunOptions read_mujoco_rollout_config(const ConfigSchema& c, std::uint64_t seed) {
  return {.policy_file = c.get_path("policy"),
          .task_file = c.get_path("task"),
          .episodes = static_cast<int>(c.get_int("episodes")),
          .seed = seed};
}

}  // namespace pegasus
#endif  // PEGASUS_HAVE_MUJOCO
