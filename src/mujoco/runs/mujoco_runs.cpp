#include "pegasus/mujoco/runs/mujoco_runs.hpp"

#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <tuple>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/sha256.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/parallel/mpi.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus {

// ARS (Mania, Guy and Recht 2018) by default, 100 iterations of every iterative method.
OptimizerOptions mujoco_default_optimizer() {
  OptimizerOptions o;
  o.method = "ars";
  ForEachOptimizerMethod([&](auto member) {
    if constexpr (requires { (o.*member).max_iterations; }) (o.*member).max_iterations = 100;
  });
  o.ars.directions = 8;
  o.ars.top_directions = 4;
  o.hill_climbing.proposals_per_iteration = 8;
  o.hill_climbing.initial_step = 0.1;
  return o;
}

namespace {

// Seeds of the held-out evaluation scenarios, apart from the training scenarios' seed.
std::uint64_t evaluation_seed(std::uint64_t seed) { return seed * 0x9E3779B97F4A7C15ULL + 0x4D4A4556ULL; }

struct Problem {
  std::shared_ptr<const MujocoEnvironment> env;
  std::shared_ptr<const MujocoPolicy> policy;
  PolicyPhase phase;  // the policy's switch, its position resolved in the task's observation
};

// `phase_field` names where the phase's observation came from in messages.
Problem load_problem(const std::string& model_path, const std::string& task_path,
                     const std::string& policy_class, const std::vector<int>& hidden, PolicyPhase phase,
                     std::string_view phase_field) {
  if (model_path.empty()) throw InputError("model: expected an MJCF file (--model M.xml)");
  if (task_path.empty()) throw InputError("task: expected a task file (--task T.toml)");
  MujocoModel model = MujocoModel::load(model_path);
  MujocoTask task = load_mujoco_task(task_path, model);
  if (phase.phased()) phase.position = observation_position(task, phase.observation, phase_field);
  auto env = std::make_shared<const MujocoEnvironment>(std::move(model), std::move(task));
  auto policy = std::shared_ptr<const MujocoPolicy>(
      make_mujoco_policy(policy_class, env->observation_dim(), env->action_dim(), hidden, phase));
  return {env, policy, phase};
}

// success_rate is null when the task has no success criterion; mean_training_return (the return of the
// reward with its training-only terms) only when the task has such terms.
nlohmann::json evaluation_json(const std::vector<MujocoRolloutResult>& results, const MujocoTask& task) {
  double sum = 0.0, training_sum = 0.0;
  int successes = 0, crashes = 0;
  std::int64_t steps = 0;
  for (const auto& r : results) {
    sum += r.discounted_return;
    training_sum += r.training_return;
    successes += r.success ? 1 : 0;
    crashes += r.crashed ? 1 : 0;
    steps += r.steps;
  }
  const double n = static_cast<double>(results.size());
  nlohmann::json out = {
      {"episodes", results.size()},
      {"mean_return", sum / n},
      {"success_rate", task.has_success_criterion() ? nlohmann::json(successes / n) : nullptr},
      {"crashes", crashes},
      {"control_steps", steps}};
  if (task.has_training_only_terms()) out["mean_training_return"] = number_or_null(training_sum / n);
  return out;
}

// The reward the search maximised and the one the results are of, as the summary records them.
nlohmann::json reward_json(const MujocoTask& task) {
  static constexpr const char* kKinds[] = {"body_velocity", "healthy",        "site_distance", "joint_target",
                                           "joint_speed",   "in_range",       "energy",        "control_cost",
                                           "contact_cost",  "joint_velocity", "displacement"};
  nlohmann::json training_only = nlohmann::json::array();
  for (std::size_t i = 0; i < task.reward.size(); ++i)
    if (task.reward[i].training_only)
      training_only.push_back(fmt::format("reward[{}] {}", i, kKinds[static_cast<int>(task.reward[i].kind)]));
  return {{"terms", task.reward.size()},
          {"training_only_terms", training_only},
          {"uhat_of",
           training_only.empty() ? "task reward" : "training reward (task reward and training-only terms)"},
          {"evaluation_of", "task reward"}};
}

// The U-hat of every iteration's central policy (ARS: the policy the iteration moved to), beside the best
// so far that the optimizer's history holds: progress.csv's central_uhat. NaN for methods without one.
class CentralRecorder final : public IterationCallback {
 public:
  explicit CentralRecorder(MujocoObjective& objective) : objective_(objective) {}
  CallbackReturnType operator()(const IterationReport&) override {
    values.push_back(objective_.TakeCentralValue());
    return CallbackReturnType::kContinue;
  }
  std::vector<double> values;

