#include "pegasus/mujoco/mujoco_task.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "../io/toml_fields.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/sha256.hpp"

namespace pegasus {

namespace {

std::string object_kind(int type) {
  switch (type) {
    case mjOBJ_BODY:
      return "body";
    case mjOBJ_JOINT:
      return "joint";
    case mjOBJ_SITE:
      return "site";
    case mjOBJ_SENSOR:
      return "sensor";
    case mjOBJ_ACTUATOR:
      return "actuator";
    default:
      return "object";
  }
}

int object_count(const mjModel* m, int type) {
  switch (type) {
    case mjOBJ_BODY:
      return m->nbody;
    case mjOBJ_JOINT:
      return m->njnt;
    case mjOBJ_SITE:
      return m->nsite;
    case mjOBJ_SENSOR:
      return m->nsensor;
    case mjOBJ_ACTUATOR:
      return m->nu;
    default:
      return 0;
  }
}

// The numbers of a joint in qpos and in qvel.
int joint_qpos_size(int type) { return type == mjJNT_FREE ? 7 : type == mjJNT_BALL ? 4 : 1; }
int joint_dof_size(int type) { return type == mjJNT_FREE ? 6 : type == mjJNT_BALL ? 3 : 1; }

class TaskReader {
 public:
  TaskReader(const std::filesystem::path& path, const MujocoModel& model)
      : fields_(path.string()), model_(model) {}

  // Names come from the user's file and may hold any bytes (a TOML "\n" escape): TomlFields prints one line.
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    fields_.fail(nullptr, field, what);
  }

  // Id of the named object; fails naming the field, the name and the model's objects of that kind.
  int resolve(int type, const std::string& name, const std::string& field) const {
    const int id = model_.id_of(type, name);
    if (id >= 0) return id;
    std::string known;
    const int n = object_count(model_.get(), type);
    for (int i = 0; i < n && i < 12; ++i) known += (i ? ", " : "") + model_.name_of(type, i);
    if (n > 12) known += ", ...";
    const std::string kind = object_kind(type);
    const std::string kinds = kind == "body" ? "bodies" : kind + "s";
    fail(field, fmt::format("the model has no {} \"{}\" ({}: {})", kind, name, kinds,
                            known.empty() ? "none" : known));
  }

  // A scalar (hinge or slide) joint: its qpos address.
  int scalar_joint(const std::string& name, const std::string& field) const {
    const int id = resolve(mjOBJ_JOINT, name, field);
    const int type = model_.get()->jnt_type[id];
    if (type != mjJNT_HINGE && type != mjJNT_SLIDE)
      fail(field, fmt::format("joint \"{}\" is not a hinge or slide joint", name));
    return id;
  }

  double number(const toml::node_view<const toml::node>& node, const std::string& field, double fallback,
                double lower = -INFINITY, double upper = INFINITY) const {
    return fields_.number(node.node(), field, fallback, lower, upper);
  }

  int integer(const toml::node_view<const toml::node>& node, const std::string& field, int fallback,
              int lower, int upper) const {
    return static_cast<int>(fields_.integer(node.node(), field, fallback, lower, upper));
  }

  std::string string(const toml::node_view<const toml::node>& node, const std::string& field) const {
    if (!node) fail(field, "missing (expected a name)");
    return fields_.string(node.node(), field, "");
  }

  std::vector<std::string> names(const toml::node_view<const toml::node>& node,
                                 const std::string& field) const {
    return fields_.strings(node.node(), field);
  }

  // `table_name` names the table in messages ("initial", "reward[0]"); empty for the file's top level.
  void check_keys(const toml::table& table, const std::string& table_name,
                  const std::set<std::string>& allowed) const {
    fields_.only_keys(table, table_name, allowed);
  }

  const TomlFields& fields() const { return fields_; }

