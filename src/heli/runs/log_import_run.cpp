#include "pegasus/heli/runs/log_import_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/sha256.hpp"
#include "pegasus/logs/ulog.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus {

namespace {

using sysid::FlightLog;
using sysid::HorizonMse;

constexpr std::array<double, 3> kHorizons = {0.5, 1.0, 2.0};

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

// What moved: each control's range, and the controls that never change (they carry nothing an
// identification can learn from).
struct ControlRanges {
  nlohmann::json range, constant = nlohmann::json::array();
};

ControlRanges control_ranges(const FlightLog& log) {
  ControlRanges out;
  for (std::size_t k = 0; k < 4; ++k) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& a : log.controls) {
      lo = std::min(lo, a[k]);
      hi = std::max(hi, a[k]);
    }
    const std::string name = sysid::kLogControlColumns[k];
    out.range[name] = {lo, hi};
    if (lo == hi) out.constant.push_back(name);
  }
  return out;
}

// The lines that say what was imported, and warn of a truncated file and of constant controls.
std::string imported_lines(const FlightLog& log, const logs::VehicleLogSpec& spec, const logs::UlogFile& ulog,
                           const nlohmann::json& prov, const std::filesystem::path& file,
                           const nlohmann::json& constant_controls) {
  std::string topics;
  for (const auto& t : prov["topics"]) topics += (topics.empty() ? "" : ", ") + t["topic"].get<std::string>();
  std::ostringstream imported;
  imported << fmt::format(
      "imported {:.1f} s ({} rows at {} Hz) of {} from {}; {} dropouts in the file ({} ms)\n", log.seconds(),
      log.rows(), spec.rate_hz, topics, file.filename().string(), ulog.dropouts.size(),
      prov["dropout_total_ms"].get<double>());
  if (ulog.truncated_at)
    imported << fmt::format("warning: the file ends inside the message at byte {}; read up to it\n",
                            *ulog.truncated_at);
  for (const auto& name : constant_controls)
    imported << fmt::format(
        "warning: {} is constant over the log: nothing about its effect can be identified\n",
        name.get<std::string>());
  return imported.str();
}

// The hold-out prediction study of the imported log (LogImportRunOptions::identify): summary.json's
// `prediction`, and the root-mean-square errors the terminal gets.
struct ImportPrediction {
  nlohmann::json summary, rmse;
};

constexpr std::array<const char*, 3> kPredictionKeys = {"identified", "global_linear", "constant_velocity"};

// The identification options for the imported log, its training part long enough for them.
sysid::IdentifyOptions import_identify_options(const LogImportRunOptions& o, const logs::Vehicle& vehicle,
                                               const FlightLog& log, const FlightLog& train,
                                               const FlightLog& test, const std::filesystem::path& file) {
  const logs::VehicleLogSpec& spec = vehicle.log;
  sysid::IdentifyOptions io = o.identification;
  io.structure.rate_hz = spec.model_rate_hz;
  // A range too short to identify from is the range's fault, or the import's wish: say which options.
  const double log_dt = 1 / spec.rate_hz;
  if (const std::size_t need = sysid::min_training_log_rows(log_dt, io.structure);
      train.rows() < need || test.rows() < 2)
    throw InputError(fmt::format(
        "{}: the imported range gives {} rows ({:.1f} s at {} Hz), {} of them for training; identification "
        "at {} Hz needs at least {} training rows ({:.1f} s): choose a longer range (--start-s, --end-s), "
        "a "
        "larger --train-fraction, or --identify=false to import only",
        file.string(), log.rows(), static_cast<double>(log.rows()) * log_dt, spec.rate_hz, train.rows(),
        io.structure.rate_hz, need, static_cast<double>(need) * log_dt));
  io.structure.extra_states = false;  // the X-Cell's rotor and gyro lags are no part of this vehicle
  io.structure.templates = vehicle.kinematic_templates;
  return io;
}