 private:
  MujocoObjective& objective_;
};

CsvWriter progress_csv(const std::vector<IterationRecord>& history, const std::vector<double>& central) {
  CsvWriter csv({"iteration", "evaluations", "seconds", "objective", "central_uhat"});
  for (std::size_t i = 0; i < history.size(); ++i) {
    const IterationRecord& h = history[i];
    const double c = i < central.size() ? central[i] : std::numeric_limits<double>::quiet_NaN();
    csv.add_row({h.iteration, h.evaluations, h.seconds, h.value,
                 std::isfinite(c) ? CsvCell(c) : CsvCell(std::string())});
  }
  return csv;
}

// Stops the search at the end of the first iteration that ends past the budget. Under mpirun rank 0's clock
// decides for every rank (the ranks' clocks differ, and a rank that stopped alone would leave the others
// waiting in a collective).
class TimeBudget final : public IterationCallback {
 public:
  explicit TimeBudget(double seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  CallbackReturnType operator()(const IterationReport&) override {
    reached_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() >= seconds_;
    if (mpi::size() > 1) reached_ = mpi::broadcast_from_root(reached_ ? "1" : "0") == "1";
    return reached_ ? CallbackReturnType::kTerminate : CallbackReturnType::kContinue;
  }
  bool reached() const { return reached_; }

 private:
  double seconds_;
  std::chrono::steady_clock::time_point start_;
  bool reached_ = false;
};

// The task's success criterion, as the summary records it.
nlohmann::json success_json(const MujocoEnvironment& env) {
  const MujocoTask& task = env.task();
  nlohmann::json ranges = nlohmann::json::array();
  static constexpr const char* kQuantities[] = {"qpos", "qvel", "body_height", "site_height"};
  for (const auto& r : task.success_ranges)
    ranges.push_back({{"quantity", kQuantities[static_cast<int>(r.kind)]},
                      {"name", r.name},
                      {"min", number_or_null(r.lower)},
                      {"max", number_or_null(r.upper)}});
  return {{"return", number_or_null(task.success_return)},
          {"bonus", task.success_bonus},
          {"hold_steps", task.success_hold_steps},
          {"at", task.success_anywhere ? "any" : "end"},
          {"ranges", ranges}};
}

CsvWriter evaluation_csv(const std::vector<MujocoRolloutResult>& results) {
  CsvWriter csv({"episode", "return", "steps", "crashed", "success"});
  for (std::size_t i = 0; i < results.size(); ++i)
    csv.add_row({static_cast<std::int64_t>(i), results[i].discounted_return,
                 static_cast<std::int64_t>(results[i].steps), static_cast<std::int64_t>(results[i].crashed),
                 static_cast<std::int64_t>(results[i].success)});
  return csv;
}

// The 3-D replay of one rollout (the report draws it with three.js primitives): every geom's type, size and
// colour once, and per control step (the start included) its world position and orientation, MuJoCo's z-up
// world frame, quaternions (w, x, y, z). Written as replay.json by `mujoco train` (held-out episode 0) and
// `mujoco rollout` (episode 0).
// The 3-D replay of replay.json: every geom of the model as a three.js primitive after each control step.
ChartSection replay_section(const std::string& what) {
  return {
      .id = "replay",
      .title = "3-D replay",
      .intro = what +
               " (replay.json): every geom of the model drawn as a three.js primitive at its world "
               "position and orientation after each control step. Drag to turn the view, scroll to "
               "zoom; Play runs the episode in real time, the slider moves through it.",
      .charts = {
          {.kind = ChartKind::kMujocoReplay, .title = "3-D replay", .traces = {{.file = "replay.json"}}}}};
}

nlohmann::json replay_json(const MujocoEnvironment& env, const MujocoPolicy& policy,
                           std::span<const double> theta, const ObservationNormalizer& normalizer,
                           const ScenarioSet& scenarios) {
  const mjModel* m = env.model().get();
  static constexpr const char* kTypes[] = {"plane",     "hfield",   "sphere", "capsule",
                                           "ellipsoid", "cylinder", "box",    "mesh"};
  nlohmann::json geoms = nlohmann::json::array();
  for (int g = 0; g < m->ngeom; ++g) {
    const int type = m->geom_type[g];
    geoms.push_back(
        {{"name", env.model().name_of(mjOBJ_GEOM, g)},
         {"type", type >= 0 && type < 8 ? kTypes[type] : "other"},
         {"size", {m->geom_size[3 * g], m->geom_size[3 * g + 1], m->geom_size[3 * g + 2]}},
         {"rgba",
          {m->geom_rgba[4 * g], m->geom_rgba[4 * g + 1], m->geom_rgba[4 * g + 2], m->geom_rgba[4 * g + 3]}}});
  }
  nlohmann::json t = nlohmann::json::array(), frames = nlohmann::json::array();
  const MujocoStepObserver record = [&](int, const mjData* d, std::span<const double>, double) {
    t.push_back(d->time);
    std::vector<double> frame;
    frame.reserve(static_cast<std::size_t>(7 * m->ngeom));
    for (int g = 0; g < m->ngeom; ++g) {
      mjtNum q[4];
      mju_mat2Quat(q, d->geom_xmat + 9 * g);
      for (int k = 0; k < 3; ++k) frame.push_back(d->geom_xpos[3 * g + k]);
      for (int k = 0; k < 4; ++k) frame.push_back(q[k]);
    }
    frames.push_back(std::move(frame));
  };
  MujocoSlot slot(env);
  env.rollout(policy, theta, normalizer, scenarios, 0, slot, nullptr, &record);
  return {{"format", "pegasus.mujoco.replay"},
          {"version", 1},
          {"model", env.model().path().filename().string()},
          {"geoms", geoms},
          {"t", t},
          {"frames", frames}};
}

// The theta of --initial-policy, checked against this run's policy; empty when none is given.
Theta initial_theta(const MujocoTrainingRunOptions& o, const Problem& problem) {
  const std::string& path = o.initial_policy_file;
  if (path.empty()) return {};
  const MujocoPolicyFile start = read_mujoco_policy_file(path);
  const nlohmann::json shape = problem.policy->describe();
  if (start.policy_class != shape.at("class").get<std::string>() ||
      start.hidden != shape.at("hidden").get<std::vector<int>>())
    throw InputError(fmt::format(
        "initial_policy: {} holds a {} policy with hidden widths [{}]; this run trains a "
        "{} policy with [{}]",
        path, start.policy_class, fmt::join(start.hidden, ", "), shape.at("class").get<std::string>(),
        fmt::join(shape.at("hidden").get<std::vector<int>>(), ", ")));
  if (const PolicyPhase& phase = problem.phase; !start.phase.same_switch(phase)) {
    auto said = [](const PolicyPhase& p) {
      return p.phased() ? fmt::format("phased by {} above {}", p.observation, p.above)
                        : std::string("unphased");
    };
    throw InputError(fmt::format("initial_policy: {} holds a policy {}; this run trains one {}", path,
                                 said(start.phase), said(phase)));
  }
  if (o.normalize)
    throw InputError(
        "initial_policy: only with normalize = false (this run's observation statistics would replace the "
        "file's from the first iteration, and its theta would see other inputs)");
  check_mujoco_policy_file(start, *problem.policy, problem.env->observation_dim(), path);
  return start.theta;
}

// The objective's counters (steps, rollouts, crashes, first success) and observation statistics ride in
// every checkpoint, whatever the method: ARS also keeps them in its own state, but CMA-ES and the others do
// not, and a resumed run must end with the uninterrupted run's summary.
// progress.csv's central U-hat of the iterations before a resume rides there too.
void carry_objective_state(TrainingPlan& plan, MujocoObjective& objective, CentralRecorder& central) {
  plan.caller_state = [&objective, &central] {
    nlohmann::json state = objective.NormalizerState();
    nlohmann::json values = nlohmann::json::array();
    for (const double v : central.values) values.push_back(number_or_null(v));
    state["central_uhat"] = values;
    return state;
  };
  if (plan.resume_from && plan.resume_from->contains("caller") && !plan.resume_from->at("caller").is_null()) {
    const nlohmann::json& caller = plan.resume_from->at("caller");
    objective.RestoreNormalizer(caller);
    if (caller.contains("central_uhat") && caller.at("central_uhat").is_array())
      for (const auto& v : caller.at("central_uhat"))
        central.values.push_back(v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN());
  }
}

// policy.json: the policy with the model's and task's files and digests it was trained on.
void write_mujoco_policy(RunDirectory& dir, const MujocoTrainingRunOptions& o, const Problem& problem,
                         const Theta& theta, const MujocoObjective& objective) {
  const MujocoEnvironment& env = *problem.env;
  const nlohmann::json shape = problem.policy->describe();
  const MujocoPolicyFile policy{.model = std::filesystem::absolute(o.model_file).string(),
                                .task = std::filesystem::absolute(o.task_file).string(),
                                .model_digest = env.model().digest(),
                                .task_digest = file_sha256(o.task_file),
                                .task_content_digest = mujoco_task_content_digest(o.task_file),
                                .policy_class = shape.at("class").get<std::string>(),
                                .hidden = shape.at("hidden").get<std::vector<int>>(),
                                .phase = problem.phase,
                                .theta = theta,
                                .normalizer = objective.normalizer()};
  dir.write_json("policy.json", mujoco_policy_file_json(policy));
}

// summary.json of a training run: identical for any threads and ranks (wall-clock figures go to run.json).
nlohmann::json training_summary_json(const MujocoTrainingRunOptions& o, const Problem& problem,
                                     const OptimizerSummary& summary, const MujocoObjective& objective,
                                     bool stopped_by_budget, const nlohmann::json& evaluation) {
  const MujocoEnvironment& env = *problem.env;
  const std::int64_t frame_skip = env.task().frame_skip;
  nlohmann::json first_success = nullptr;
  if (const auto& f = objective.first_success())
    first_success = {{"evaluation", f->evaluation},
                     {"control_steps", f->control_steps},
                     {"physics_steps", f->control_steps * frame_skip}};
  return {{"experiment", "mujoco train"},
          {"method", summary.method},
          {"policy_class", problem.policy->describe().at("class")},
          {"phase", policy_phase_json(problem.phase)},
          {"parameters", problem.policy->parameters().size()},
          {"observation_dim", env.observation_dim()},
          {"action_dim", env.action_dim()},
          {"scenarios", o.scenarios},
          {"horizon", env.task().horizon},
          {"frame_skip", frame_skip},
          {"integrator", env.integrator()},
          {"reward", reward_json(env.task())},
          {"time_budget_seconds",
           o.time_budget_seconds > 0.0 ? nlohmann::json(o.time_budget_seconds) : nlohmann::json(nullptr)},
          {"stopped_by_time_budget", stopped_by_budget},
          {"termination", std::string(TerminationTypeName(summary.termination_type))},
          {"message", summary.message},
          {"iterations", summary.iterations},
          {"evaluations", summary.evaluations},
          {"initial_uhat", number_or_null(summary.initial_value)},
          {"final_uhat", number_or_null(summary.best_value)},
          {"uhat_finite", std::isfinite(summary.best_value)},
          {"nonfinite_uhat_evaluations", objective.nonfinite_evaluations()},
          {"training_rollouts", objective.rollouts()},
          {"training_control_steps", objective.control_steps()},
          {"training_physics_steps", objective.control_steps() * frame_skip},
          {"training_crashes", objective.crashes()},
          {"first_success", first_success},
          {"success_return", number_or_null(env.task().success_return)},
          {"success", success_json(env)},
          {"evaluation", evaluation}};
}

// The printed result, and the exit code: 1 where U-hat of the result, or of any evaluation on the way, was
// not finite.
int say_training_result(std::ostream& out, const MujocoTrainingRunOptions& o, const OptimizerSummary& summary,
                        const MujocoObjective& objective, bool stopped_by_budget,
                        const nlohmann::json& evaluation) {
  out << summary.BriefReport() << "\n";
  const nlohmann::json& rate = evaluation.at("success_rate");
  out << fmt::format(
      "held-out: mean return {:.3f}{} over {} episodes ({} crashes){}; {} training control steps\n",
      evaluation.at("mean_return").get<double>(),
      rate.is_null() ? "" : fmt::format(", success rate {:.3f}", rate.get<double>()), o.evaluation_episodes,
      evaluation.at("crashes").get<int>(), rate.is_null() ? ", no success criterion in the task" : "",
      objective.control_steps());
  if (stopped_by_budget)
    out << fmt::format("stopped by the time budget of {} s after {} iterations\n", o.time_budget_seconds,
                       summary.iterations);
  if (!std::isfinite(summary.best_value)) {
    out << fmt::format(
        "error: U-hat of the policy found is not finite ({}): no result; summary.json has uhat_finite = "
        "false\n",
        summary.best_value);
    return 1;
  }
  // A finite result of a search that met a non-finite U-hat on the way (ARS and CMA-ES then stop with
  // FAILURE) is not trusted either.
  if (objective.nonfinite_evaluations() > 0) {
    out << fmt::format(
        "error: {} evaluations of U-hat were not finite (the first: evaluation {}); the search's result is "
        "not "
        "trusted; summary.json has nonfinite_uhat_evaluations\n",
        objective.nonfinite_evaluations(), objective.first_nonfinite_evaluation());
    return 1;
  }
  return 0;
}

}  // namespace

int run_mujoco_training(const MujocoTrainingRunOptions& o, RunSink& sink, ThreadPool& pool) {
  const Problem problem =
      load_problem(o.model_file, o.task_file, o.policy_class, o.hidden,
                   {.observation = o.phase_observation, .above = o.phase_above}, "--phase-observation");
  const MujocoEnvironment& env = *problem.env;
  OptimizerOptions options = o.optimizer;
  // Every random method draws from the run's seed itself (the figures of experiments/mujoco/README.md were
  // measured so).
  options.SetSeeds(o.seed);
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);