 private:
  TomlFields fields_;
  const MujocoModel& model_;
};

// A range's bound: a finite number, or an infinite one (TOML's inf, -inf) for no bound on that side; NaN
// is refused (every comparison with it is false: a range no value is inside).
double bound(const TaskReader& r, const toml::node_view<const toml::node>& node, const std::string& field,
             double fallback) {
  if (const toml::node* n = node.node(); n && n->is_floating_point()) {
    const double x = *n->value<double>();
    if (std::isinf(x)) return x;
    if (std::isnan(x)) r.fields().fail(n, field, "expected a number, -inf or inf, got nan");
  }
  return r.number(node, field, fallback);
}

// A named quantity's range: [[termination]] and [[success.range]] tables.
// `prefix` names the table in messages; its other keys are the caller's to check when check_keys is false.
TerminationRange read_range(const TaskReader& r, const mjModel* m, const toml::node& node,
                            const std::string& prefix, bool check_keys = true) {
  const toml::table* t = node.as_table();
  if (!t) r.fail(prefix, "expected a table");
  if (check_keys) r.check_keys(*t, prefix, {"quantity", "name", "min", "max", "bounds"});
  const toml::node_view<const toml::node> v{*t};
  const std::string quantity = r.string(v["quantity"], prefix + ".quantity");
  TerminationRange out{};
  out.name = r.string(v["name"], prefix + ".name");
  if (quantity == "qpos" || quantity == "qvel") {
    out.kind = quantity == "qpos" ? QuantityKind::kQpos : QuantityKind::kQvel;
    out.id = r.scalar_joint(out.name, prefix + ".name");
    out.adr = quantity == "qpos" ? m->jnt_qposadr[out.id] : m->jnt_dofadr[out.id];
  } else if (quantity == "body_height") {
    out.kind = QuantityKind::kBodyHeight;
    out.id = r.resolve(mjOBJ_BODY, out.name, prefix + ".name");
  } else if (quantity == "site_height") {
    out.kind = QuantityKind::kSiteHeight;
    out.id = r.resolve(mjOBJ_SITE, out.name, prefix + ".name");
  } else {
    r.fail(prefix + ".quantity",
           fmt::format("expected one of qpos, qvel, body_height, site_height; got \"{}\"", quantity));
  }
  // Without either bound every value is in range: a termination that never ends, a success or an in_range
  // bonus that always holds.
  if (!v["min"] && !v["max"])
    r.fail(prefix, "expected min, max or both (without them every value is in range)");
  out.lower = bound(r, v["min"], prefix + ".min", -INFINITY);
  out.upper = bound(r, v["max"], prefix + ".max", INFINITY);
  if (!(out.lower < out.upper)) r.fail(prefix + ".max", "expected max > min");
  // Closed by default, as before `bounds` existed; Gymnasium's healthy ranges are open: "()".
  const std::string bounds =
      r.fields().choice(v["bounds"].node(), prefix + ".bounds", "[]", {"[]", "()", "[)", "(]"});
  out.lower_open = bounds[0] == '(';
  out.upper_open = bounds[1] == ')';
  return out;
}

MujocoTask mujoco_task_from_toml(const toml::table& root, const std::filesystem::path& path,
                                 const MujocoModel& model);

}  // namespace

bool MujocoTask::has_training_only_terms() const {
  for (const auto& term : reward)
    if (term.training_only) return true;
  return false;
}

int MujocoTask::observation_dim() const {
  int d = 0;
  for (const auto& item : observation) d += item.dim;
  return d;
}

namespace {

// The [observation] key of each kind, in the order of ObservationKind.
constexpr const char* kObservationKeys[] = {"qpos",    "qpos_sincos", "qvel",
                                            "sensors", "site_pos",    "body_linvel"};

}  // namespace

