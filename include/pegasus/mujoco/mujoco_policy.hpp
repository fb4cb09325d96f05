#pragma once
// Policy classes for robots (thesis §4.1; issue 18), acting on normalised observations
//   z = clip((o - mean) / std, -clip, clip)
// with the mean and standard deviation frozen during an optimizer iteration, as in Augmented Random Search
// (Mania, Guy and Recht 2018, "V2"). Actions are in [-1, 1] per actuator; the environment maps them onto
// each actuator's ctrlrange.
//   linear   a = clip(W z + b, -1, 1)                                     nu (d + 1) parameters
//   mlp      h_1 = tanh(W_1 z + b_1), ..., a = tanh(W_L h_{L-1} + b_L)     (Eigen)
// Either class may be phased: two policies of the class, one acting while a chosen raw observation number is
// above a threshold and the other while it is not (twice the parameters, "below." and "above." names). A
// legged robot's stance and flight are such phases (a touch sensor above 0), and Raibert's hopping
// controllers are a state machine over them: a servo of the body's pitch in stance, the foot placed by the
// speed in flight. Every parameter starts at 0 (ARS's zero start: the first perturbations explore every
// weight equally).
//
// act writes into caller-owned spans (no allocation in a step) instead of returning the action by value
// as the project's PolicyFor concept does for small fixed-size actions.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

// Frozen per-dimension mean and 1/std; identity (0, 1) until statistics arrive.
struct ObservationNormalizer {
  std::vector<double> mean, inverse_std;
  double clip = 10.0;

  explicit ObservationNormalizer(int dim = 0, double clip_to = 10.0)
      : mean(static_cast<std::size_t>(dim), 0.0),
        inverse_std(static_cast<std::size_t>(dim), 1.0),
        clip(clip_to) {}
  void apply(std::span<const double> observation, std::span<double> z) const;
};

// Running count, mean and sum of squared deviations per dimension (Chan et al.'s parallel merge), so that
// statistics gathered per rollout merge in scenario order into the same bits on any number of threads.
struct ObservationMoments {
  double count = 0.0;
  std::vector<double> mean, m2;

  explicit ObservationMoments(int dim = 0)
      : mean(static_cast<std::size_t>(dim), 0.0), m2(static_cast<std::size_t>(dim), 0.0) {}
  void reset();
  void add(std::span<const double> observation);
  void merge(const ObservationMoments& other);
  // mean and 1/std of everything added; a dimension whose variance is below 1e-8 keeps 1/std = 1.
  void freeze_into(ObservationNormalizer* normalizer) const;
  nlohmann::json to_json() const;
  static ObservationMoments from_json(const nlohmann::json& state, int dim);
};

class MujocoPolicy {
 public:
  virtual ~MujocoPolicy() = default;
  virtual const ParameterSpec& parameters() const = 0;
  // action (size nu) in [-1, 1] from the raw observation (size d) and its normalised z (size d); scratch
  // has scratch_size() doubles.
  virtual void act(std::span<const double> theta, std::span<const double> observation,
                   std::span<const double> z, std::span<double> action, std::span<double> scratch) const = 0;
  virtual int scratch_size() const { return 0; }
  // {"class": its registered name, "hidden": [...]}, and "phase" ({"observation", "above"}) when phased
  virtual nlohmann::json describe() const = 0;
};

// A policy class, registered once by name: the name that the `policy` option (TOML key and --policy) and
// policy.json's "class" give, a one-line doc for the option's help, whether it takes hidden layers, and its
// factory. make_mujoco_policy, parse_mujoco_policy_file and the option's choices all read the registry.
// A class with hidden_layers takes `hidden` (1 to 16 layers of 1 to 4096 units) and its policy.json lists
// them; any other class is built without them (the option's widths are ignored) and its file says [].
// make's policy must describe() itself with "class": name.
struct MujocoPolicyClass {
  using Factory = std::function<std::unique_ptr<MujocoPolicy>(int observation_dim, int action_dim,
                                                              const std::vector<int>& hidden)>;
  std::string name;
  std::string doc;
  bool hidden_layers = false;
  Factory make;
};
// Adds a class after those registered, or replaces the one of its name in its place. Thread-safe; call
// before the class is named (a CLI option's choices are read when its command is declared).
void register_mujoco_policy_class(MujocoPolicyClass policy_class);
// The registered classes in registration order: the built-ins first ("linear", then "mlp").
std::vector<MujocoPolicyClass> mujoco_policy_classes();
std::vector<std::string> mujoco_policy_class_names();