  Theta theta = initial_theta(o, problem);  // checked before the run directory is made
  RunDirectory& dir = sink.dir;
  MujocoObjective objective(problem.env, problem.policy, env.scenarios(o.seed, o.scenarios, o.variant), &pool,
                            o.normalize);
  auto bar = sink.progress("iterations", static_cast<std::uint64_t>(options.IterationLimit()));
  std::int64_t shown = 0;
  TrainingPlan plan;
  plan.seed = o.seed;
  plan.stages = {{.name = options.method, .optimizer = options, .derive_seeds = false}};
  plan.refuse_nonfinite_result = false;  // said below as the run's verdict, with its summary
  plan.checkpoint_every = o.checkpoint_every;
  plan.on_checkpoint = [&](const nlohmann::json& checkpoint) {
    dir.save_checkpoint(checkpoint);
    const std::int64_t done = TrainingCheckpointIterations(checkpoint);
    bar.advance(static_cast<std::uint64_t>(std::max<std::int64_t>(0, done - shown)));
    shown = done;
  };
  plan.resume_from = dir.load_checkpoint();
  CentralRecorder central(objective);
  carry_objective_state(plan, objective, central);
  plan.callbacks.push_back(&central);
  TimeBudget budget(o.time_budget_seconds);
  if (o.time_budget_seconds > 0.0) plan.callbacks.push_back(&budget);
  if (env.task().has_training_only_terms())
    sink.out << "note: training_only reward terms count in U-hat only, held-out returns are of the full task "
                "reward; a constant shift in a task with termination is not potential-based (thesis ch. 3), "
                "so the policy found can differ from the full reward's optimum\n";
  TrainingSummary training;
  Train(plan, objective, &theta, &training);
  const OptimizerSummary& summary = training.stages.front();
  bar.finish();

