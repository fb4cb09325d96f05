#pragma once
// A MuJoCo model (MJCF) and a task file (TOML) that names the model's own joints, bodies, sites, sensors
// and actuators, resolved once against the compiled model (issue 18).
//
// MujocoModel holds the compiled mjModel, immutable and shared read-only by every thread (MuJoCo's
// model/data split; STYLE.md). The task file is checked against it when loaded: an error names the file,
// the field and the missing name, e.g.
//   task.toml: reward[1].body: the model has no body "torso" (bodies: world, cart, pole)
//
// Task file (every field documented in experiments/mujoco/README.md):
//   horizon = 500                 control steps H per rollout
//   discount = 1.0                gamma in [0, 1]
//   frame_skip = 2                physics steps (of the MJCF's timestep) per control step
//   crash_penalty = -100.0        reward of the step at which MuJoCo reported instability (NaN, huge qacc)
//   termination_penalty = -300.0  added to the reward of the step that leaves a termination range (a fall)
//   success_bonus = 500.0         added to the reward of a rollout's last step when the rollout succeeds
//   success_return = 300.0        a rollout succeeds when its return reaches this (none by default: without
//                                 it or [success] the task has no success criterion and no success rate)
//   [initial]   qpos = { hinge = 3.14159 }            start values of scalar joints (else the MJCF's qpos0)
//               qpos_noise = 0.01, qvel_noise = 0.01  half-widths of uniform perturbations of every qpos/qvel
//   [noise]     actuator = 0.05     half-width of uniform noise on each ctrl, as a fraction of its half-range
//               push_bodies = ["torso"], push_force = 20.0, push_probability = 0.02   random pushes
//   [observation] qpos = [...], qpos_sincos = [...], qvel = [...], sensors = [...], site_pos = [...],
//                 body_linvel = [...], clip = 10.0
//   [[reward]]  term = "body_velocity" | "healthy" | "site_distance" | "joint_target" | "joint_speed" |
//               "in_range" | "energy" | "control_cost" |
//               "contact_cost", weight = ..., and the term's fields (body/axis, site/target, joint/target)
//   [success]   hold_steps = 100, at = "end" | "any", [[success.range]] quantity = ..., name = ..., min = ..,
//   max = ..
//   [[termination]] quantity = "qpos" | "qvel" | "body_height" | "site_height", name = ..., min = .., max =
//   ..
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

struct mjModel_;

namespace pegasus {

// The compiled MJCF, shared read-only by all threads.
class MujocoModel {
 public:
  // Compiles the MJCF file; InputError "FILE: <MuJoCo's message>" when it is missing or malformed.
  static MujocoModel load(const std::filesystem::path& path);

  const mjModel_* get() const { return model_.get(); }
  const std::filesystem::path& path() const { return path_; }
  // SHA-256 of the compiled model (MuJoCo's binary form): it changes with the MJCF file and with every file
  // it includes or loads (meshes, height fields), which the MJCF file's own bytes do not show.
  std::string digest() const;

  // Id of the named object of MuJoCo type `type` (mjtObj), or -1.
  int id_of(int type, const std::string& name) const;
  // Name of object `id` of type `type` ("" when unnamed).
  std::string name_of(int type, int id) const;