// mse_vs_horizon.csv of the models, with its charts, and their RMSE at kHorizons (the rollouts behind each
// into `rollouts`).
nlohmann::json write_prediction_errors(RunDirectory& dir,
                                       const std::vector<std::pair<std::string, HorizonMse>>& models,
                                       nlohmann::json& rollouts) {
  CsvWriter mse_csv({"model", "seconds", "variable", "mse", "rollouts"});
  nlohmann::json rmse;
  for (std::size_t m = 0; m < models.size(); ++m) {
    const HorizonMse& h = models[m].second;
    for (std::size_t t = 0; t < h.seconds.size(); ++t)
      for (std::size_t v = 0; v < sysid::kReportVars; ++v)
        mse_csv.add_row({models[m].first, h.seconds[t], std::string(sysid::kReportVarNames[v]), h.mse[t][v],
                         std::int64_t{h.count[t]}});
    nlohmann::json n;
    rmse[kPredictionKeys[m]] = rmse_at_horizons(h, &n);
    rollouts[kPredictionKeys[m]] = n;
  }
  dir.write_csv("mse_vs_horizon.csv", mse_csv);
  dir.add_charts(mse_vs_horizon_section("mse_vs_horizon.csv",
                                        {sysid::kReportVarNames.begin(), sysid::kReportVarNames.end()}));
  return rmse;
}

// The identified model (model.json) against a global linear one and constant velocity on the hold-out part.
ImportPrediction predict_imported(const LogImportRunOptions& o, const logs::Vehicle& vehicle,
                                  const FlightLog& log, const std::filesystem::path& file, RunDirectory& dir,
                                  ThreadPool& pool) {
  const auto split =
      static_cast<std::size_t>(std::lround(o.train_fraction * static_cast<double>(log.rows())));
  const auto [train, test] = split_log(log, split);
  const sysid::IdentifyOptions io = import_identify_options(o, vehicle, log, train, test, file);
  sysid::IdentifyReport report;
  const sysid::IdentifiedModel model = sysid::identify(train, io, pool, &report);
  sysid::IdentifyOptions global_options = io;
  global_options.local = false;
  const sysid::IdentifiedModel global = sysid::identify(train, global_options, pool);
  model.save(dir.path() / "model.json");

  const double spacing = o.start_spacing_s, longest = kHorizons.back();
  const std::vector<std::pair<std::string, HorizonMse>> models = {
      {io.local ? "identified (locally weighted)" : "identified (global linear)",
       sysid::horizon_mse(model, test, longest, spacing, pool)},
      {"global linear", sysid::horizon_mse(global, test, longest, spacing, pool)},
      {"constant velocity", sysid::constant_velocity_mse(test, model.dt(), longest, spacing)}};
  if (models.back().second.count.back() == 0)
    throw InputError(
        fmt::format("--train-fraction: the hold-out part ({:.1f} s) is shorter than the {} s horizon",
                    test.seconds(), longest));
  nlohmann::json rollouts;
  ImportPrediction out;
  out.rmse = write_prediction_errors(dir, models, rollouts);
  out.summary = {{"train_seconds", train.seconds()},
                 {"test_seconds", test.seconds()},
                 {"model_rate_hz", vehicle.log.model_rate_hz},
                 {"structure", model.structure().describe()},
                 {"local", io.local},
                 {"training_rows", model.data().rows()},
                 {"horizons_s", kHorizons},
                 {"rmse", out.rmse},
                 {"rollouts", rollouts},
                 {"model", "model.json"}};
  if (!report.floored_inputs.empty()) out.summary["bandwidth_at_floor"] = report.floored_inputs;
  return out;
}