int observation_position(const MujocoTask& task, std::string_view reference, std::string_view field) {
  std::vector<std::string> known;
  int position = 0;
  for (const auto& item : task.observation) {
    const std::string name = fmt::format("{}.{}", kObservationKeys[static_cast<int>(item.kind)], item.name);
    for (int k = 0; k < item.dim; ++k) {
      const std::string numbered = item.dim == 1 ? name : fmt::format("{}[{}]", name, k);
      if (numbered == reference) return position + k;
      known.push_back(numbered);
    }
    position += item.dim;
  }
  constexpr std::size_t kListed = 24;  // a humanoid's observation has hundreds
  const std::string listed =
      known.size() <= kListed
          ? fmt::format("{}", fmt::join(known, ", "))
          : fmt::format("{}, ... ({} in all)", fmt::join(known.begin(), known.begin() + kListed, ", "),
                        known.size());
  throw InputError(fmt::format("{}: the task's observation has no number \"{}\" (expected one of {})", field,
                               printable(reference), listed));
}

std::string mujoco_task_content_digest(const std::filesystem::path& path) {
  std::ostringstream text;
  text << toml::json_formatter{read_toml_input(path, "task")};
  return sha256_hex(text.str());
}

MujocoTask load_mujoco_task(const std::filesystem::path& path, const MujocoModel& model) {
  return mujoco_task_from_toml(read_toml_input(path, "task"), path, model);
}

MujocoTask parse_mujoco_task(std::string_view text, const std::filesystem::path& name,
                             const MujocoModel& model) {
  return mujoco_task_from_toml(parse_toml_input(text, name.string()), name, model);
}

