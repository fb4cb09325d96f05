// The table of `pegasus` commands. A new command is one entry here (or a function returning entries, kept in
// its own apps/pegasus/<area>_command.cpp, declared below) that names its config section and its run
// function, both in the library (include/pegasus/runs/); see command.hpp.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <thread>

#include "experiment_commands.hpp"
#include "pegasus/cli/command.hpp"
#include "pegasus/evaluators/horizon.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus::cli {

namespace {

// pegasus horizon: the epsilon-horizon H_eps of §4.2.2.
Command horizon_command() {
  return {
      .path = "horizon",
      .description =
          "Rollout length H_eps that truncates discounted returns by at most epsilon/2 (thesis 4.2.2)",
      .declare =
          [](ConfigSchema& s) {
            s.add_double("gamma", 0.99, "discount factor").greater_than(0).less_than(1);
            s.add_double("epsilon", 0.01, "allowed error of the value estimate").greater_than(0);
            s.add_double("rmax", 1.0, "largest absolute one-step reward").greater_than(0);
          },
      .run =
          [](RunContext& ctx) {
            const std::int64_t h =
                epsilon_horizon(ctx.config.get_double("gamma"), ctx.config.get_double("epsilon"),
                                ctx.config.get_double("rmax"));
            const nlohmann::json summary = {{"horizon", h}};
            ctx.out << summary.dump() << "\n";
            if (ctx.has_run_directory()) ctx.run_directory().write_json("summary.json", summary);
          },
      .out = OutDir::kOptional,
  };
}

// pegasus dev count: a deterministic, checkpointed, slow-on-request loop that exercises every part of the
// framework (checkpoint/resume, progress, CSV, SVG); the end-to-end tests kill it and resume it.
Command dev_count_command() {
  return {
      .path = "dev count",
      .description = "Framework self-test: sums a series step by step with a checkpoint after each step",
      .declare =
          [](ConfigSchema& s) {
            s.add_int("steps", 10, "number of steps").range(1, 1000000);
            s.add_double("scale", 1.0, "each value is scale * f(step)");
            s.add_string("shape", "sqrt", "f").choices({"sqrt", "linear"});
            s.add_bool("negate", false, "negate every value");
            s.add_int_list("skip", {}, "steps whose value is 0").min(0);
            s.add_double_list("weights.values", {1.0}, "weights applied in turn to the values").min_size(1);
            s.add_int("step_ms", 0, "milliseconds to sleep per step").range(0, 60000).affects_results(false);
            s.add_int("fail_at", -1, "throw an error when reaching this step (-1: never)")
                .min(-1)
                .affects_results(false);
          },
      .run =
          [](RunContext& ctx) {
            const auto steps = ctx.config.get_int("steps");
            const double scale = ctx.config.get_double("scale");
            RunDirectory& dir = ctx.run_directory();
            std::vector<double> values;
            if (auto state = dir.load_checkpoint()) values = (*state)["values"].get<std::vector<double>>();
            Progress bar = ctx.progress("steps", static_cast<std::uint64_t>(steps));
            bar.skip(values.size());
            for (auto i = static_cast<std::int64_t>(values.size()); i < steps; ++i) {
              if (i == ctx.config.get_int("fail_at"))
                throw std::runtime_error(fmt::format("failed at step {}", i));
              std::this_thread::sleep_for(std::chrono::milliseconds(ctx.config.get_int("step_ms")));
              const auto x = static_cast<double>(i);
              double v = scale * (ctx.config.get_string("shape") == "sqrt" ? std::sqrt(x) : x);
              const auto& skip = ctx.config.get_int_list("skip");
              if (std::find(skip.begin(), skip.end(), i) != skip.end()) v = 0;
              const auto& weights = ctx.config.get_double_list("weights.values");
              v *= weights[static_cast<std::size_t>(i) % weights.size()];
              values.push_back(ctx.config.get_bool("negate") ? -v : v);
              dir.save_checkpoint({{"values", values}});
              bar.advance();
            }
            bar.finish();
            double sum = 0;
            CsvWriter csv({"step", "value"});
            for (std::size_t i = 0; i < values.size(); ++i) {
              sum += values[i];
              csv.add_row({static_cast<std::int64_t>(i), values[i]});
            }
            dir.write_csv("values.csv", csv);
            const Chart chart{.title = "dev count",
                              .x = {"step"},
                              .y = {"value"},
                              .traces = {{.file = "values.csv", .x = "step", .y = "value", .name = "value"}}};
            dir.add_charts(ChartSection{.id = "values", .title = "Values", .charts = {chart}});
            dir.write_chart_svg("values.svg", chart);
            dir.write_json("summary.json", {{"steps", steps}, {"sum", sum}});
            ctx.out << fmt::format("sum {}\n", sum);
          },
      .hidden = true,
  };
}

}  // namespace

std::vector<CommandGroup> command_groups() {
  return {
      {.path = "dev", .description = "Framework self-tests", .hidden = true},
      {.path = "bicycle",
       .description = "Randlov and Alstrom's bicycle ridden to a goal by PEGASUS (thesis 4.6)"},
      {.path = "pendulum",
       .description = "Gymnasium's Pendulum-v1 swung up by PEGASUS (the race against RLtools)"},
      {.path = "heli",
       .description =
           "Autonomous helicopter (thesis ch. 5): ground-truth aircraft, pilot logs, system identification"},
      {.path = "log",
       .description = "Real flight logs: PX4 ULog import, identification and prediction error"},
#ifdef PEGASUS_HAVE_MUJOCO
      {.path = "mujoco", .description = "PEGASUS policy search on any MuJoCo (MJCF) model with a task file"},
#endif
      {.path = "shaping",
       .description = "Reward shaping (thesis ch. 3): the shaping audit and the 3.4 experiments"},
  };
}

// Each command file's group of commands (apps/pegasus/<area>_command.cpp). A new command is a new file with
// its function, declared and listed here: no other edit.
Command pomdp_gridworld_command();
std::vector<Command> bicycle_commands();  // bicycle experiment, train, ride, variance
// heli_commands() (heli pilot, identify, hover, fly, control, pipeline): experiment_commands.hpp, since the
// pipeline looks its stages up in it.
std::vector<Command> heli_maneuver_commands();  // heli maneuver, maneuver-pilot, and their generic forms
std::vector<Command> log_commands();            // log import
std::vector<Command> pendulum_commands();       // pendulum train (Pendulum-v1, the RLtools race)
std::vector<Command> mujoco_commands();         // mujoco train, rollout (empty without PEGASUS_MUJOCO)
std::vector<Command> shaping_commands();        // shaping audit, gridworld, flags, progress-bonus
Command report_command();                       // report RUN_DIR
Command export_command();                       // export --policy P.json --lang c

std::vector<Command> commands() {
  std::vector<Command> all = {
      pomdp_gridworld_command(), horizon_command(), dev_count_command(), report_command(), export_command(),
  };
  for (auto& command : bicycle_commands()) all.push_back(std::move(command));
  for (auto& command : heli_commands()) all.push_back(std::move(command));
  for (auto& command : heli_maneuver_commands()) all.push_back(std::move(command));
  for (auto& command : log_commands()) all.push_back(std::move(command));
  for (auto& command : pendulum_commands()) all.push_back(std::move(command));
  for (auto& command : shaping_commands()) all.push_back(std::move(command));
  for (auto& command : mujoco_commands()) all.push_back(std::move(command));
  return all;
}

}  // namespace pegasus::cli
