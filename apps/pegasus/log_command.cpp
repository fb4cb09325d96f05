// `pegasus log import FILE.ulg --vehicle V.toml --out DIR`: a PX4 ULog flight as the project's CSV flight
// log, identified on its first part with hold-out prediction errors: the library's config section and
// experiment (heli/runs/log_import_run.hpp).
#include "pegasus/cli/command.hpp"
#include "pegasus/heli/runs/log_import_run.hpp"

namespace pegasus::cli {

std::vector<Command> log_commands() {
  return {Command{.path = "log import",
                  .description = "Import a PX4 ULog flight as a CSV flight log (topics from a vehicle file), "
                                 "identify a model on its first part and report hold-out prediction errors",
                  .declare = declare_log_import_config,
                  .run =
                      [](RunContext& ctx) {
                        RunSink sink = ctx.sink();
                        run_log_import(read_log_import_config(ctx.config), sink, ctx.pool());
                      },
                  .positionals = {"ulog"}}};
}

}  // namespace pegasus::cli