void say_prediction_rmse(std::ostream& out, const nlohmann::json& rmse) {
  out << "hold-out RMSE (identified | global linear | constant velocity; - where the model's fit turned "
         "singular before that horizon):\n";
  for (double horizon : kHorizons) {
    const std::string key = fmt::format("{}", horizon);
    std::string line = fmt::format("  at {} s", horizon);
    for (const char* var : {"z", "zdot_b", "roll", "roll_rate"}) {
      line += fmt::format("  {}", var);
      for (std::size_t m = 0; m < kPredictionKeys.size(); ++m)
        line += (m == 0 ? " " : " | ") +
                (rmse[kPredictionKeys[m]].contains(key)
                     ? fmt::format("{:.3g}", rmse[kPredictionKeys[m]][key][var].get<double>())
                     : std::string("-"));
    }
    out << line << "\n";
  }
}

}  // namespace

void run_log_import(const LogImportRunOptions& o, RunSink& sink, ThreadPool& pool) {
  if (o.ulog_file.empty()) throw InputError("ulog: a ULog file is required (pegasus log import FILE.ulg)");
  if (o.vehicle_file.empty()) throw InputError("--vehicle: a vehicle file with a [log] section is required");
  const std::filesystem::path file = o.ulog_file;
  const logs::Vehicle vehicle = logs::read_vehicle(o.vehicle_file);
  const logs::VehicleLogSpec& spec = vehicle.log;
  const logs::UlogFile ulog =
      logs::read_ulog(file, {.truncated_tail = o.truncated_tail, .topics = spec.topic_names()});
  logs::ImportProvenance provenance;
  const FlightLog log = logs::import_ulog(ulog, spec, file.string(), o.window, &provenance);
  const std::string sha256 = file_sha256(file);
  const auto bytes = std::filesystem::file_size(file);
  const ControlRanges controls = control_ranges(log);

  RunDirectory& dir = sink.dir;
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
      {"control_range", controls.range},
      {"constant_controls", controls.constant},
      {"log", "log.csv"},
      {"provenance", "provenance.json"}};
  // Printed once the identification below has worked too: bad input there is the one line the run prints.
  std::string imported = imported_lines(log, spec, ulog, prov, file, controls.constant);
  if (o.identify) {
    const ImportPrediction prediction = predict_imported(o, vehicle, log, file, dir, pool);
    summary["prediction"] = prediction.summary;
    sink.out << imported;
    imported.clear();
    say_prediction_rmse(sink.out, prediction.rmse);
  }
  dir.write_json("summary.json", summary);
  sink.out << imported << "log: " << sink.named(dir.final_path() / "log.csv") << "\n";
}

void declare_log_import_config(ConfigSchema& s) {
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
  const sysid::IdentifyOptions identification = LogImportRunOptions{}.identification;
  for (const char* key : {"window_s", "cv_points", "coordinate_passes"})  // IdentifyOptions::VisitFields
    declare_numbers(s, identification, key);
  heli::declare_bandwidth_floor(s);
  s.add_double("start_spacing_s", LogImportRunOptions{}.start_spacing_s,
               "spacing of the open-loop prediction starts on the hold-out part, s")
      .range(0.02, 1000);
}

LogImportRunOptions read_log_import_config(const ConfigSchema& c) {
  LogImportRunOptions o{.ulog_file = c.get_path("ulog"),
                        .vehicle_file = c.get_path("vehicle"),
                        .window = {.start_s = c.get_double("start_s"), .end_s = c.get_double("end_s")},
                        .truncated_tail = c.get_string("truncated_tail") == "error"
                                              ? logs::UlogReadOptions::TruncatedTail::kError
                                              : logs::UlogReadOptions::TruncatedTail::kDiscard,
                        .identify = c.get_bool("identify"),
                        .train_fraction = c.get_double("train_fraction"),
                        .start_spacing_s = c.get_double("start_spacing_s")};
  o.identification.local = c.get_bool("local");
  read_numbers(c, o.identification);  // the three it declares
  o.identification.min_bandwidth = heli::read_bandwidth_floor(c);
  return o;
}

}  // namespace pegasus