namespace {

// The file's top-level numbers: the rollout's horizon, discount and frame skip, and the returns' penalties
// and bonuses.
// The task file's optional header: a file without one (every file before it) is of version 1.
constexpr const char* kTaskFormat = "pegasus.mujoco.task";
constexpr int kTaskVersion = 1;

void read_top_level(const TaskReader& r, const toml::table& root, MujocoTask& task) {
  r.check_keys(root, "",
               {"format", "version", "horizon", "discount", "frame_skip", "crash_penalty",
                "termination_penalty", "success_bonus", "success_return", "initial", "noise", "observation",
                "reward", "termination", "success"});
  const toml::node_view<const toml::node> top{root};
  r.fields().choice(top["format"].node(), "format", kTaskFormat, {kTaskFormat});
  r.integer(top["version"], "version", kTaskVersion, kTaskVersion, kTaskVersion);
  task.horizon = r.integer(top["horizon"], "horizon", 1000, 1, 1'000'000);
  task.discount = r.number(top["discount"], "discount", 1.0, 0.0, 1.0);
  task.frame_skip = r.integer(top["frame_skip"], "frame_skip", 1, 1, 1000);
  task.crash_penalty = r.number(top["crash_penalty"], "crash_penalty", -100.0);
  task.termination_penalty = r.number(top["termination_penalty"], "termination_penalty", 0.0);
  task.success_bonus = r.number(top["success_bonus"], "success_bonus", 0.0);
  task.success_return =
      r.number(top["success_return"], "success_return", std::numeric_limits<double>::quiet_NaN());
}

// [initial]: joint positions set before the start's noise, and that noise.
void read_initial(const TaskReader& r, const mjModel* m, const toml::table& initial, MujocoTask& task) {
  r.check_keys(initial, "initial", {"qpos", "qpos_noise", "qvel_noise"});
  if (const toml::table* qpos = initial["qpos"].as_table()) {
    for (const auto& [key, value] : *qpos) {
      const std::string field = "initial.qpos." + std::string(key.str());
      const int joint = r.scalar_joint(std::string(key.str()), field);
      task.initial_qpos.emplace_back(m->jnt_qposadr[joint], r.fields().number(&value, field, 0.0));
    }
  } else if (initial["qpos"]) {
    r.fail("initial.qpos", "expected a table of joint = value");
  }
  const toml::node_view<const toml::node> in{initial};
  task.initial_qpos_noise = r.number(in["qpos_noise"], "initial.qpos_noise", 0.0, 0.0, 1e6);
  task.initial_qvel_noise = r.number(in["qvel_noise"], "initial.qvel_noise", 0.0, 0.0, 1e6);
}

// [noise]: actuator noise and random pushes on named bodies.
void read_noise(const TaskReader& r, const toml::table& noise, MujocoTask& task) {
  r.check_keys(noise, "noise", {"actuator", "push_bodies", "push_force", "push_probability"});
  const toml::node_view<const toml::node> n{noise};
  task.actuator_noise = r.number(n["actuator"], "noise.actuator", 0.0, 0.0, 1.0);
  task.push_body_names = r.names(n["push_bodies"], "noise.push_bodies");
  for (std::size_t i = 0; i < task.push_body_names.size(); ++i)
    task.push_bodies.push_back(
        r.resolve(mjOBJ_BODY, task.push_body_names[i], fmt::format("noise.push_bodies[{}]", i)));
  task.push_force = r.number(n["push_force"], "noise.push_force", 0.0, 0.0, 1e9);
  task.push_probability = r.number(n["push_probability"], "noise.push_probability", 0.0, 0.0, 1.0);
}

// One observed quantity of a kind: the object it reads, where its numbers are and how many.
ObservationItem observation_item(const TaskReader& r, const mjModel* m, ObservationKind kind,
                                 const std::string& name, const std::string& field) {
  ObservationItem item{.kind = kind, .name = name};
  switch (kind) {
    case ObservationKind::kQpos:
      // Any joint: a free joint gives its 7 numbers (position, orientation quaternion w, x, y, z), a
      // ball joint its quaternion, a hinge or slide its one.
      item.id = r.resolve(mjOBJ_JOINT, name, field);
      item.adr = m->jnt_qposadr[item.id];
      item.dim = joint_qpos_size(m->jnt_type[item.id]);
      break;
    case ObservationKind::kQposSinCos:
      item.id = r.scalar_joint(name, field);
      item.adr = m->jnt_qposadr[item.id];
      item.dim = 2;
      break;
    case ObservationKind::kQvel:
      // A free joint's 6 (linear velocity in the world frame, angular in the body's), a ball's 3.
      item.id = r.resolve(mjOBJ_JOINT, name, field);
      item.adr = m->jnt_dofadr[item.id];
      item.dim = joint_dof_size(m->jnt_type[item.id]);
      break;
    case ObservationKind::kSensor:
      item.id = r.resolve(mjOBJ_SENSOR, name, field);
      item.adr = m->sensor_adr[item.id];
      item.dim = m->sensor_dim[item.id];
      break;
    case ObservationKind::kSitePos:
      item.id = r.resolve(mjOBJ_SITE, name, field);
      item.dim = 3;
      break;
    case ObservationKind::kBodyLinearVelocity:
      item.id = r.resolve(mjOBJ_BODY, name, field);
      item.dim = 3;
      break;
  }
  return item;
}

// The items one [observation] key names, in the file's order.
void read_observation_items(const TaskReader& r, const mjModel* m, const toml::table& observation,
                            ObservationKind kind, MujocoTask& task) {
  const char* key = kObservationKeys[static_cast<int>(kind)];
  const std::string field = std::string("observation.") + key;
  const auto list = r.names(toml::node_view<const toml::node>{observation}[key], field);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string item_field = fmt::format("{}[{}]", field, i);
    // The same numbers twice would only give the policy a redundant input (a typo for another name?).
    for (std::size_t j = 0; j < i; ++j)
      if (list[j] == list[i])
        r.fail(item_field, fmt::format("'{}' is already observed as {}[{}]", printable(list[i]), field, j));
    task.observation.push_back(observation_item(r, m, kind, list[i], item_field));
  }
}

