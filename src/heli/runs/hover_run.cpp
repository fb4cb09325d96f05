// `pegasus hover`: train the hover policy on an identified model, in the wind the aircraft will fly in, and
// write the run directory (policy.json, progress.csv, summary.json with the choices made from the data).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/training_wind.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus::heli {

// ------------------------------------------------------------------ hover

namespace {

nlohmann::json start_tries_json(const std::vector<StartTry>& tries) {
  nlohmann::json list = nlohmann::json::array();
  for (const StartTry& t : tries) {
    nlohmann::json entry = {
        {"gains", t.gains}, {"action_weight_factor", t.action_factor}, {"taken", t.taken}};
    if (t.lqr_used)
      entry.update({{"crashed_scenarios", t.check.crashed}, {"scenarios", t.check.scenarios}});
    else
      entry["reason"] = t.reason;
    list.push_back(entry);
  }
  return list;
}

// One line: every start tried, its crash count, and the one taken.
std::string start_tries_line(const std::vector<StartTry>& tries, double max_fraction) {
  std::vector<std::string> parts;
  for (const StartTry& t : tries) {
    const std::string weights =
        t.action_factor == 1 ? "" : fmt::format(", action weights x{:g}", t.action_factor);
    parts.push_back(t.lqr_used ? fmt::format("{}{}: {} of {} crashed{}", t.gains, weights, t.check.crashed,
                                             t.check.scenarios, t.taken ? " (taken)" : "")
                               : fmt::format("{}{}: no gains ({})", t.gains, weights, t.reason));
  }
  return fmt::format("LQR starts tried (at most {:g}% of the scenarios may crash): {}\n", 100 * max_fraction,
                     fmt::join(parts, "; "));
}

// What was chosen from the data, or by the options, in one place (issue 48): the model's class and noise as
// identify chose them, the start, the optimizer.
nlohmann::json hover_choices(const sysid::IdentifiedModel& model, const HoverTrainingOptions& o,
                             const HoverTrainingResult& r) {
  nlohmann::json choices = {{"optimizer", o.optimizer.method}};
  if (model.model_choice().is_object() && model.model_choice().contains("chosen"))
    choices["model_class"] = model.model_choice().at("chosen");
  else
    choices["model_class"] = model.is_global() ? "global linear" : "locally weighted";
  const sysid::NoiseCorrelation& c = model.noise_correlation();
  choices["noise"] = c.has_measurement() ? "ar1+measurement" : c.any() ? "ar1" : "white";
  const auto taken =
      std::find_if(r.start_tries.begin(), r.start_tries.end(), [](const StartTry& t) { return t.taken; });
  if (!o.lqr_start)
    choices["start"] = {{"gains", "constant"}};
  else if (taken == r.start_tries.end())
    choices["start"] = {{"gains", "none survived"}, {"tries", r.start_tries.size()}};
  else
    choices["start"] = {{"gains", taken->gains},
                        {"action_weight_factor", taken->action_factor},
                        {"tries", r.start_tries.size()}};
  if (const HoverPolicyInit limited = hover_command_limits(model, o.command_margin);
      limited.has_command_limits())
    choices["command_limits"] = {{"lower", limited.command_lower},
                                 {"upper", limited.command_upper},
                                 {"margin", o.command_margin},
                                 {"by", "the global linear model's logged controls"}};
  return choices;
}

// The options valid, and the hover target above the ground truth's ground.
void check_hover_options(const HoverRunOptions& options) {
  const HoverTrainingOptions& o = options.training;
  std::string error;
  // "field: what": named as the user gave the field (--integral-seconds, or the config file's key).
  if (!o.IsValid(&error)) {
    const std::size_t colon = error.find(": ");
    if (colon == std::string::npos) throw InputError(error);
    throw ConfigFieldError(error.substr(0, colon), error.substr(colon + 2));
  }
  if (options.aircraft.vehicle.simulator != "none" && !(o.target.z < 0))
    throw ConfigFieldError("target",
                           fmt::format("z = {:g} is at or below the ground of {}'s ground truth (NED: z < 0 "
                                       "is above it)",
                                       o.target.z, options.aircraft.vehicle.name()));
}

// The lines that say what training will do before it starts: the reward's terms, the wind, a control step
// the model stretches, and the evaluation budget where it binds (returned; 0 where none).
std::int64_t say_hover_setup(std::ostream& out, const HoverRunOptions& options,
                             const sysid::IdentifiedModel& model, const TrainingWind& wind) {
  const HoverTrainingOptions& o = options.training;
  // Which terms are in the reward (issue 53): with a judged cost, only the file's.
  out << fmt::format("reward ({}): {}\n",
                     options.judged_cost ? "the vehicle file's [cost], whole" : "the reward.* options",
                     hover_reward_for(model, o).terms(o.crash_penalty));
  // The wind in the scenarios, stated or a vehicle file's default (issue 53): one line, where not the
  // X-Cell's calm.
  if (options.aircraft.from_file() || !o.disturbance.calm()) out << training_wind_line(wind) << "\n";
  // A control step longer than the model's is one model step's change stretched (learned_model.hpp): allowed,
  // and `identify` reports it as training runs it, but not without a word.
  if (const double ratio = model.dt() * o.control_rate_hz; ratio < 1 - 1e-9)
    out << fmt::format(
        "warning: the controller's step ({:g} s) is {:g} steps of the {:g} Hz model, which takes it as one "
        "step's change times {:g}; a model identified at the control rate (log.model_rate_hz) steps it "
        "faithfully\n",
        1 / o.control_rate_hz, 1 / ratio, 1 / model.dt(), 1 / ratio);
  // The command limits of a global linear model's training (issue 48): said where there are any.
  if (const HoverPolicyInit limited = hover_command_limits(model, o.command_margin);
      limited.has_command_limits()) {
    out << command_limits_line(limited, o.command_margin) << "\n";
  }
  // The default budget on a locally weighted model (issues 48, 53): said where it binds.
  const std::int64_t budget =
      o.evaluation_budget(model, static_cast<int>(hover_policy_for(model, o).parameters().size()));
  if (budget > 0)
    out << fmt::format(
        "budget: at most {} U-hat evaluations, about {:g} CPU s of refits of the locally weighted model ({} "
        "rows, refitted every {} control steps; --cpu-budget-s sets it, 0 lifts it)\n",
        budget, o.cpu_budget_s, model.data().x.rows(), o.refit_steps(model));
  return budget;
}

// Training, checkpointed after every iteration and resumed from the run directory's checkpoint, with a bar
// over the iterations.
HoverTrainingResult train_hover_in(RunSink& sink, std::shared_ptr<const sysid::IdentifiedModel> model,
                                   const HoverTrainingOptions& o, ThreadPool& pool) {
  RunDirectory& dir = sink.dir;
  HoverTrainingHooks hooks;
  hooks.checkpoint_every = 1;
  hooks.resume_from = dir.load_checkpoint();
  const bool two = o.optimizer.method == "gradient" && o.then_hill_climb;
  const std::int64_t g_iters = o.optimizer.IterationLimit();
  auto bar = sink.progress(
      "optimizer iterations",
      static_cast<std::uint64_t>(g_iters + (two ? o.optimizer.hill_climbing.max_iterations : 0)));
  std::uint64_t last = 0;
  if (hooks.resume_from) {
    last = static_cast<std::uint64_t>(TrainingCheckpointIterations(*hooks.resume_from));
    bar.skip(last);
  }
  hooks.on_checkpoint = [&](const nlohmann::json& c) {
    dir.save_checkpoint(c);
    const auto done = static_cast<std::uint64_t>(TrainingCheckpointIterations(c));
    if (done > last) bar.advance(done - last);
    last = done;
  };
  // Where stderr is no terminal an iteration's line can be minutes apart: a line on the clock between them.
  EvaluationTally tally;
  hooks.on_evaluations = [&tally](std::span<const double> values) { tally.add(values); };
  HoverTrainingResult r = [&] {  // not const: returned by move
    const ProgressTicker ticker(
        "hover training", [&] { return tally.text(bar.done(), bar.total()); },
        Progress::default_enabled(sink.quiet, dir.ranks()));
    return train_hover(model, o, hooks, pool);
  }();
  bar.finish();
  return r;
}

// progress.csv with its chart, and policy.json of the policy class as training settled it (`used`).
void write_hover_policy(const RunSink& sink, const HoverRunOptions& options,
                        const sysid::IdentifiedModel& model, const HoverTrainingOptions& used,
                        const HoverTrainingResult& r) {
  RunDirectory& dir = sink.dir;
  const HoverTrainingOptions& o = options.training;
  dir.write_csv("progress.csv", optimizer_progress_csv(r.progress));
  const ChartSection progress = optimizer_progress_section(
      {{"", "progress.csv"}},
      "U-hat of the best policy so far against optimizer iterations, evaluations and time.");
  dir.add_charts(progress);
  dir.write_chart_svg("progress.svg", progress.charts.front());
  const HoverPolicy policy = hover_policy_for(model, used);
  PolicyFile file =
      hover_policy_file(policy, r.theta, o.target, hover_init_from_model(model).trim, o.integrator());
  file.provenance = {{"command", "pegasus heli hover"},
                     {"model", sink.named(options.model_file)},
                     {"uhat", r.final_uhat},
                     {"scenarios", o.scenarios},
                     {"seconds", o.seconds},
                     {"seed", o.seed}};
  // Only with a vehicle file, so that the X-Cell's policy files stay as they were.
  if (options.aircraft.from_file()) file.provenance["vehicle"] = options.aircraft.vehicle.name();
  // Only when not 50 Hz, so that policy files trained at the thesis's rate stay as they were.
  if (o.control_rate_hz != 50) file.options["control_rate_hz"] = o.control_rate_hz;
  dir.write_json("policy.json", policy_file_json(file));
}

nlohmann::json optimizer_phase_json(const OptimizerSummary& s) {
  if (s.method.empty()) return nullptr;
  return {
      {"method", s.method},           {"iterations", s.iterations},
      {"evaluations", s.evaluations}, {"initial_uhat", s.initial_value},
      {"best_uhat", s.best_value},    {"termination", std::string(TerminationTypeName(s.termination_type))},
      {"message", s.message}};
}

// summary.json's figures every hover training gives.
nlohmann::json hover_summary_core(const HoverTrainingOptions& o, const HoverTrainingResult& r) {
  const std::int64_t evaluations = r.progress.empty() ? 0 : r.progress.back().evaluations;
  nlohmann::json summary = {{"initial_uhat", r.initial_uhat},
                            {"final_uhat", r.final_uhat},
                            {"iterations", r.progress.size()},
                            {"evaluations", evaluations},
                            {"scenarios", o.scenarios},
                            {"scenario_seconds", o.seconds},
                            {"gamma", o.gamma},
                            {"gradient", nullptr},
                            {"hill_climb", optimizer_phase_json(r.hill_climb)},
                            {"starting_policy",
                             {{"scenarios", r.start.scenarios},
                              {"crashed_scenarios", r.start.crashed},
                              {"mean_seconds_to_crash", r.start.mean_seconds_to_crash}}},
                            {"policy", "policy.json"}};
  // The first phase under its method's key (gradient by default; hill_climb, cmaes, bobyqa, ... when the
  // optimizer is another, which then runs alone): a hill-climbing run is not reported as a gradient phase.
  {
    std::string first = o.optimizer.method;
    std::replace(first.begin(), first.end(), '-', '_');
    summary[first] = optimizer_phase_json(r.gradient);
  }
  return summary;
}

// The LQR start as training settled it: starting_gains and start_tries, and the lines that warn of it.
void add_starting_gains(nlohmann::json& summary, std::ostream& out, const LqrStart& lqr,
                        const HoverTrainingOptions& used, const HoverTrainingResult& r) {
  const HoverPolicyInit& g = lqr.init;
  summary["starting_gains"] = {{"method", lqr.used ? "lqr" : "constant"},
                               {"reason", lqr.reason},
                               {"action_weight_factor", used.lqr_action_factor},
                               {"spectral_radius", lqr.spectral_radius},
                               {"open_loop_radius", lqr.open_loop_radius},
                               {"gains",
                                {{"a1", {{"err", g.k_pos}, {"vel", g.k_vel}, {"att", g.k_att}}},
                                 {"a2", {{"err", g.k_pos_lat}, {"vel", g.k_vel_lat}, {"att", g.k_roll}}},
                                 {"a3", {{"err", g.k_alt}, {"vel", g.k_climb}}},
                                 {"a4", {{"err", g.k_yaw}, {"vel", g.k_yaw_rate}}}}}};
  if (!lqr.used)
    out << "warning: LQR starting gains not used: " << lqr.reason
        << "; training starts from the constant gains instead\n";
  summary["start_tries"] = start_tries_json(r.start_tries);
  if (!r.start_tries.empty()) out << start_tries_line(r.start_tries, used.max_start_crash_fraction);
}

// The settings away from their defaults, each only when it is, so that other runs' summaries stay as they
// were (digests): the integral term, the tilt limit, the judged cost, the wind, the envelope, the rate.
void add_hover_settings(nlohmann::json& summary, const HoverRunOptions& options,
                        const sysid::IdentifiedModel& model, const HoverTrainingResult& r,
                        const std::optional<LqrStart>& settled_lqr) {
  const HoverTrainingOptions& o = options.training;
  if (o.integral_seconds > 0) {
    nlohmann::json integral = {{"integral_seconds", o.integral_seconds},
                               {"limit_position", o.integral_limit_position},
                               {"limit_yaw", o.integral_limit_yaw}};
    if (settled_lqr) integral["lqr_integral_seconds"] = settled_lqr->integral_seconds;
    for (std::size_t c = 0; c < 4; ++c)
      integral["a" + std::to_string(c + 1)] = r.theta[HoverPolicy::kParameters + c];
    summary["integral"] = integral;
  }
  if (o.max_tilt_rad != HoverTrainingOptions{}.max_tilt_rad) summary["max_tilt_rad"] = o.max_tilt_rad;
  if (options.judged_cost)  // likewise: the judged cost's terms as trained
    summary["judged_cost"] = {{"reward", hover_reward_for(model, o).terms(o.crash_penalty)},
                              {"crash_penalty", o.crash_penalty}};
  if (!o.disturbance.calm()) summary["wind"] = wind_summary(o.disturbance);  // likewise
  const HoverTrainingOptions calm_defaults;
  for (const auto& [key, value, fallback] :
       {std::tuple{"max_position_error_m", o.max_position_error_m, calm_defaults.max_position_error_m},
        std::tuple{"max_speed_mps", o.max_speed_mps, calm_defaults.max_speed_mps},
        std::tuple{"max_rate_radps", o.max_rate_radps, calm_defaults.max_rate_radps}})
    if (value != fallback) summary[key] = value;
  if (o.control_rate_hz != 50) {  // likewise
    summary["control_rate_hz"] = o.control_rate_hz;
    summary["refit_every"] = o.refit_steps(model);
  }
}

}  // namespace

