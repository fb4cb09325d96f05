// `pegasus log import FILE.ulg --vehicle V.toml --out DIR`: a PX4 ULog flight as the project's CSV flight
// log (logs/ulog_import.hpp), with its provenance; then, on the first part of it, the identification of
// thesis §5.2 and the hold-out prediction error of the identified model, the global linear model and a
// constant-velocity baseline at 0.5, 1 and 2 s (Fig 5.2's measure).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/logs/ulog.hpp"
#include "pegasus/logs/ulog_import.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "pegasus/sysid/flight_log.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {
namespace {

using sysid::FlightLog;
using sysid::HorizonMse;

constexpr std::array<double, 3> kHorizons = {0.5, 1.0, 2.0};

void declare_import(ConfigSchema& s) {
  s.add_string("ulog", "", "the PX4 ULog file (.ulg)");
  s.add_string("vehicle", "", "vehicle file whose [log] section names the topics (README: vehicle files)");
  s.add_double("start_s", 0, "skip this many seconds after the first time every topic has data")
      .range(0, 1e6);
  s.add_double("end_s", 0, "end this many seconds after that time (0: where the first topic ends)")
      .range(0, 1e6);
  s.add_string("truncated_tail", "discard",
               "a last message cut off by the end of the file: discard it (the ULog spec's rule) or error")
      .choices({"discard", "error"});
  s.add_bool("identify", true, "identify a model on the first part and report hold-out prediction errors");
  s.add_double("train_fraction", 0.7, "the first part of the log used for identification").range(0.1, 0.95);
  s.add_bool("local", true, "locally weighted regression (false: globally linear)");
  s.add_double("window_s", 8, "cross-validation leaves out this window around each held-out point, s")
      .range(0, 1000);
  s.add_int("cv_points", 300, "held-out points per cross-validation evaluation").range(10, 100000);
  s.add_int("coordinate_passes", 1, "passes of per-input bandwidth refinement").range(0, 10);
  declare_bandwidth_floor(s);
  s.add_double("start_spacing_s", 0.5, "spacing of the open-loop prediction starts on the hold-out part, s")
      .range(0.02, 1000);
}

// Two copies of a log: rows [0, split) and [split, rows).
std::pair<FlightLog, FlightLog> split_log(const FlightLog& log, std::size_t split) {
  FlightLog a, b;
  for (FlightLog* part : {&a, &b}) {
    const std::size_t lo = part == &a ? 0 : split, hi = part == &a ? split : log.rows();
    part->time.assign(log.time.begin() + static_cast<std::ptrdiff_t>(lo),
                      log.time.begin() + static_cast<std::ptrdiff_t>(hi));
    part->states.assign(log.states.begin() + static_cast<std::ptrdiff_t>(lo),
                        log.states.begin() + static_cast<std::ptrdiff_t>(hi));
    part->controls.assign(log.controls.begin() + static_cast<std::ptrdiff_t>(lo),
                          log.controls.begin() + static_cast<std::ptrdiff_t>(hi));
  }
  return {std::move(a), std::move(b)};
}

// Root-mean-square error of every report variable at each of kHorizons, and the rollouts behind it.
nlohmann::json rmse_at_horizons(const HorizonMse& h, nlohmann::json* rollouts) {
  nlohmann::json out = nlohmann::json::object();
  for (double horizon : kHorizons) {
    const std::size_t t = h.seconds.empty() || h.seconds.size() < 2
                              ? 0
                              : static_cast<std::size_t>(std::lround(horizon / h.seconds[1]));
    const std::string key = fmt::format("{}", horizon);
    if (t >= h.seconds.size() || h.count[t] == 0) continue;
    nlohmann::json vars;
    for (std::size_t v = 0; v < sysid::kReportVars; ++v)
      vars[sysid::kReportVarNames[v]] = std::sqrt(h.mse[t][v]);
    out[key] = vars;
    (*rollouts)[key] = h.count[t];
  }
  return out;
}

void run_import(RunContext& ctx) {
  const auto& c = ctx.config;
  if (c.get_string("ulog").empty())
    throw InputError("ulog: a ULog file is required (pegasus log import FILE.ulg)");
  if (c.get_string("vehicle").empty())
    throw InputError("--vehicle: a vehicle file with a [log] section is required");
  const std::filesystem::path file = c.get_string("ulog");
  const logs::VehicleLogSpec spec = logs::read_vehicle_log_spec(c.get_string("vehicle"));
  const logs::UlogFile ulog =
      logs::read_ulog(file, {.truncated_tail = c.get_string("truncated_tail") == "error"
                                                   ? logs::UlogReadOptions::TruncatedTail::kError
                                                   : logs::UlogReadOptions::TruncatedTail::kDiscard,
                             .topics = spec.topic_names()});
  logs::ImportProvenance provenance;
  const FlightLog log =
      logs::import_ulog(ulog, spec, file.string(),
                        {.start_s = c.get_double("start_s"), .end_s = c.get_double("end_s")}, &provenance);
  const std::string sha256 = logs::file_sha256(file);
  const auto bytes = std::filesystem::file_size(file);

  // What moved: a control that never changes carries nothing an identification can learn from.
  nlohmann::json control_range, constant_controls = nlohmann::json::array();
  for (std::size_t k = 0; k < 4; ++k) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& a : log.controls) {
      lo = std::min(lo, a[k]);
      hi = std::max(hi, a[k]);
    }
    const std::string name = sysid::kLogControlColumns[k];
    control_range[name] = {lo, hi};
    if (lo == hi) constant_controls.push_back(name);
  }

  RunDirectory& dir = ctx.run_directory();
  dir.write_text("log.csv", sysid::flight_log_csv(log));
  dir.add_charts(flight_log_sections("log.csv", "",
                                     {sysid::kLogControlColumns.begin(), sysid::kLogControlColumns.end()}));
  nlohmann::json prov = provenance.json;
  prov["source"] = {{"path", file.string()}, {"sha256", sha256}, {"bytes", bytes}};
  dir.write_json("provenance.json", prov);

  nlohmann::json summary = {
      {"source", {{"file", file.filename().string()}, {"sha256", sha256}, {"bytes", bytes}}},
      {"vehicle", spec.vehicle},
      {"rows", log.rows()},
      {"rate_hz", spec.rate_hz},
      {"seconds", log.seconds()},
      {"time_range_s", prov["time_range_s"]},
      {"topics", prov["topics"]},
      {"instance", spec.instance},
      {"dropouts", ulog.dropouts.size()},
      {"dropout_total_ms", prov["dropout_total_ms"]},
      {"truncated_at_byte", prov["ulog"]["truncated_at_byte"]},
      {"control_range", control_range},
      {"constant_controls", constant_controls},
      {"log", "log.csv"},
      {"provenance", "provenance.json"}};
  std::string topics;
  for (const auto& t : prov["topics"]) topics += (topics.empty() ? "" : ", ") + t["topic"].get<std::string>();
  ctx.out << fmt::format("imported {:.1f} s ({} rows at {} Hz) of {} from {}; {} dropouts ({} ms)\n",
                         log.seconds(), log.rows(), spec.rate_hz, topics, file.filename().string(),
                         ulog.dropouts.size(), prov["dropout_total_ms"].get<double>());
  if (ulog.truncated_at)
    ctx.out << fmt::format("warning: the file ends inside the message at byte {}; read up to it\n",
                           *ulog.truncated_at);
  for (const auto& name : constant_controls)
    ctx.out << fmt::format(
        "warning: {} is constant over the log: nothing about its effect can be identified\n",
        name.get<std::string>());

  if (c.get_bool("identify")) {
    const auto split = static_cast<std::size_t>(std::lround(c.get_double("train_fraction") * log.rows()));
    const auto [train, test] = split_log(log, split);
    sysid::IdentifyOptions o;
    o.structure.rate_hz = spec.model_rate_hz;
    o.structure.extra_states = false;  // the X-Cell's rotor and gyro lags are no part of this vehicle
    o.local = c.get_bool("local");
    o.window_s = c.get_double("window_s");
    o.cv_points = static_cast<int>(c.get_int("cv_points"));
    o.coordinate_passes = static_cast<int>(c.get_int("coordinate_passes"));
    o.min_bandwidth = read_bandwidth_floor(c);
    ThreadPool& pool = ctx.pool();
    sysid::IdentifyReport report;
    const sysid::IdentifiedModel model = sysid::identify(train, o, pool, &report);
    sysid::IdentifyOptions global_options = o;
    global_options.local = false;
    const sysid::IdentifiedModel global = sysid::identify(train, global_options, pool);
    model.save(dir.path() / "model.json");

    const double spacing = c.get_double("start_spacing_s"), longest = kHorizons.back();
    const std::vector<std::pair<std::string, HorizonMse>> models = {
        {o.local ? "identified (locally weighted)" : "identified (global linear)",
         sysid::horizon_mse(model, test, longest, spacing, pool)},
        {"global linear", sysid::horizon_mse(global, test, longest, spacing, pool)},
        {"constant velocity", sysid::constant_velocity_mse(test, model.dt(), longest, spacing)}};
    if (models.back().second.count.back() == 0)
      throw InputError(
          fmt::format("--train-fraction: the hold-out part ({:.1f} s) is shorter than the {} s horizon",
                      test.seconds(), longest));
    CsvWriter mse_csv({"model", "seconds", "variable", "mse", "rollouts"});
    nlohmann::json rmse, rollouts;
    const std::array<const char*, 3> keys = {"identified", "global_linear", "constant_velocity"};
    for (std::size_t m = 0; m < models.size(); ++m) {
      const HorizonMse& h = models[m].second;
      for (std::size_t t = 0; t < h.seconds.size(); ++t)
        for (std::size_t v = 0; v < sysid::kReportVars; ++v)
          mse_csv.add_row({models[m].first, h.seconds[t], std::string(sysid::kReportVarNames[v]), h.mse[t][v],
                           std::int64_t{h.count[t]}});
      nlohmann::json n;
      rmse[keys[m]] = rmse_at_horizons(h, &n);
      rollouts[keys[m]] = n;
    }
    dir.write_csv("mse_vs_horizon.csv", mse_csv);
    dir.add_charts(mse_vs_horizon_section("mse_vs_horizon.csv",
                                          {sysid::kReportVarNames.begin(), sysid::kReportVarNames.end()}));
    summary["prediction"] = {{"train_seconds", train.seconds()},
                             {"test_seconds", test.seconds()},
                             {"model_rate_hz", spec.model_rate_hz},
                             {"structure", model.structure().describe()},
                             {"local", o.local},
                             {"training_rows", model.data().rows()},
                             {"horizons_s", kHorizons},
                             {"rmse", rmse},
                             {"rollouts", rollouts},
                             {"model", "model.json"}};
    if (!report.floored_inputs.empty()) summary["prediction"]["bandwidth_at_floor"] = report.floored_inputs;
    ctx.out
        << "hold-out RMSE (identified | global linear | constant velocity; - where the model's fit turned "
           "singular before that horizon):\n";
    for (double horizon : kHorizons) {
      const std::string key = fmt::format("{}", horizon);
      std::string line = fmt::format("  at {} s", horizon);
      for (const char* var : {"z", "zdot_b", "roll", "roll_rate"}) {
        line += fmt::format("  {}", var);
        for (std::size_t m = 0; m < keys.size(); ++m)
          line += (m == 0 ? " " : " | ") + (rmse[keys[m]].contains(key)
                                                ? fmt::format("{:.3g}", rmse[keys[m]][key][var].get<double>())
                                                : std::string("-"));
      }
      ctx.out << line << "\n";
    }
  }
  dir.write_json("summary.json", summary);
  ctx.out << "log: " << (dir.final_path() / "log.csv").string() << "\n";
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
