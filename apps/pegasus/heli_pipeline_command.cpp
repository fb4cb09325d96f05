// `pegasus heli pipeline` and `pegasus pipeline --vehicle`: the whole chain (pilot logs, identification,
// hover training, flights against the pilot) as stages that are the commands a user would type, each run in
// this process into its own sub-run directory (command.hpp: run_stage).
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/logs/vehicle.hpp"

namespace pegasus::cli {

namespace {

// The table's command at `path`.
const Command& heli_command(const std::string& path) {
  static const std::vector<Command> table = heli_commands();
  const auto it = std::find_if(table.begin(), table.end(), [&](const Command& c) { return c.path == path; });
  if (it == table.end()) throw std::logic_error("no command '" + path + "'");
  return *it;
}

// While alive, the process works in `dir`: the pipeline's stages run in its run directory, so that their
// files name each other by paths relative to it (it moves when the run is committed), exactly as a user
// typing the stages there would. Nothing else runs meanwhile: the stages' thread pools open no paths.
class WorkingDirectory {
 public:
  explicit WorkingDirectory(const std::filesystem::path& dir) : previous_(std::filesystem::current_path()) {
    std::filesystem::current_path(dir);
  }
  WorkingDirectory(const WorkingDirectory&) = delete;
  WorkingDirectory& operator=(const WorkingDirectory&) = delete;
  ~WorkingDirectory() {
    std::error_code ignored;  // the folder the process came from is gone: nothing better to do
    std::filesystem::current_path(previous_, ignored);
  }

