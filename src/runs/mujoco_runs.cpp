#include "pegasus/runs/mujoco_runs.hpp"

#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/optimizers/training.hpp"
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

// success_rate is null when the task has no success criterion.
nlohmann::json evaluation_json(const std::vector<MujocoRolloutResult>& results, const MujocoTask& task) {
  double sum = 0.0;
  int successes = 0, crashes = 0;
  std::int64_t steps = 0;
  for (const auto& r : results) {
    sum += r.discounted_return;
    successes += r.success ? 1 : 0;
    crashes += r.crashed ? 1 : 0;
    steps += r.steps;
  }
  const double n = static_cast<double>(results.size());
  return {{"episodes", results.size()},
          {"mean_return", sum / n},
          {"success_rate", task.has_success_criterion() ? nlohmann::json(successes / n) : nullptr},
          {"crashes", crashes},
          {"control_steps", steps}};
}

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

}  // namespace

void run_mujoco_training(const MujocoTrainingRunOptions& o, RunSink& sink, ThreadPool& pool) {
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
  const int m = o.scenarios;
  MujocoObjective objective(problem.env, problem.policy, env.scenarios(o.seed, m, o.variant), &pool,
                            o.normalize);
  auto bar = sink.progress("iterations", static_cast<std::uint64_t>(options.IterationLimit()));
  std::int64_t shown = 0;
  TrainingPlan plan;
  plan.seed = o.seed;
  plan.stages = {{.name = options.method, .optimizer = options, .derive_seeds = false}};
  plan.checkpoint_every = o.checkpoint_every;
  plan.on_checkpoint = [&](const nlohmann::json& checkpoint) {
    dir.save_checkpoint(checkpoint);
    const std::int64_t done = TrainingCheckpointIterations(checkpoint);
    bar.advance(static_cast<std::uint64_t>(std::max<std::int64_t>(0, done - shown)));
    shown = done;
  };
  plan.resume_from = dir.load_checkpoint();
  // The objective's counters (steps, rollouts, crashes, first success) and observation statistics ride in
  // every checkpoint, whatever the method: ARS also keeps them in its own state, but CMA-ES and the others do
  // not, and a resumed run must end with the uninterrupted run's summary.
  plan.caller_state = [&objective] { return objective.NormalizerState(); };
  if (plan.resume_from && plan.resume_from->contains("caller") && !plan.resume_from->at("caller").is_null())
    objective.RestoreNormalizer(plan.resume_from->at("caller"));
  TrainingSummary training;
  Train(plan, objective, &theta, &training);
  const OptimizerSummary& summary = training.stages.front();
  bar.finish();

  const int episodes = o.evaluation_episodes;
  const ScenarioSet held_out = env.scenarios(evaluation_seed(o.seed), episodes, ScenarioVariant::kPlain);
  const auto results = objective.rollout_all(theta, held_out);
  const nlohmann::json evaluation = evaluation_json(results, env.task());
  dir.write_json("replay.json", replay_json(env, *problem.policy, theta, objective.normalizer(), held_out));

  dir.write_csv("progress.csv", optimizer_progress_csv(summary.history));
  dir.write_csv("evaluation.csv", evaluation_csv(results));
  dir.add_charts({optimizer_progress_section({{"", "progress.csv"}},
                                             "U-hat of the best policy so far against "
                                             "optimizer iterations, evaluations and time."),
                  replay_section("Held-out episode 0 of the final policy")});
  const nlohmann::json shape = problem.policy->describe();
  const MujocoPolicyFile policy{.model = std::filesystem::absolute(o.model_file).string(),
                                .task = std::filesystem::absolute(o.task_file).string(),
                                .model_digest = env.model().digest(),
                                .task_digest = file_sha256(o.task_file),
                                .policy_class = shape.at("class").get<std::string>(),
                                .hidden = shape.at("hidden").get<std::vector<int>>(),
                                .phase = problem.phase,
                                .theta = theta,
                                .normalizer = objective.normalizer()};
  dir.write_json("policy.json", mujoco_policy_file_json(policy));
  const std::int64_t frame_skip = env.task().frame_skip;
  nlohmann::json first_success = nullptr;
  sink.timings = {{"training_seconds", summary.wall_seconds}, {"seconds_to_first_success", nullptr}};
  if (const auto& f = objective.first_success()) {
    first_success = {{"evaluation", f->evaluation},
                     {"control_steps", f->control_steps},
                     {"physics_steps", f->control_steps * frame_skip}};
    sink.timings["seconds_to_first_success"] = f->seconds;
  }
  dir.write_json("summary.json", {{"experiment", "mujoco train"},
                                  {"method", summary.method},
                                  {"policy_class", shape.at("class")},
                                  {"phase", policy_phase_json(problem.phase)},
                                  {"parameters", problem.policy->parameters().size()},
                                  {"observation_dim", env.observation_dim()},
                                  {"action_dim", env.action_dim()},
                                  {"scenarios", m},
                                  {"horizon", env.task().horizon},
                                  {"frame_skip", frame_skip},
                                  {"termination", std::string(TerminationTypeName(summary.termination_type))},
                                  {"message", summary.message},
                                  {"iterations", summary.iterations},
                                  {"evaluations", summary.evaluations},
                                  {"initial_uhat", number_or_null(summary.initial_value)},
                                  {"final_uhat", summary.best_value},
                                  {"training_rollouts", objective.rollouts()},
                                  {"training_control_steps", objective.control_steps()},
                                  {"training_physics_steps", objective.control_steps() * frame_skip},
                                  {"training_crashes", objective.crashes()},
                                  {"first_success", first_success},
                                  {"success_return", number_or_null(env.task().success_return)},
                                  {"success", success_json(env)},
                                  {"evaluation", evaluation}});
  // Wall-clock measurements go to run.json ("timings"): summary.json is identical for any threads and ranks.
  sink.out << summary.BriefReport() << "\n";
  const nlohmann::json& rate = evaluation.at("success_rate");
  sink.out << fmt::format(
      "held-out: mean return {:.3f}{} over {} episodes ({} crashes){}; {} training control steps\n",
      evaluation.at("mean_return").get<double>(),
      rate.is_null() ? "" : fmt::format(", success rate {:.3f}", rate.get<double>()), episodes,
      evaluation.at("crashes").get<int>(), rate.is_null() ? ", no success criterion in the task" : "",
      objective.control_steps());
}

