// `pegasus heli maneuver` and `heli maneuver-pilot` (and `maneuver`, `maneuver-pilot` with --vehicle): the
// library's config sections (heli/runs/maneuver_config.hpp) and manoeuvre experiments
// (heli/runs/maneuver_runs.hpp, thesis §5.4).
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/heli/runs/maneuver_config.hpp"

namespace pegasus::cli {
namespace {

void run(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_maneuver(heli::read_maneuver_config(ctx.config, ctx.seed), sink, ctx.pool());
}

void run_pilot(RunContext& ctx) {
  RunSink sink = ctx.sink();
  heli::run_maneuver_pilot(heli::read_maneuver_pilot_config(ctx.config, ctx.seed), sink);
}

}  // namespace

std::vector<Command> heli_maneuver_commands() {
  std::vector<Command> commands = {
      Command{.path = "heli maneuver",
              .description = "Learn an AMA Class III manoeuvre (III.1, III.2, III.3) with PEGASUS and "
                             "fly it on the ground truth (thesis 5.4)",
              .declare = heli::declare_maneuver_config,
              .run = run,
              .resolve = heli::resolve_maneuver_config},
      Command{.path = "heli maneuver-pilot",
              .description = "Fly the scripted pilot through hover, sweeps and the three manoeuvres: "
                             "identification data that covers them",
              .declare = heli::declare_maneuver_pilot_config,
              .run = run_pilot,
              .resolve = heli::resolve_gust_sigma}};
  // The same for any vehicle with a ground truth (--vehicle V.toml); the `heli` ones fly the X-Cell 60.
  Command maneuver = commands[0], pilot = commands[1];
  maneuver.path = "maneuver";
  maneuver.description =
      "Learn a manoeuvre or a figure-eight on a vehicle's identified model and fly it on its "
      "ground truth (--vehicle V.toml)";
  pilot.path = "maneuver-pilot";
  pilot.description =
      "Fly a vehicle's scripted pilot through hover, sweeps and manoeuvres (--vehicle V.toml, --maneuvers)";
  commands.push_back(std::move(maneuver));
  commands.push_back(std::move(pilot));
  return commands;
}

}  // namespace pegasus::cli