  const ScenarioSet held_out =
      env.scenarios(evaluation_seed(o.seed), o.evaluation_episodes, ScenarioVariant::kPlain);
  const auto results = objective.rollout_all(theta, held_out);
  const nlohmann::json evaluation = evaluation_json(results, env.task());
  dir.write_json("replay.json", replay_json(env, *problem.policy, theta, objective.normalizer(), held_out));

  dir.write_csv("progress.csv", progress_csv(summary.history, central.values));
  dir.write_csv("evaluation.csv", evaluation_csv(results));
  dir.add_charts({optimizer_progress_section({{"", "progress.csv"}},
                                             "U-hat of the best policy so far against "
                                             "optimizer iterations, evaluations and time (progress.csv's "
                                             "central_uhat column holds each iteration's central policy)."),
                  replay_section("Held-out episode 0 of the final policy")});
  write_mujoco_policy(dir, o, problem, theta, objective);
  sink.timings = {{"training_seconds", summary.wall_seconds}, {"seconds_to_first_success", nullptr}};
  if (const auto& f = objective.first_success()) sink.timings["seconds_to_first_success"] = f->seconds;
  dir.write_json("summary.json",
                 training_summary_json(o, problem, summary, objective, budget.reached(), evaluation));
  // Wall-clock measurements go to run.json ("timings"): summary.json is identical for any threads and ranks.
  return say_training_result(sink.out, o, summary, objective, budget.reached(), evaluation);
}