namespace {

// Each of Disturbance::VisitFields's settings under its summary key.
struct WindSummary {
  const sysid::Disturbance& d;
  nlohmann::json j = nlohmann::json::object();
  template <class T>
  void setting(const sysid::DisturbanceSetting& s, T sysid::Disturbance::*member) {
    j[s.summary_key] = d.*member;
  }
};

}  // namespace

nlohmann::json wind_summary(const sysid::Disturbance& d) {
  WindSummary v{d};
  sysid::Disturbance::VisitFields(v);
  return v.j;
}

namespace {

// The model hover trains on: the one identify chose, or (issue 48) the global linear fit identify recorded
// beside a locally weighted one whose starting policy cannot fly the default training wind. A vehicle file's
// aircraft with no wind stated trains in wind (heli/training_wind.hpp) so that its integral term learns to
// hold position where the aircraft will fly; a locally weighted model crashes where the airspeed leaves the
// logs', and would train calm. On an outside-like helicopter its start crashed 29 of 30 scenarios of that
// wind (10 of 30 in 0.5 m/s gusts alone), and its calm-trained controller cost 0.86-0.90x the hand-tuned
// baseline's in calm air and 0.30-0.46x in a 4 m/s wind, against 1.26x and 1.34x trained in the wind on the
// global fit (docs/results/baselines.md). `line` and `choice` say so where the model changed.
struct TrainingModel {
  std::shared_ptr<const sysid::IdentifiedModel> model;
  std::string line;
  nlohmann::json choice;  // summary.json's choices.training_model; null: the model identify chose
};

TrainingModel training_model(const HoverRunOptions& stated,
                             std::shared_ptr<const sysid::IdentifiedModel> model, ThreadPool& pool) {
  if (stated.wind_source != WindSource::kDefault || model->is_global())
    return {std::move(model), "", nullptr};
  std::optional<sysid::IdentifiedModel> global = model->alternative();
  if (!global || !global->is_global()) return {std::move(model), "", nullptr};
  HoverTrainingOptions windy = stated.training;
  windy.disturbance = default_training_wind(*global).disturbance;
  const StartingPolicyCheck check = check_starting_policy(model, windy, pool);
  if (check.crashed <= windy.max_start_crash_fraction * check.scenarios)
    return {std::move(model), "", nullptr};
  const std::string reason = fmt::format(
      "the locally weighted model's starting policy crashed {} of {} scenarios of the default training wind "
      "(more than {:g}%): it cannot carry the wind the aircraft will fly in",
      check.crashed, check.scenarios, 100 * windy.max_start_crash_fraction);
  return {std::make_shared<const sysid::IdentifiedModel>(std::move(*global)),
          fmt::format("model: the global linear fit identify made beside the chosen locally weighted model, "
                      "since {} (identify --local=true and a stated [hover.wind] or --wind.* keep the local "
                      "model)\n",
                      reason),
          {{"class", "global linear"}, {"by", "the default training wind"}, {"reason", reason}}};
}

}  // namespace