 private:
  std::filesystem::path previous_;
};

}  // namespace

void declare_pipeline(ConfigSchema& s) {
  const sysid::IdentifyOptions identify_defaults;
  const heli::HoverTrainingOptions hover_defaults;
  const heli::FlightOptions flight_defaults;
  declare_vehicle(s);
  s.add_double("train_seconds", heli::PilotRunOptions{}.seconds, "pilot training flight, s (thesis 5.2: 339)")
      .range(30, 36000);
  s.add_double("test_seconds", 140, "pilot hold-out flight, s (thesis 5.2: 140)").range(20, 36000);
  s.add_int("cv_points", identify_defaults.cv_points,
            "identification: held-out points per cross-validation evaluation")
      .range(10, 100000);
  s.add_double_list("scale_grid", identify_defaults.scale_grid,
                    "identification: bandwidths tried, in input standard deviations")
      .min(1e-6)
      .min_size(1);
  s.add_int("coordinate_passes", identify_defaults.coordinate_passes,
            "identification: passes of per-input bandwidth refinement")
      .range(0, 10);
  s.add_int("scenarios", hover_defaults.scenarios, "hover training: PEGASUS scenarios").range(1, 100000);
  s.add_double("scenario_seconds", hover_defaults.seconds, "hover training: flight per scenario, s")
      .greater_than(0)
      .max(3600);
  s.add_int("gradient_iterations", hover_defaults.optimizer.gradient.max_iterations,
            "hover training: gradient ascent iterations")
      .range(0, 1000000);
  s.add_int("hill_climbing_iterations", hover_defaults.optimizer.hill_climbing.max_iterations,
            "hover training: hill-climbing iterations")
      .range(0, 1000000);
  s.add_double("start_pos_sigma", hover_defaults.start_pos_sigma,
               "hover training and flights: start position perturbation per axis, m")
      .range(0, 100);
  s.add_double("start_vel_sigma", hover_defaults.start_vel_sigma,
               "hover training and flights: start velocity perturbation per axis, m/s")
      .range(0, 100);
  s.add_int("flights", flight_defaults.flights, "flights on the ground truth (policy and pilot)")
      .range(1, 1000000);
  s.add_double("flight_seconds", flight_defaults.seconds, "flight length on the ground truth, s")
      .greater_than(0)
      .max(36000);
}

void run_pipeline(RunContext& ctx) {
  const auto& c = ctx.config;
  // Another aircraft: its vehicle file, checked before any stage runs, goes to every stage (by its absolute
  // path: the stages run in the run directory), which are then the generic commands; the X-Cell's stages stay
  // the `heli` ones they always were.
  const std::string vehicle_file = c.get_string("vehicle");
  std::optional<logs::Vehicle> vehicle;
  if (!vehicle_file.empty()) {
    vehicle = logs::read_vehicle(vehicle_file);
    if (vehicle->simulator == "none")
      throw InputError(fmt::format(
          "{}: vehicle.simulator: expected a built-in ground truth for the pipeline to fly (one of xcell, "
          "crazyflie2), got 'none'; for this aircraft run `pegasus identify` and `pegasus hover --vehicle` "
          "on "
          "its own logs and serve the policy with `pegasus control`",
          vehicle_file));
  }
  const std::uint64_t seed = ctx.seed;
  // The stages take seed, seed + 1 and seed + 2: all must be valid seeds before the first stage runs.
  constexpr std::uint64_t kLargestSeed = std::numeric_limits<std::int64_t>::max() - 2;
  if (seed > kLargestSeed) {
    throw InputError(
        fmt::format("--seed: expected an integer in [0, {}] (heli pipeline gives its stages seed + 1 and "
                    "seed + 2), got {}",
                    kLargestSeed, seed));
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
    {
      const WorkingDirectory in_run_directory(root);
      try {
        run_stage(*stage.command, stage.config, name, {.quiet = ctx.quiet}, ctx.out, std::cerr);
      } catch (const InputError& e) {
        throw InputError(fmt::format("pipeline stage {}: {}", name, e.what()));
      }
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
  Stage identify_stage = stage_of("identify", seed);
  identify_stage.set("train", std::string("pilot-train/log.csv"));
  identify_stage.set("test", std::string("pilot-test/log.csv"));
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

  const nlohmann::json hover = read_json_file(root / "hover" / "summary.json");
  const nlohmann::json fly = read_json_file(root / "fly" / "summary.json");
  nlohmann::json summary = {
      {"hover", {{"initial_uhat", hover.at("initial_uhat")}, {"final_uhat", hover.at("final_uhat")}}},
      {"flights", fly.at("flights")},
      {"crashes", fly.at("crashes")},
      {"rms_position_m", fly.at("rms_position_m")},
      {"rms_velocity_mps", fly.at("rms_velocity_mps")},
      {"rms_yaw_rad", fly.at("rms_yaw_rad")},
      {"pilot", fly.at("pilot")},
      {"stages", {"pilot-train", "pilot-test", "identify", "hover", "fly"}}};
  if (vehicle) summary["vehicle"] = vehicle->name();  // only then: the X-Cell's summaries stay as they were
  dir.write_json("summary.json", summary);
  const auto& pl = fly.at("pilot");
  const std::filesystem::path final_fly = dir.final_path() / "fly";
  ctx.out << fmt::format("\n== {} pipeline: headline figures ==\n", vehicle ? vehicle->name() : "helicopter");
  ctx.out << fmt::format("hover training U-hat: {:.6g} -> {:.6g}\n", hover.at("initial_uhat").get<double>(),
                         hover.at("final_uhat").get<double>());
  ctx.out << fmt::format(
      "learned policy on the ground truth: {} flights of {} s, {} crashes, RMS position {:.3f} m, velocity "
      "{:.3f} m/s, yaw {:.4f} rad\n",
      fly.at("flights").get<int>(), format_double(c.get_double("flight_seconds")),
      fly.at("crashes").get<int>(), fly.at("rms_position_m").get<double>(),
      fly.at("rms_velocity_mps").get<double>(), fly.at("rms_yaw_rad").get<double>());
  ctx.out << fmt::format(
      "scripted pilot, same starts and gusts:       {} crashes, RMS position {:.3f} m, velocity {:.3f} m/s, "
      "yaw {:.4f} rad\n",
      pl.at("crashes").get<int>(), pl.at("rms_position_m").get<double>(),
      pl.at("rms_velocity_mps").get<double>(), pl.at("rms_yaw_rad").get<double>());
  ctx.out << "plots: " << (final_fly / "position_x.svg").string()
          << ", position_y.svg, altitude.svg, velocity_xb/yb/zb.svg (Figs 5.6-5.7); "
          << (dir.final_path() / "hover" / "progress.svg").string() << "; "
          << (dir.final_path() / "identify" / "mse_xdot_b.svg").string() << "\n";
}

}  // namespace pegasus::cli
