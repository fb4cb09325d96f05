// `pegasus log import FILE.ulg --vehicle V.toml --out DIR`: a PX4 ULog flight as the project's CSV flight
// log (logs/ulog_import.hpp), with its provenance; then, on the first part of it, the identification of
// thesis §5.2 and the hold-out prediction error of the identified model, the global linear model and a
// constant-velocity baseline at 0.5, 1 and 2 s (Fig 5.2's measure).
#include "experiment_commands.hpp"
#include "pegasus/runs/log_import_run.hpp"

namespace pegasus::cli {
namespace {

void declare_import(ConfigSchema& s) {
  s.add_string("ulog", "", "the PX4 ULog file (.ulg)").input_file();
  s.add_string("vehicle", "", "vehicle file whose [log] section names the topics (README: vehicle files)")
      .input_file();
  s.add_double("start_s", 0, "skip this many seconds after the first time every topic has data")
      .range(0, 1e6);
  s.add_double("end_s", 0, "end this many seconds after that time (0: where the first topic ends)")
      .range(0, 1e6);
  s.add_string("truncated_tail", "discard",
               "a last message cut off by the end of the file: discard it (the ULog spec's rule) or error")
      .choices({"discard", "error"});
  s.add_bool("identify", LogImportRunOptions{}.identify,
             "identify a model on the first part and report hold-out prediction errors");
  s.add_double("train_fraction", LogImportRunOptions{}.train_fraction,
               "the first part of the log used for identification")
      .range(0.1, 0.95);
  s.add_bool("local", LogImportRunOptions{}.identification.local,
             "locally weighted regression (false: globally linear)");
  s.add_double("window_s", LogImportRunOptions{}.identification.window_s,
               "cross-validation leaves out this window around each held-out point, s")
      .range(0, 1000);
  s.add_int("cv_points", LogImportRunOptions{}.identification.cv_points,
            "held-out points per cross-validation evaluation")
      .range(10, 100000);
  s.add_int("coordinate_passes", LogImportRunOptions{}.identification.coordinate_passes,
            "passes of per-input bandwidth refinement")
      .range(0, 10);
  declare_bandwidth_floor(s);
  s.add_double("start_spacing_s", LogImportRunOptions{}.start_spacing_s,
               "spacing of the open-loop prediction starts on the hold-out part, s")
      .range(0.02, 1000);
}

void run_import(RunContext& ctx) {
  const auto& c = ctx.config;
  LogImportRunOptions o{.ulog_file = c.get_string("ulog"),
                        .vehicle_file = c.get_string("vehicle"),
                        .window = {.start_s = c.get_double("start_s"), .end_s = c.get_double("end_s")},
                        .truncated_tail = c.get_string("truncated_tail") == "error"
                                              ? logs::UlogReadOptions::TruncatedTail::kError
                                              : logs::UlogReadOptions::TruncatedTail::kDiscard,
                        .identify = c.get_bool("identify"),
                        .train_fraction = c.get_double("train_fraction"),
                        .start_spacing_s = c.get_double("start_spacing_s")};
  o.identification.local = c.get_bool("local");
  o.identification.window_s = c.get_double("window_s");
  o.identification.cv_points = static_cast<int>(c.get_int("cv_points"));
  o.identification.coordinate_passes = static_cast<int>(c.get_int("coordinate_passes"));
  o.identification.min_bandwidth = read_bandwidth_floor(c);
  RunSink sink = ctx.sink();
  run_log_import(o, sink, ctx.pool());
}

}  // namespace

std::vector<Command> log_commands() {
  return {Command{.path = "log import",
                  .description = "Import a PX4 ULog flight as a CSV flight log (topics from a vehicle file), "
                                 "identify a model on its first part and report hold-out prediction errors",
                  .declare = declare_import,
                  .run = run_import,
                  .positionals = {"ulog"}}};
}

}  // namespace pegasus::cli