// raw_clip = { qvel = 10.0 }: each named kind's raw numbers are clipped before anything else sees them.
void read_raw_clip(const TaskReader& r, const toml::node& raw, MujocoTask& task) {
  const toml::table* clips = raw.as_table();
  if (!clips)
    r.fields().fail(&raw, "observation.raw_clip", "expected a table of kind = clip, e.g. { qvel = 10.0 }");
  r.check_keys(*clips, "observation.raw_clip",
               std::set<std::string>(std::begin(kObservationKeys), std::end(kObservationKeys)));
  for (const auto& [key, value] : *clips) {
    const std::string kind(key.str());
    const double clip = r.fields().number(&value, "observation.raw_clip." + kind, 0.0, 1e-12, INFINITY);
    bool observed = false;
    for (auto& item : task.observation)
      if (kObservationKeys[static_cast<int>(item.kind)] == kind) {
        item.raw_clip = clip;
        observed = true;
      }
    if (!observed)
      r.fields().fail(&value, "observation.raw_clip." + kind,
                      fmt::format("the observation has no {} items to clip", kind));
  }
}

// [observation]: what the policy sees, kind by kind in the order of ObservationKind, and its clips.
void read_observation(const TaskReader& r, const mjModel* m, const toml::table* observation,
                      MujocoTask& task) {
  if (!observation) r.fail("observation", "missing (expected a table naming what the policy sees)");
  r.check_keys(*observation, "observation",
               {"qpos", "qpos_sincos", "qvel", "sensors", "site_pos", "body_linvel", "clip", "raw_clip"});
  const toml::node_view<const toml::node> obs{*observation};
  task.observation_clip = r.number(obs["clip"], "observation.clip", 10.0, 1e-6, 1e9);
  for (const ObservationKind kind :
       {ObservationKind::kQpos, ObservationKind::kQposSinCos, ObservationKind::kQvel,
        ObservationKind::kSensor, ObservationKind::kSitePos, ObservationKind::kBodyLinearVelocity})
    read_observation_items(r, m, *observation, kind, task);
  if (task.observation.empty()) r.fail("observation", "names nothing (expected at least one quantity)");
  if (const toml::node* raw = observation->get("raw_clip")) read_raw_clip(r, *raw, task);
}

// The point of a body_velocity or displacement term's body: "com", "origin" or "site:NAME" of a site fixed
// in that body.
void read_body_point(const TaskReader& r, const MujocoModel& model,
                     const toml::node_view<const toml::node>& v, const std::string& prefix, RewardTerm& out) {
  const std::string point = r.fields().string(v["point"].node(), prefix + ".point", "com");
  if (point == "com") {
    out.point = BodyPoint::kCom;
  } else if (point == "origin") {
    out.point = BodyPoint::kOrigin;
  } else if (point.starts_with("site:")) {
    out.point = BodyPoint::kSite;
    out.site = r.resolve(mjOBJ_SITE, point.substr(5), prefix + ".point");
    if (const int owner = model.get()->site_bodyid[out.site]; owner != out.id)
      r.fail(prefix + ".point",
             fmt::format("site \"{}\" is fixed in body \"{}\", not in \"{}\"", printable(point.substr(5)),
                         printable(model.name_of(mjOBJ_BODY, owner)), printable(out.name)));
  } else {
    r.fail(prefix + ".point",
           fmt::format("expected \"com\", \"origin\" or \"site:NAME\"; got \"{}\"", printable(point)));
  }
}