void run_mujoco_rollout(const MujocoRolloutRunOptions& o, RunSink& sink) {
  if (o.policy_file.empty()) throw InputError("policy: expected a policy file (--policy FILE)");
  const MujocoPolicyFile file = read_mujoco_policy_file(o.policy_file);
  const Problem problem = load_problem(file.model, file.task, file.policy_class, file.hidden, file.phase,
                                       fmt::format("{}: phase.observation", o.policy_file));
  const MujocoEnvironment& env = *problem.env;
  check_mujoco_policy_file(file, *problem.policy, env.observation_dim(), o.policy_file);
  // The files as they are now, which may not be what the policy was trained on: allowed, but not unsaid.
  for (const auto& [what, path, then, now] :
       {std::tuple{"model", file.model, file.model_digest, env.model().digest()},
        std::tuple{"task", file.task, file.task_digest, file_sha256(file.task)}})
    if (!then.empty() && then != now)
      sink.out << fmt::format(
          "warning: the {} {} has changed since {} was trained on it; the rollout uses it as it "
          "is now\n",
          what, printable(path), printable(o.policy_file));
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
  MujocoSlot slot(env);
  for (int i = 0; i < episodes; ++i)
    results[static_cast<std::size_t>(i)] = env.rollout(*problem.policy, theta, normalizer, scenarios, i, slot,
                                                       nullptr, i == 0 ? &record : nullptr);

  RunDirectory& dir = sink.dir;
  const nlohmann::json evaluation = evaluation_json(results, env.task());
  dir.write_csv("returns.csv", evaluation_csv(results));
  dir.write_csv("trajectory.csv", trajectory);
  dir.write_json("replay.json", replay_json(env, *problem.policy, theta, normalizer, scenarios));
  dir.add_charts(replay_section("Episode 0 of the rollout"));
  dir.write_json("summary.json", {{"experiment", "mujoco rollout"},
                                  {"success_return", number_or_null(env.task().success_return)},
                                  {"success", success_json(env)},
                                  {"evaluation", evaluation}});
  sink.out << fmt::format("mean return {:.3f} over {} episodes\n", evaluation.at("mean_return").get<double>(),
                          episodes);
}

}  // namespace pegasus
#endif