 private:
  std::shared_ptr<const mjModel_> model_;
  std::filesystem::path path_;
};

enum class ObservationKind { kQpos, kQposSinCos, kQvel, kSensor, kSitePos, kBodyLinearVelocity };
struct ObservationItem {
  ObservationKind kind;
  std::string name;
  int id = 0;   // joint, sensor, site or body id
  int adr = 0;  // qpos/qvel/sensordata address
  int dim = 1;  // numbers this item adds to the observation
};

enum class RewardKind {
  kBodyVelocity,
  kHealthy,
  kSiteDistance,
  kJointTarget,
  kJointSpeed,
  kInRange,
  kEnergy,
  kControlCost,
  kContactCost
};
enum class QuantityKind { kQpos, kQvel, kBodyHeight, kSiteHeight };
// The rollout ends (an absorbing state) when a named quantity leaves [lower, upper].
struct TerminationRange {
  QuantityKind kind;
  std::string name;
  int id = 0;
  int adr = 0;
  double lower = 0.0, upper = 0.0;
};

// One term of the reward of a control step; the reward is the sum of weight * value over the terms:
//   body_velocity  the body's world-frame linear velocity along `axis` (0 x, 1 y, 2 z), m/s, at the end of
//                  the step (forward progress, as in the locomotion tasks)
//   healthy        1 for every step that ends inside every termination range (the "healthy" bonus)
//   site_distance  |site position - target| in metres (a negative weight rewards getting close)
//   joint_target   |qpos of the scalar joint - target| (radians or metres)
//   joint_speed    |qvel of the scalar joint| (rad/s or m/s; a negative weight discourages spinning)
//   energy         |potential + kinetic energy - target| in J (MuJoCo's mj_energyPos/mj_energyVel: gravity
//                  and joint springs), for swing-up tasks whose goal has a known energy
//   in_range       1 for every step that ends with the named quantity (as in [[termination]]) in [min, max]
//   control_cost   sum of squared actions in [-1, 1] (a negative weight makes it a cost)
//   contact_cost   sum over contacts of the squared contact force (N^2) after the last physics step
struct RewardTerm {
  RewardKind kind;
  double weight = 1.0;
  std::string name;  // body, site or joint
  int id = 0;
  int adr = 0;  // qpos address of joint_target
  int axis = 0;
  std::array<double, 3> target{};  // site_distance: world position; joint_target, energy: target[0]
  TerminationRange range{};        // in_range
  double cap = std::numeric_limits<double>::infinity();  // the value counts at most this much (before weight)
};

struct MujocoTask {
  int horizon = 1000;
  double discount = 1.0;
  int frame_skip = 1;
  double crash_penalty = -100.0;
  double termination_penalty = 0.0;
  double success_bonus = 0.0;  // paid on the last step of a rollout that meets the success criterion
  double success_return = std::numeric_limits<double>::quiet_NaN();  // NaN: no bar on the return

  std::vector<std::pair<int, double>> initial_qpos;  // (qpos address, value)
  double initial_qpos_noise = 0.0;
  double initial_qvel_noise = 0.0;

  double actuator_noise = 0.0;
  std::vector<int> push_bodies;
  std::vector<std::string> push_body_names;
  double push_force = 0.0;
  double push_probability = 0.0;

  std::vector<ObservationItem> observation;
  double observation_clip = 10.0;  // normalised observations are clipped to +-clip
  std::vector<RewardTerm> reward;
  std::vector<TerminationRange> termination;
  // Success of one rollout: its return reaches success_return and, when success_ranges is not empty,
  //   at = "end" (success_anywhere false): it runs its whole horizon and ends each of its last
  //            success_hold_steps control steps inside every range (e.g. balanced for the final 3 s);
  //   at = "any": it does not crash and ends success_hold_steps consecutive control steps inside every
  //            range somewhere (e.g. swung up to the top once).
  std::vector<TerminationRange> success_ranges;
  int success_hold_steps = 1;
  bool success_anywhere = false;

  int observation_dim() const;
  // The task says what success is: a return to reach or [success] ranges. Without either no rollout
  // succeeds and no success rate is reported (a made-up bar would call a falling robot a success).
  bool has_success_criterion() const { return !std::isnan(success_return) || !success_ranges.empty(); }
};

// The position in the observation vector of one number, written as the task file names it: "KIND.NAME" for
// an item of one number (a hinge's qpos, a touch sensor) or "KIND.NAME[k]" for number k of a longer one
// (site_pos.foot[2] is the foot's height), KIND one of the [observation] keys. InputError "FIELD: ..." naming
// what the observation holds otherwise.
int observation_position(const MujocoTask& task, std::string_view reference, std::string_view field);

// Parses the task file and resolves every name against `model`. InputError "FILE: field: ..." otherwise.
MujocoTask load_mujoco_task(const std::filesystem::path& path, const MujocoModel& model);
// The same for text already read; `name` stands for the file in messages.
MujocoTask parse_mujoco_task(std::string_view text, const std::filesystem::path& name,
                             const MujocoModel& model);

}  // namespace pegasus