// What a term of kind `term` reads besides the keys every term has.
void read_term_specifics(const TaskReader& r, const MujocoModel& model, const toml::node& node,
                         const std::string& term, const std::string& prefix, MujocoTask& task,
                         RewardTerm& out) {
  const mjModel* m = model.get();
  const toml::node_view<const toml::node> v{node};
  if (term == "body_velocity" || term == "displacement") {
    out.kind = term == "displacement" ? RewardKind::kDisplacement : RewardKind::kBodyVelocity;
    out.name = r.string(v["body"], prefix + ".body");
    out.id = r.resolve(mjOBJ_BODY, out.name, prefix + ".body");
    out.axis = r.integer(v["axis"], prefix + ".axis", 0, 0, 2);
    read_body_point(r, model, v, prefix, out);
    if (out.kind == RewardKind::kDisplacement) out.slot = task.displacement_terms++;
  } else if (term == "healthy") {
    out.kind = RewardKind::kHealthy;
  } else if (term == "site_distance") {
    out.kind = RewardKind::kSiteDistance;
    out.name = r.string(v["site"], prefix + ".site");
    out.id = r.resolve(mjOBJ_SITE, out.name, prefix + ".site");
    const toml::array* target = v["target"].as_array();
    if (!target || target->size() != 3) r.fail(prefix + ".target", "expected [x, y, z] in metres");
    // Finite numbers: a NaN target would make every distance NaN, and so every return.
    for (int k = 0; k < 3; ++k)
      out.target[static_cast<std::size_t>(k)] = r.fields().number(
          &(*target)[static_cast<std::size_t>(k)], fmt::format("{}.target[{}]", prefix, k), 0.0);
  } else if (term == "joint_target") {
    out.kind = RewardKind::kJointTarget;
    out.name = r.string(v["joint"], prefix + ".joint");
    out.id = r.scalar_joint(out.name, prefix + ".joint");
    out.adr = m->jnt_qposadr[out.id];
    if (!v["target"]) r.fail(prefix + ".target", "missing (expected the joint's target position)");
    out.target[0] = r.number(v["target"], prefix + ".target", 0.0);
  } else if (term == "joint_speed" || term == "joint_velocity") {
    out.kind = term == "joint_speed" ? RewardKind::kJointSpeed : RewardKind::kJointVelocity;
    out.name = r.string(v["joint"], prefix + ".joint");
    out.id = r.scalar_joint(out.name, prefix + ".joint");
    out.adr = m->jnt_dofadr[out.id];
  } else if (term == "energy") {
    out.kind = RewardKind::kEnergy;
    if (!v["target"]) r.fail(prefix + ".target", "missing (expected the target mechanical energy in J)");
    out.target[0] = r.number(v["target"], prefix + ".target", 0.0);
  } else if (term == "in_range") {
    out.kind = RewardKind::kInRange;
    out.range = read_range(r, m, node, prefix, false);
    out.name = out.range.name;
  } else if (term == "control_cost") {
    out.kind = RewardKind::kControlCost;
  } else if (term == "contact_cost") {
    out.kind = RewardKind::kContactCost;
  } else {
    r.fail(
        prefix + ".term",
        fmt::format("expected one of body_velocity, displacement, healthy, site_distance, joint_target, "
                    "joint_speed, joint_velocity, energy, in_range, control_cost, contact_cost; got \"{}\"",
                    printable(term)));
  }
}

// A key another term reads (a body on a healthy term, say) would be ignored without a word.
void check_term_keys(const TaskReader& r, const toml::table& t, const std::string& term, RewardKind kind,
                     const std::string& prefix) {
  const std::map<RewardKind, std::set<std::string>> own_keys = {
      {RewardKind::kBodyVelocity, {"body", "axis", "point"}},
      {RewardKind::kDisplacement, {"body", "axis", "point"}},
      {RewardKind::kJointVelocity, {"joint"}},
      {RewardKind::kSiteDistance, {"site", "target"}},
      {RewardKind::kJointTarget, {"joint", "target"}},
      {RewardKind::kJointSpeed, {"joint"}},
      {RewardKind::kEnergy, {"target"}},
      {RewardKind::kInRange, {"quantity", "name", "min", "max", "bounds"}}};
  const auto it = own_keys.find(kind);
  const std::set<std::string> none;
  const std::set<std::string>& own = it == own_keys.end() ? none : it->second;
  for (const auto& [key, node] : t) {
    const std::string name(key.str());
    if (name == "term" || name == "weight" || name == "cap" || name == "training_only" || own.contains(name))
      continue;
    std::string takes = "term, weight, cap, training_only";
    for (const auto& k : own) takes += ", " + k;
    r.fields().fail(&node, prefix + "." + name,
                    fmt::format("the {} term does not read this key (it takes {})", term, takes));
  }
}

