// `pegasus heli pilot`, `heli identify`, `heli hover`, `heli fly`, `heli control` and `heli pipeline`, and
// their generic forms with --vehicle: the library's helicopter config sections (heli/runs/heli_config.hpp)
// and experiments (heli/runs/heli_runs.hpp: the ground truth flown by the scripted pilot, identification,
// PEGASUS hover training on the identified model, flights on the ground truth, thesis ch. 5; the line-by-line
// controller server). The pipeline, made of these commands, is heli_pipeline_command.cpp.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/simulators.hpp"

namespace pegasus::cli {
namespace {

void run_pilot(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_pilot(heli::read_pilot_config(ctx.config, ctx.seed), sink);
}

void run_identify(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_identify(heli::read_identify_config(ctx.config), sink, ctx.pool());
}

void run_hover(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_hover(heli::read_hover_config(ctx.config, ctx.seed), sink, ctx.pool());
}

void run_fly(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_fly(heli::read_fly_config(ctx.config, ctx.seed), sink, ctx.pool());
}

void run_control(RunContext& ctx) {
  const auto& c = ctx.config;
  heli::run_control({.vehicle_file = c.get_path("vehicle"),
                     .policy_file = c.get_path("policy"),
                     .bench_lines = c.get_int("bench_lines")},
                    stdin, stdout, stderr, ctx.out);
}

}  // namespace

std::vector<Command> heli_commands() {
  std::vector<Command> commands = {
      Command{.path = "heli pilot",
              .description = "Fly the ground-truth helicopter with the scripted pilot (hover, then sweeps) "
                             "and log it at 50 Hz",
              .declare = heli::declare_pilot_config,
              .run = run_pilot,
              .resolve = heli::resolve_gust_sigma},
      Command{.path = "heli identify",
              .description =
                  "Identify a helicopter model by locally weighted regression from flight logs (thesis 5.2)",
              .declare = heli::declare_identify_config,
              .run = run_identify,
              .resolve = heli::resolve_identify_config},
      Command{
          .path = "heli hover",
          .description = "Learn to hover (thesis 5.3): PEGASUS on the identified model, writes policy.json",
          .declare = heli::declare_hover_config,
          .run = run_hover,
          .resolve = heli::resolve_hover_config},
      Command{.path = "heli fly",
              .description =
                  "Fly a policy file (or the scripted pilot) on the ground-truth helicopter with gusts",
              .declare = heli::declare_fly_config,
              .run = run_fly,
              .resolve = heli::resolve_gust_sigma},
      Command{
          .path = "heli control",
          .description = "Serve a policy file: one state per line on stdin, four controls per line on stdout",
          .declare = heli::declare_control_config,
          .run = run_control,
          .out = OutDir::kNone},
      Command{
          .path = "heli pipeline",
          .description =
              "The whole helicopter chain: pilot logs, identification, hover training, flights vs the pilot",
          .declare = heli::declare_pipeline_config,
          .run = run_pipeline},
  };
  // The same commands for any aircraft a vehicle file describes; the `heli` ones are their aliases with the
  // X-Cell 60 as the default vehicle.
  const std::map<std::string, std::string> generic = {
      {"identify", "Identify an aircraft's model from its flight logs (--vehicle V.toml; thesis 5.2)"},
      {"hover", "Learn to hover an identified aircraft model by PEGASUS (--vehicle V.toml; thesis 5.3)"},
      {"pilot", "Fly the vehicle's ground truth with the scripted pilot (hover, then sweeps) and log it"},
      {"pipeline",
       "The whole chain for a vehicle with a ground truth (--vehicle V.toml): pilot logs, identification, "
       "hover "
       "training, flights vs the pilot"},
      {"fly", "Fly a policy on the vehicle's ground truth (vehicles with a simulator: " +
                  heli::ground_truth_list() + ")"},
      {"control",
       "Serve a policy to an aircraft in its own layout (--vehicle V.toml): a state line in, its "
       "controls out"}};
  for (std::size_t i = 0, n = commands.size(); i < n; ++i) {
    const std::string name = commands[i].path.substr(std::string("heli ").size());
    if (const auto it = generic.find(name); it != generic.end()) {
      Command c = commands[i];
      c.path = name;
      c.description = it->second;
      commands.push_back(std::move(c));
    }
  }
  return commands;
}

}  // namespace pegasus::cli