void run_mujoco_rollout(const MujocoRolloutRunOptions& o, RunSink& sink, ThreadPool& pool) {
  if (o.policy_file.empty()) throw InputError("policy: expected a policy file (--policy FILE)");
  const MujocoPolicyFile file = read_mujoco_policy_file(o.policy_file);
  const bool other_task = !o.task_file.empty();
  const std::string task_file = other_task ? o.task_file : file.task;
  const Problem problem = load_problem(file.model, task_file, file.policy_class, file.hidden, file.phase,
                                       fmt::format("{}: phase.observation", o.policy_file));
  const MujocoEnvironment& env = *problem.env;
  check_mujoco_policy_file(file, *problem.policy, env.observation_dim(), o.policy_file);
  // The files as they are now, which may not be what the policy was trained on: allowed, but not unsaid. The
  // task is compared by its parsed content where the policy file has it (an edited comment is no change).
  const bool by_content = !file.task_content_digest.empty();
  std::vector<std::tuple<std::string, std::string, std::string, std::string>> inputs = {
      {"model", file.model, file.model_digest, env.model().digest()}};
  if (!other_task)
    inputs.emplace_back("task", file.task, by_content ? file.task_content_digest : file.task_digest,
                        by_content ? mujoco_task_content_digest(file.task) : file_sha256(file.task));
  for (const auto& [what, path, then, now] : inputs)
    if (!then.empty() && then != now)
      sink.out << fmt::format(
          "warning: the {} {} has changed since {} was trained on it; the rollout uses it as it "
          "is now\n",
          what, printable(path), printable(o.policy_file));
  if (other_task)
    sink.out << fmt::format("rollout under the task {} (the policy was trained on {})\n",
                            printable(task_file), printable(file.task));
  const std::vector<double>& theta = file.theta;
  const ObservationNormalizer& normalizer = file.normalizer;

  const int episodes = o.episodes;
  const ScenarioSet scenarios = env.scenarios(evaluation_seed(o.seed), episodes, ScenarioVariant::kPlain);
  const mjModel* m = env.model().get();
  std::vector<std::string> header = {"step", "time", "reward"};
  for (int j = 0; j < m->nq; ++j) header.push_back(fmt::format("qpos{}", j));
  for (int b = 1; b < m->nbody; ++b)
    for (const char axis : {'x', 'y', 'z'}) {
      const std::string name = env.model().name_of(mjOBJ_BODY, b);
      header.push_back(fmt::format("{}_{}", name.empty() ? fmt::format("body{}", b) : name, axis));
    }
  CsvWriter trajectory(header);
  const MujocoStepObserver record = [&](int t, const mjData* d, std::span<const double>, double reward) {
    std::vector<CsvCell> row = {static_cast<std::int64_t>(t), d->time, reward};
    for (int j = 0; j < m->nq; ++j) row.push_back(d->qpos[j]);
    for (int b = 1; b < m->nbody; ++b)
      for (int k = 0; k < 3; ++k) row.push_back(d->xpos[3 * b + k]);
    trajectory.add_row(std::move(row));
  };
  std::vector<MujocoRolloutResult> results(static_cast<std::size_t>(episodes));
  {
    MujocoSlot slot(env);
    results[0] = env.rollout(*problem.policy, theta, normalizer, scenarios, 0, slot, nullptr, &record);
  }
  // The other episodes on every thread, each worker with one slot of its own; every episode's result is a
  // function of its scenario alone, so they do not depend on the threads.
  const std::size_t rest = results.size() - 1;
  const std::size_t workers = std::min<std::size_t>(static_cast<std::size_t>(pool.size()), rest);
  pool.parallel_for(
      workers,
      [&](std::size_t w) {
        MujocoSlot slot(env);
        for (std::size_t i = 1 + w; i < results.size(); i += workers)
          results[i] = env.rollout(*problem.policy, theta, normalizer, scenarios, static_cast<int>(i), slot);
      },
      1);

  RunDirectory& dir = sink.dir;
  const nlohmann::json evaluation = evaluation_json(results, env.task());
  dir.write_csv("returns.csv", evaluation_csv(results));
  dir.write_csv("trajectory.csv", trajectory);
  dir.write_json("replay.json", replay_json(env, *problem.policy, theta, normalizer, scenarios));
  dir.add_charts(replay_section("Episode 0 of the rollout"));
  dir.write_json("summary.json", {{"experiment", "mujoco rollout"},
                                  {"task", other_task ? nlohmann::json(task_file) : nlohmann::json(nullptr)},
                                  {"integrator", env.integrator()},
                                  {"success_return", number_or_null(env.task().success_return)},
                                  {"success", success_json(env)},
                                  {"evaluation", evaluation}});
  sink.out << fmt::format("mean return {:.3f} over {} episodes\n", evaluation.at("mean_return").get<double>(),
                          episodes);
}

}  // namespace pegasus
#endif
