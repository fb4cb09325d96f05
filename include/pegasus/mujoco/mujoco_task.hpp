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
//                 body_linvel = [...] (of the centre of mass), clip = 10.0 (normalised),
//                 raw_clip = { qvel = 10.0 } (raw, per kind)
//   [[reward]]  term = "body_velocity" | "displacement" | "healthy" | "site_distance" | "joint_target" |
//               "joint_speed" | "joint_velocity" | "in_range" | "energy" | "control_cost" | "contact_cost",
//               weight = ..., cap = ..., training_only = false, and the term's fields (body/axis/point,
//               site/target, joint/target)
//   [success]   hold_steps = 100, at = "end" | "any", [[success.range]] quantity = ..., name = ..., min = ..,
//               max = .., bounds = "[]" | "()" | "[)" | "(]"
//   [[termination]] quantity = "qpos" | "qvel" | "body_height" | "site_height", name = ..., min = ..,
//                   max = .., bounds = "[]" (min and max may be omitted or infinite: -inf, inf)
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
  // The raw numbers are clipped to +-raw_clip before anything sees them (the normaliser's statistics, the
  // policy, a phase switch): [observation] raw_clip = { qvel = 10.0 }, as Gymnasium's hopper clips qvel.
  double raw_clip = std::numeric_limits<double>::infinity();
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
  kContactCost,
  kJointVelocity,
  kDisplacement
};
enum class QuantityKind { kQpos, kQvel, kBodyHeight, kSiteHeight };
// The rollout ends (an absorbing state) when a named quantity leaves the range from lower to upper: closed
// ([min, max], the default) or open at either end (`bounds = "()"`, "[)", "(]"; Gymnasium's healthy ranges
// are open); an omitted bound, or min = -inf / max = inf, leaves that side unbounded. NaN is outside every
// range.
struct TerminationRange {
  QuantityKind kind;
  std::string name;
  int id = 0;
  int adr = 0;
  double lower = 0.0, upper = 0.0;
  bool lower_open = false, upper_open = false;
  bool contains(double x) const {
    return (lower_open ? x > lower : x >= lower) && (upper_open ? x < upper : x <= upper);
  }
};

// Where a body's velocity or displacement is measured (body_velocity, displacement `point`):
//   com     the body's centre of mass (its inertial frame, mjData.xipos: the body's own, not its subtree's);
//           mj_objectVelocity(mjOBJ_BODY). The default, and what body_velocity measured before `point`.
//   origin  the body frame's origin (mjData.xpos; mj_objectVelocity(mjOBJ_XBODY)), where Gymnasium's
//           get_body_com reads a body's position despite its name
//   site    a site fixed in the body ("site:NAME"; mjData.site_xpos, mj_objectVelocity(mjOBJ_SITE))
enum class BodyPoint { kCom, kOrigin, kSite };

// One term of the reward of a control step; the reward is the sum of weight * value over the terms:
//   body_velocity  the world-frame linear velocity of a point of the body (`point`, BodyPoint: its centre of
//                  mass by default) along `axis` (0 x, 1 y, 2 z), m/s, at the end of the step (forward
//                  progress, as in the locomotion tasks)
//   healthy        1 for every step that ends inside every termination range (the "healthy" bonus)
//   site_distance  |site position - target| in metres (a negative weight rewards getting close)
//   joint_target   |qpos of the scalar joint - target| (radians or metres)
//   joint_speed    |qvel of the scalar joint| (rad/s or m/s; a negative weight discourages spinning)
//   energy         |potential + kinetic energy - target| in J (MuJoCo's mj_energyPos/mj_energyVel: gravity
//                  and joint springs), for swing-up tasks whose goal has a known energy
//   in_range       1 for every step that ends with the named quantity (as in [[termination]]) in [min, max]
//   control_cost   sum of squared actions in [-1, 1] (a negative weight makes it a cost)
//   contact_cost   sum over contacts of the squared contact force (N^2) of the last physics step (RK4: of
//                  the state at the end of the control step under its ctrl)
//   joint_velocity signed qvel of the scalar joint (rad/s or m/s)
//   displacement   (x_after - x_before) / (frame_skip * timestep): the body point's world-frame position
//                  along `axis` at the end of the control step less that at its start, over the step's
//                  duration (Gymnasium's forward reward), beside body_velocity's instantaneous value
// A term with training_only = true counts in the reward the search maximises and nowhere else (held-out
// evaluation, rollouts and success use the full task reward without it): ARS's "shift" of the alive bonus.
struct RewardTerm {
  RewardKind kind;
  double weight = 1.0;
  std::string name;  // body, site or joint
  int id = 0;
  int adr = 0;  // qpos address of joint_target, qvel address of joint_speed and joint_velocity
  int axis = 0;
  BodyPoint point = BodyPoint::kCom;  // body_velocity, displacement
  int site = -1;                      // point = site: its id
  int slot = 0;                       // displacement: its place in MujocoSlot::displacement_before
  bool training_only = false;
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
  int displacement_terms = 0;  // reward terms of kind displacement
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
  // Some reward term counts in training only (RewardTerm::training_only).
  bool has_training_only_terms() const;
  // The task says what success is: a return to reach or [success] ranges. Without either no rollout
  // succeeds and no success rate is reported (a made-up bar would call a falling robot a success).
  bool has_success_criterion() const { return !std::isnan(success_return) || !success_ranges.empty(); }
};

// The position in the observation vector of one number, written as the task file names it: "KIND.NAME" for
// an item of one number (a hinge's qpos, a touch sensor) or "KIND.NAME[k]" for number k of a longer one
// (site_pos.foot[2] is the foot's height), KIND one of the [observation] keys. InputError "FIELD: ..." naming
// what the observation holds otherwise.
int observation_position(const MujocoTask& task, std::string_view reference, std::string_view field);

// SHA-256 of the task file's parsed TOML (as JSON, keys in order): the same for files that differ only in
// comments, spacing or the order of keys in a table. InputError as for load_mujoco_task.
std::string mujoco_task_content_digest(const std::filesystem::path& path);

// Parses the task file and resolves every name against `model`. InputError "FILE: field: ..." otherwise.
MujocoTask load_mujoco_task(const std::filesystem::path& path, const MujocoModel& model);
// The same for text already read; `name` stands for the file in messages.
MujocoTask parse_mujoco_task(std::string_view text, const std::filesystem::path& name,
                             const MujocoModel& model);

}  // namespace pegasus