// One [[reward]] term: the keys every term has, then its own.
RewardTerm read_reward_term(const TaskReader& r, const MujocoModel& model, const toml::node& node,
                            const std::string& prefix, MujocoTask& task) {
  const toml::table* t = node.as_table();
  if (!t) r.fail(prefix, "expected a table");
  r.check_keys(*t, prefix,
               {"term", "weight", "cap", "training_only", "body", "axis", "point", "site", "joint", "target",
                "quantity", "name", "min", "max", "bounds"});
  const toml::node_view<const toml::node> v{*t};
  const std::string term = r.string(v["term"], prefix + ".term");
  RewardTerm out{};
  out.weight = r.number(v["weight"], prefix + ".weight", 1.0);
  out.cap = r.number(v["cap"], prefix + ".cap", out.cap);
  if (const toml::node* only = t->get("training_only")) {
    const auto flag = only->value_exact<bool>();
    if (!flag) r.fields().fail(only, prefix + ".training_only", "expected true or false");
    out.training_only = *flag;
  }
  read_term_specifics(r, model, node, term, prefix, task, out);
  check_term_keys(r, *t, term, out.kind, prefix);
  return out;
}

// [success]: the ranges a success holds, for how long and when; with them the return is no bar unless the
// file sets one.
void read_success(const TaskReader& r, const mjModel* m, const toml::table& root, const toml::table& success,
                  MujocoTask& task) {
  r.check_keys(success, "success", {"hold_steps", "at", "range"});
  const toml::node_view<const toml::node> v{success};
  task.success_hold_steps = r.integer(v["hold_steps"], "success.hold_steps", 1, 1, task.horizon);
  if (v["at"]) {
    task.success_anywhere = r.fields().choice(v["at"].node(), "success.at", "end", {"end", "any"}) == "any";
  }
  const toml::array* ranges = v["range"].as_array();
  if (!ranges || ranges->empty()) r.fail("success.range", "missing (expected [[success.range]] tables)");
  for (std::size_t i = 0; i < ranges->size(); ++i)
    task.success_ranges.push_back(read_range(r, m, (*ranges)[i], fmt::format("success.range[{}]", i)));
  const toml::node_view<const toml::node> top{root};
  task.success_return = r.number(top["success_return"], "success_return", -INFINITY);
}

MujocoTask mujoco_task_from_toml(const toml::table& root, const std::filesystem::path& path,
                                 const MujocoModel& model) {
  const mjModel* m = model.get();
  // The model's fault, not the task file's: named first, whatever the task says.
  if (m->nu < 1)
    throw InputError(fmt::format("{}: the model has no actuators (nothing for a policy to drive)",
                                 model.path().empty() ? std::string("model") : model.path().string()));
  TaskReader r(path, model);
  MujocoTask task;
  read_top_level(r, root, task);
  if (const toml::table* initial = root["initial"].as_table()) read_initial(r, m, *initial, task);
  if (const toml::table* noise = root["noise"].as_table()) read_noise(r, *noise, task);
  read_observation(r, m, root["observation"].as_table(), task);

  const toml::array* reward = root["reward"].as_array();
  if (!reward || reward->empty()) r.fail("reward", "missing (expected [[reward]] terms)");
  for (std::size_t i = 0; i < reward->size(); ++i)
    task.reward.push_back(read_reward_term(r, model, (*reward)[i], fmt::format("reward[{}]", i), task));

  if (const toml::array* termination = root["termination"].as_array()) {
    for (std::size_t i = 0; i < termination->size(); ++i)
      task.termination.push_back(read_range(r, m, (*termination)[i], fmt::format("termination[{}]", i)));
  } else if (root["termination"]) {
    r.fail("termination", "expected [[termination]] tables");
  }

  if (const toml::table* success = root["success"].as_table()) {
    read_success(r, m, root, *success, task);
  } else if (root["success"]) {
    r.fail("success", "expected a [success] table");
  }

  // No bound on the scenario numbers a start or a step draws: each rollout slot holds buffers of the model's
  // own sizes (MujocoSlot).
  return task;
}
}  // namespace

}  // namespace pegasus