// The switch of a phased policy: the "above" half acts while observation[position] > above, the "below" half
// otherwise. `observation` names the number as observation_position (mujoco_task.hpp) reads it; an empty
// name is no switch.
struct PolicyPhase {
  std::string observation;
  int position = -1;
  double above = 0.0;

  bool phased() const { return !observation.empty(); }
  // The same switch, whether or not either side's position is resolved.
  bool same_switch(const PolicyPhase& other) const {
    return observation == other.observation && above == other.above;
  }
  bool operator==(const PolicyPhase&) const = default;
};
// {"observation": ..., "above": ...}, or null when unphased: as policy.json, summary.json and describe hold
// it.
nlohmann::json policy_phase_json(const PolicyPhase& phase);

// kind: a registered class (hidden: its layer widths when it takes them), phased when phase.phased() (its
// position resolved, below observation_dim). InputError naming `policy`, `hidden` or `phase_observation`
// otherwise.
std::unique_ptr<MujocoPolicy> make_mujoco_policy(const std::string& kind, int observation_dim, int action_dim,
                                                 const std::vector<int>& hidden,
                                                 const PolicyPhase& phase = {});

// policy.json, as `pegasus mujoco train` writes it and `pegasus mujoco rollout` reads it:
//   {"format": "pegasus.mujoco.policy", "version": 1, "model": PATH, "task": PATH, "class": CLASS,
//    "hidden": [WIDTH, ...], "theta": [...], "normalizer": {"mean": [...], "inverse_std": [...], "clip": C}}
// and, for a phased policy, "phase": {"observation": "KIND.NAME", "above": X} (theta: the below half, then
// the above half).
// CLASS is a registered class's name, and "hidden" is [] for a class without hidden layers.
inline constexpr const char* kMujocoPolicyFormat = "pegasus.mujoco.policy";
inline constexpr int kMujocoPolicyVersion = 1;
struct MujocoPolicyFile {
  std::string model, task;  // the MJCF and the task file it was trained on (absolute paths when written)
  // What they were then (MujocoModel::digest(), the task file's SHA-256): a rollout says when either changed.
  // Empty in files written before they were recorded.
  std::string model_digest, task_digest;
  // The task's parsed content (mujoco_task_content_digest): what a rollout compares when the file has it, so
  // that an edit of comments or spacing alone is no change. Empty in files written before it was recorded.
  std::string task_content_digest;
  std::string policy_class;
  std::vector<int> hidden;
  PolicyPhase phase;  // position unresolved (-1): the task resolves the name
  std::vector<double> theta;
  ObservationNormalizer normalizer;
};
nlohmann::json mujoco_policy_file_json(const MujocoPolicyFile& file);
// Checked by form and meaning where it is read: "FILE: FIELD: expected ..., got ..." as one InputError line
// (the sizes of theta and the normalizer against the model are checked by check_mujoco_policy_file).
MujocoPolicyFile parse_mujoco_policy_file(const nlohmann::json& j, const std::string& file);
MujocoPolicyFile read_mujoco_policy_file(const std::filesystem::path& file);
// InputError naming `file` when theta or the normalizer do not fit `policy` and an observation of `dim`.
void check_mujoco_policy_file(const MujocoPolicyFile& policy_file, const MujocoPolicy& policy, int dim,
                              const std::string& file);

}  // namespace pegasus
