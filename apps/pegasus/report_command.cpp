// pegasus report RUN_DIR: writes RUN_DIR/report.html (include/pegasus/report/report.hpp). Every command that
// writes a run directory also writes its report at the end (command.cpp); this command (re)makes one, e.g.
// for a run directory copied from elsewhere or written before reports existed.
#include <fmt/format.h>

#include <filesystem>
#include <ostream>

#include "experiment_commands.hpp"
#include "pegasus/cli/command.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/report/report.hpp"

namespace pegasus::cli {

Command report_command() {
  return {
      .path = "report",
      .description =
          "Write RUN_DIR/report.html: one self-contained HTML file (charts, 3-D flight replay) that "
          "works offline",
      .declare =
          [](ConfigSchema& s) {
            s.add_string("run_dir", "", "the run directory (written by a pegasus command) to report on");
          },
      .run =
          [](RunContext& ctx) {
            const std::filesystem::path dir = ctx.config.get_path("run_dir");
            if (dir.empty()) throw InputError("RUN_DIR: expected a run directory (pegasus report RUN_DIR)");
            const auto file = report::write_report(dir);
            std::error_code ec;
            const auto bytes = std::filesystem::file_size(file, ec);
            ctx.out << fmt::format("report: {} ({:.1f} MB)\n", file.string(),
                                   static_cast<double>(bytes) / 1e6);
          },
      .out = OutDir::kNone,
      .positionals = {"run_dir"},
  };
}

}  // namespace pegasus::cli
