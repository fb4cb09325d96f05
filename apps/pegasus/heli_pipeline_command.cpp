// `pegasus heli pipeline` and `pegasus pipeline --vehicle`: the whole chain (pilot logs, identification,
// hover training, flights against the pilot) as stages that are the commands a user would type, each run in
// this process into its own sub-run directory (command.hpp: run_stage). The stages name each other's files
// relative to the pipeline's run directory (it moves when the run is committed), exactly as a user typing
// the stages there would; their configs carry it as their base directory (ConfigSchema::get_path), so that
// the process's working directory is neither used nor changed.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus::cli {

namespace {

// The table's command at `path`.
const Command& heli_command(const std::string& path) {
  static const std::vector<Command> table = heli_commands();
  const auto it = std::find_if(table.begin(), table.end(), [&](const Command& c) { return c.path == path; });
  if (it == table.end()) throw std::logic_error("no command '" + path + "'");
  return *it;
}

}  // namespace

void run_pipeline(RunContext& ctx) {
  const auto& c = ctx.config;
  // Another aircraft: its vehicle file, checked before any stage runs, goes to every stage (by its absolute
  // path, as the stages' config.toml record it), which are then the generic commands; the X-Cell's stages
  // stay the `heli` ones they always were.
  const std::string vehicle_file = c.get_path("vehicle");
  std::optional<logs::Vehicle> vehicle;
  if (!vehicle_file.empty()) {
    vehicle = logs::read_vehicle(vehicle_file);
    if (vehicle->simulator == "none")
      throw InputError(fmt::format(
          "{}: vehicle.simulator: expected a ground truth for the pipeline to fly (one of {}), got 'none'; "
          "for this aircraft run `pegasus identify` and `pegasus hover --vehicle` on its own logs and serve "
          "the policy with `pegasus control`",
          vehicle_file, heli::ground_truth_list()));
  }
  const std::uint64_t seed = ctx.seed;
  // The stages take seed to seed + 2, and the noise-check flights seed + 3 on: all must be valid seeds before
  // the first stage runs.
  const auto check_flights = static_cast<std::uint64_t>(c.get_int("noise_check_flights"));
  const std::uint64_t largest_seed = std::numeric_limits<std::int64_t>::max() - 2 - check_flights;
  if (seed > largest_seed) {
    throw InputError(
        fmt::format("--seed: expected an integer in [0, {}] (heli pipeline gives its stages seeds up to "
                    "seed + {}), got {}",
                    largest_seed, 2 + check_flights, seed));
  }
  RunDirectory& dir = ctx.run_directory();
  const std::filesystem::path root = std::filesystem::absolute(dir.path());
  const std::string absolute_vehicle =
      vehicle ? std::filesystem::absolute(vehicle_file).string() : std::string();

  // A stage's settings: its command's own fields, each set with its type from the pipeline's field of the
  // same meaning (named in a stage's error about it; the pipeline itself for the files the stages pass on),
  // the vehicle file and the common ones.
  struct Stage {
    const Command* command;
    ConfigSchema config;
    void set(const std::string& field, FieldValue value, const std::string& from = {}) {
      config.set(field, std::move(value), from.empty() ? "heli pipeline" : ConfigSchema::option_name(from));
    }
  };
  const auto stage_of = [&](const char* name, std::uint64_t stage_seed) {
    const Command& command = heli_command(vehicle ? name : std::string("heli ") + name);
    Stage stage{&command, command_schema(command)};
    stage.config.set_base_directory(root);  // the stages name each other's files relative to it
    stage.set("seed", static_cast<std::int64_t>(stage_seed), "seed");
    stage.set("threads", std::int64_t{ctx.threads}, "threads");
    if (vehicle) stage.set("vehicle", absolute_vehicle, "vehicle");
    return stage;
  };
  const auto run = [&](const std::string& name, const Stage& stage) {
    if (std::filesystem::exists(root / name / "summary.json")) {
      ctx.out << fmt::format("[{}] done before, kept: {}\n", name, (dir.final_path() / name).string());
      return;
    }
    ctx.out << fmt::format("[{}] {}\n", name,
                           fmt::join(command_line_of(*stage.command, stage.config, name), " "));
    ctx.out.flush();
    const auto start = std::chrono::steady_clock::now();
    try {
      run_stage(*stage.command, stage.config, name, {.quiet = ctx.quiet}, ctx.out, ctx.err);
    } catch (const InputError& e) {
      throw InputError(fmt::format("pipeline stage {}: {}", name, e.what()));
    }
    ctx.out << fmt::format("[{}] {:.1f} s\n", name,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };

  for (const auto& [name, seconds, stage_seed] : {std::tuple{"pilot-train", "train_seconds", seed},
                                                  std::tuple{"pilot-test", "test_seconds", seed + 1}}) {
    Stage pilot = stage_of("pilot", stage_seed);
    pilot.set("seconds", c.get_double(seconds), seconds);
    run(name, pilot);
  }
  std::vector<std::string> check_logs;
  for (std::uint64_t i = 0; i < check_flights; ++i) {
    const std::string name = fmt::format("pilot-check-{}", i + 1);
    Stage pilot = stage_of("pilot", seed + 3 + i);
    pilot.set("seconds", c.get_double("noise_check_seconds"), "noise_check_seconds");
    run(name, pilot);
    check_logs.push_back(name + "/log.csv");
  }
  Stage identify_stage = stage_of("identify", seed);
  identify_stage.set("train", std::string("pilot-train/log.csv"));
  identify_stage.set("test", std::string("pilot-test/log.csv"));
  if (!check_logs.empty()) identify_stage.set("noise_check_logs", check_logs);
  for (const char* field : {"cv_points", "coordinate_passes"})
    identify_stage.set(field, c.get_int(field), field);
  identify_stage.set("scale_grid", c.get_double_list("scale_grid"), "scale_grid");
  identify_stage.set("variants", false);
  run("identify", identify_stage);
  // The start sigmas only when set, so that the X-Cell's stages are the commands they always were.
  const auto with_starts = [&](Stage& stage) {
    for (const char* field : {"start_pos_sigma", "start_vel_sigma"})
      if (c.origin(field) != "default") stage.set(field, c.get_double(field), field);
  };
  Stage hover_stage = stage_of("hover", seed);
  hover_stage.set("model", std::string("identify/model.json"));
  hover_stage.set("scenarios", c.get_int("scenarios"), "scenarios");
  hover_stage.set("seconds", c.get_double("scenario_seconds"), "scenario_seconds");
  hover_stage.set("optimizer.gradient.max_iterations", c.get_int("gradient_iterations"),
                  "gradient_iterations");
  hover_stage.set("optimizer.hill_climbing.max_iterations", c.get_int("hill_climbing_iterations"),
                  "hill_climbing_iterations");
  with_starts(hover_stage);
  run("hover", hover_stage);
  Stage fly_stage = stage_of("fly", seed + 2);
  fly_stage.set("policy", std::string("hover/policy.json"));
  fly_stage.set("compare_pilot", true);
  fly_stage.set("flights", c.get_int("flights"), "flights");
  fly_stage.set("seconds", c.get_double("flight_seconds"), "flight_seconds");
  with_starts(fly_stage);
  run("fly", fly_stage);

  RunSink sink = ctx.sink();
  heli::write_pipeline_summary(vehicle ? vehicle->name() : std::string(), c.get_double("flight_seconds"),
                               sink);
}

}  // namespace pegasus::cli
