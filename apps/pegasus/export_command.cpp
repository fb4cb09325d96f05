// pegasus export --policy P.json --lang c --out DIR: a policy file becomes a dependency-free C99 header and
// source for a flight computer: the library's config section and export (codegen/runs/export_run.hpp).
#include "pegasus/cli/command.hpp"
#include "pegasus/codegen/runs/export_run.hpp"

namespace pegasus::cli {

Command export_command() {
  return {
      .path = "export",
      .description =
          "Write a policy file as a dependency-free C99 controller (PREFIX.h, PREFIX.c), bit-identical "
          "to the C++ policy",
      .declare = declare_export_config,
      .run =
          [](RunContext& ctx) {
            RunSink sink = ctx.sink();
            run_c_export(read_export_config(ctx.config), sink);
          },
  };
}

}  // namespace pegasus::cli