void run_hover(const HoverRunOptions& stated, RunSink& sink, ThreadPool& pool) {
  check_hover_options(stated);
  const TrainingModel trained_on =
      training_model(stated, stated.aircraft.load_model(stated.model_file), pool);
  const auto& model = trained_on.model;
  sink.out << trained_on.line;
  // The wind in the scenarios, stated or a vehicle file's default (issue 53), once the model is read.
  const TrainingWind wind = training_wind(stated.wind_source, stated.training.disturbance, *model);
  HoverRunOptions options = stated;
  options.training.disturbance = wind.disturbance;
  const HoverTrainingOptions& o = options.training;
  RunDirectory& dir = sink.dir;
  options.aircraft.keep(dir);
  const std::int64_t budget = say_hover_setup(sink.out, options, *model, wind);
  const HoverTrainingResult r = train_hover_in(sink, model, o, pool);

  HoverTrainingOptions used = o;  // with the LQR start's action weights as training settled them
  used.lqr_action_factor = r.lqr_action_factor;
  used.lqr_gains_from_alternative = r.lqr_gains_from_alternative;
  write_hover_policy(sink, options, *model, used, r);
  const double seconds = r.progress.empty() ? 0.0 : r.progress.back().seconds;
  const std::int64_t evaluations = r.progress.empty() ? 0 : r.progress.back().evaluations;
  nlohmann::json summary = hover_summary_core(o, r);
  // Only for AR(1) models, so that the summaries of white-noise models stay as they were (digests).
  if (model->noise_correlation().any())
    summary["model_noise"] = model->noise_correlation().has_measurement() ? "ar1+measurement" : "ar1";
  // The LQR start as training settled it, for the summary's starting_gains and integral.
  const std::optional<LqrStart> settled_lqr =
      o.lqr_start ? std::optional(lqr_hover_init(*model, used)) : std::nullopt;
  // only when asked: summaries with the constants stay as they were
  if (settled_lqr) add_starting_gains(summary, sink.out, *settled_lqr, used, r);
  summary["choices"] = hover_choices(*model, o, r);
  if (options.aircraft.from_file()) summary["choices"]["wind"] = {{"by", wind.by}, {"reason", wind.reason}};
  if (!trained_on.choice.is_null()) summary["choices"]["training_model"] = trained_on.choice;
  if (options.aircraft.from_file()) summary["vehicle"] = options.aircraft.vehicle.name();  // likewise
  add_hover_settings(summary, options, *model, r, settled_lqr);
  if (budget > 0)
    summary["evaluation_budget"] = budget;  // only where it binds, so other runs stay as they were
  dir.write_json("summary.json", summary);
  sink.timings = {{"train_seconds", seconds},
                  {"gradient_seconds", r.gradient.method.empty() ? 0.0 : r.gradient.wall_seconds},
                  {"hill_climb_seconds", r.hill_climb.method.empty() ? 0.0 : r.hill_climb.wall_seconds}};
  if (r.start.crashed > 0)
    sink.out << fmt::format(
        "warning: the starting policy crashes the learned model in {} of {} scenarios (after {:.2f} s on "
        "average)\n",
        r.start.crashed, r.start.scenarios, r.start.mean_seconds_to_crash);
  sink.out << fmt::format(
      "hover training: U-hat {:.6g} -> {:.6g} in {} iterations, {} evaluations, {:.1f} s\n", r.initial_uhat,
      r.final_uhat, r.progress.size(), evaluations, seconds);
  sink.out << "policy: " << sink.named(dir.final_path() / "policy.json") << "\n";
}

}  // namespace pegasus::heli
