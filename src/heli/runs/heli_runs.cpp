#include "pegasus/heli/runs/heli_runs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

using sysid::FlightLog;
using sysid::IdentifiedModel;
using sysid::kLogControlColumns;

// ------------------------------------------------------------------ the aircraft

VehicleChoice VehicleChoice::read(const std::string& file) {
  if (file.empty()) return {};
  return {.file = file, .vehicle = logs::read_vehicle(file)};
}

void VehicleChoice::keep(const RunDirectory& dir) const {
  if (from_file()) dir.write_text("vehicle.toml", read_file(file));
}

const std::string& VehicleChoice::simulator() const {
  if (vehicle.simulator == "none")
    throw InputError(
        fmt::format("{}: vehicle.simulator: 'none': the project has no ground truth of {} to fly; serve its "
                    "controller to the aircraft or its simulator with `pegasus control --vehicle {} --policy "
                    "P.json`",
                    vehicle.log.file, vehicle.name(), vehicle.log.file));
  return vehicle.simulator;
}

std::unique_ptr<GroundTruth> VehicleChoice::ground_truth(const GroundTruthSettings& settings) const {
  const std::string& name = simulator();
  try {
    return make_ground_truth(name, settings);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
}

namespace {

// Simulator steps per row of the vehicle's log, when its rate divides the simulator's.
std::optional<std::size_t> steps_per_log_row(const logs::Vehicle& vehicle, const GroundTruth& aircraft) {
  const double steps = 1 / (aircraft.step_seconds() * vehicle.log.rate_hz);
  if (!(steps >= 1 - 1e-9 && std::abs(steps - std::round(steps)) <= 1e-9)) return std::nullopt;
  return static_cast<std::size_t>(std::llround(steps));
}

}  // namespace

void VehicleChoice::check_pilot_log(const GroundTruth& aircraft) const {
  if (!from_file()) return;
  if (!steps_per_log_row(vehicle, aircraft))
    throw InputError(
        fmt::format("{}: log.rate_hz: the {} ground truth steps at {:g} Hz and its pilot logs every n-th "
                    "step; expected a rate that divides {:g} Hz, got {:g} Hz",
                    file, vehicle.simulator, 1 / aircraft.step_seconds(), 1 / aircraft.step_seconds(),
                    vehicle.log.rate_hz));
  (void)logs::vehicle_log_columns(vehicle);
}

VehicleChoice::PilotLog VehicleChoice::write_pilot_log(const RunDirectory& dir, const FlightLog& log,
                                                       const GroundTruth& aircraft) const {
  check_pilot_log(aircraft);
  const std::size_t every = from_file() ? *steps_per_log_row(vehicle, aircraft) : 1;
  if (every == 1 && logs_in_pipeline_layout(vehicle)) {
    dir.write_text("log.csv", flight_log_csv(log));
    return {.charted = "log.csv", .rows = log.rows(), .every = 1};
  }
  dir.write_text("log.csv", logs::vehicle_log_csv(log, vehicle, every));
  dir.write_text("pipeline_log.csv", flight_log_csv(log));
  return {.charted = "pipeline_log.csv", .rows = (log.rows() + every - 1) / every, .every = every};
}

std::shared_ptr<const IdentifiedModel> VehicleChoice::load_model(const std::string& model_file) const {
  if (model_file.empty())
    throw InputError("--model: expected an identified model (model.json of pegasus identify)");
  auto model = std::make_shared<const IdentifiedModel>(IdentifiedModel::load(model_file));
  const std::string identified_for =
      model->vehicle().empty() ? std::string(kBuiltInVehicle) : model->vehicle();
  if (identified_for != vehicle.name())
    throw InputError(fmt::format(
        "{}: vehicle: the model was identified from {}'s logs, and this run is for {}; give the vehicle file "
        "it was identified with (--vehicle)",
        model_file, identified_for, vehicle.name()));
  return model;
}

// ------------------------------------------------------------------ pilot

void run_pilot(const PilotRunOptions& options, RunSink& sink) {
  const std::unique_ptr<GroundTruth> aircraft = options.aircraft.ground_truth(options.settings);
  const double dt = aircraft->step_seconds();
  PilotOptions o = pilot_options_for(options.aircraft.vehicle.simulator);
  o.hover_seconds = options.hover_seconds;
  o.sweeps = options.sweeps;
  for (double& amplitude : o.sweep_amplitude) amplitude *= options.sweep_scale;
  const double seconds = options.seconds;
  RunDirectory& dir = sink.dir;
  options.aircraft.check_pilot_log(*aircraft);
  const PilotFlight f = fly_pilot(*aircraft, o, seconds, options.seed);
  options.aircraft.keep(dir);
  const VehicleChoice::PilotLog written = options.aircraft.write_pilot_log(dir, f.log, *aircraft);
  FlightLog truth = f.log;
  for (std::size_t i = 0; i < truth.rows(); ++i) truth.states[i] = f.truth[i];
  dir.write_text("truth.csv", flight_log_csv(truth));
  const auto log_charts = flight_log_sections(written.charted, "truth.csv",
                                              {kLogControlColumns.begin(), kLogControlColumns.end()});
  dir.add_charts(log_charts);
  dir.write_chart_svg("position.svg", log_charts.front().charts.back());
  const HoverPoint trim = aircraft->hover_point();
  nlohmann::json summary = {{"seconds", static_cast<double>(f.log.rows()) * dt},
                            {"rows", written.rows},
                            {"rate_hz", 1 / (dt * static_cast<double>(written.every))},
                            {"crashed", f.crash != CrashReason::kNone},
                            {"crash_reason", crash_reason_name(f.crash)},
                            {"crash_time", f.crash_time},
                            {"trim", {{"roll", trim.roll}, {"pitch", trim.pitch}}},
                            {"log", "log.csv"},
                            {"truth", "truth.csv"}};
  for (std::size_t c = 0; c < kControlNames.size(); ++c) summary["trim"][kControlNames[c]] = trim.controls[c];
  if (options.aircraft.from_file()) summary["vehicle"] = options.aircraft.vehicle.name();
  if (written.charted != "log.csv") summary["pipeline_log"] = written.charted;  // log.csv in the file's terms
  dir.write_json("summary.json", summary);
  sink.out << fmt::format("flew {:.1f} s ({} rows at {:g} Hz){}; log: {}\n", summary["seconds"].get<double>(),
                          written.rows, summary["rate_hz"].get<double>(),
                          f.crash != CrashReason::kNone ? ", CRASHED: " + crash_reason_name(f.crash) : "",
                          sink.named(dir.final_path() / "log.csv"));
  if (f.crash != CrashReason::kNone)
    throw std::runtime_error(
        fmt::format("the pilot crashed ({}) at {} s", crash_reason_name(f.crash), f.crash_time));
}

void run_control(const ControlRunOptions& options, std::FILE* in, std::FILE* out, std::FILE* err,
                 std::ostream& report) {
  const std::string& path = options.policy_file;
  if (path.empty()) throw InputError("--policy: expected a policy file (policy.json of pegasus heli hover)");
  const PolicyFile file = read_policy_file(path);
  const auto controller = make_controller(file, path);
  if (options.bench_lines > 0) {
    if (!options.vehicle_file.empty())
      throw InputError(
          "--bench-lines: the synthetic lines are in the pipeline's own layout; time the loop without "
          "--vehicle");
    const ControlLoopTiming t = time_control_loop(*controller, file.trim, options.bench_lines);
    report << fmt::format("{} lines in {:.3f} s: {:.0f} lines/s (each line parsed, answered and flushed)\n",
                          t.lines, t.seconds, static_cast<double>(t.lines) / t.seconds);
    return;
  }
  double dt = 0.02;  // a line's time when it has none: the policy's rate
  if (const auto it = file.options.find("control_rate_hz");
      it != file.options.end() && it->is_number() && it->get<double>() > 0)
    dt = 1 / it->get<double>();
  // A policy trained for another aircraft (than the vehicle file, or the X-Cell without one) still runs: the
  // user may mean it, but not silently.
  const VehicleChoice aircraft = VehicleChoice::read(options.vehicle_file);
  const logs::Vehicle& vehicle = aircraft.vehicle;
  if (const std::string w =
          other_vehicle_warning(trained_vehicle(file), path, vehicle.name(), "serving it in the terms of");
      !w.empty())
    std::fprintf(err, "%s\n", w.c_str());
  const ControlLoopStats stats =
      aircraft.from_file()
          ? run_control_loop(*controller, file.trim, in, out, err, dt, logs::control_line_format(vehicle))
          : run_control_loop(*controller, file.trim, in, out, err, dt);
  // Every line was answered (the trim controls); the exit code says that none was served from the input.
  if (!stats.header_refused.empty())
    throw InputError(fmt::format("stdin:1: {}; all {} lines after it were answered with the trim controls",
                                 printable(stats.header_refused), stats.lines - 1));
}

void write_pipeline_summary(const std::string& vehicle, double flight_seconds, RunSink& sink) {
  const nlohmann::json hover = read_json_file(sink.dir.path() / "hover" / "summary.json");
  const nlohmann::json fly = read_json_file(sink.dir.path() / "fly" / "summary.json");
  nlohmann::json summary = {
      {"hover", {{"initial_uhat", hover.at("initial_uhat")}, {"final_uhat", hover.at("final_uhat")}}},
      {"flights", fly.at("flights")},
      {"crashes", fly.at("crashes")},
      {"rms_position_m", fly.at("rms_position_m")},
      {"rms_velocity_mps", fly.at("rms_velocity_mps")},
      {"rms_yaw_rad", fly.at("rms_yaw_rad")},
      {"pilot", fly.at("pilot")}};
  // The noise-check flights (heli pipeline's noise_check_flights) sit between the test flight and identify.
  std::vector<std::string> stages = {"pilot-train", "pilot-test"};
  for (int i = 1; std::filesystem::exists(sink.dir.path() / fmt::format("pilot-check-{}", i)); ++i)
    stages.push_back(fmt::format("pilot-check-{}", i));
  stages.insert(stages.end(), {"identify", "hover", "fly"});
  summary["stages"] = stages;
  const nlohmann::json identify = read_json_file(sink.dir.path() / "identify" / "summary.json");
  if (identify.contains("noise_check_passes")) summary["noise_check_passes"] = identify["noise_check_passes"];
  if (!vehicle.empty()) summary["vehicle"] = vehicle;  // only then: the X-Cell's summaries stay as they were
  // The choices made from the data: identify's (model class, noise, control gains), then hover's start and
  // optimizer, its wind and command limits.
  nlohmann::json choices = identify.value("choices", nlohmann::json::object());
  for (const char* key : {"start", "optimizer", "wind", "command_limits", "training_model"})
    if (hover.contains("choices") && hover["choices"].contains(key)) choices[key] = hover["choices"][key];
  summary["choices"] = choices;
  sink.dir.write_json("summary.json", summary);
  const auto& pl = fly.at("pilot");
  const std::filesystem::path final_fly = sink.dir.final_path() / "fly";
  sink.out << fmt::format("\n== {} pipeline: headline figures ==\n",
                          vehicle.empty() ? std::string("helicopter") : vehicle);
  sink.out << "choices: " << choices.dump() << "\n";
  if (identify.contains("noise_check_passes"))
    sink.out << fmt::format("noise check: the learned model's 2 sd bands {} on {} hold-out steps\n",
                            identify["noise_check_passes"].get<bool>() ? "pass" : "fail",
                            identify.value("noise_check_steps", 0));
  sink.out << fmt::format("hover training U-hat: {:.6g} -> {:.6g}\n", hover.at("initial_uhat").get<double>(),
                          hover.at("final_uhat").get<double>());
  sink.out << fmt::format(
      "learned policy on the ground truth: {} flights of {} s, {} crashes, RMS position {:.3f} m, velocity "
      "{:.3f} m/s, yaw {:.4f} rad\n",
      fly.at("flights").get<int>(), format_double(flight_seconds), fly.at("crashes").get<int>(),
      fly.at("rms_position_m").get<double>(), fly.at("rms_velocity_mps").get<double>(),
      fly.at("rms_yaw_rad").get<double>());
  sink.out << fmt::format(
      "scripted pilot, same starts and gusts:       {} crashes, RMS position {:.3f} m, velocity {:.3f} m/s, "
      "yaw {:.4f} rad\n",
      pl.at("crashes").get<int>(), pl.at("rms_position_m").get<double>(),
      pl.at("rms_velocity_mps").get<double>(), pl.at("rms_yaw_rad").get<double>());
  sink.out << "plots: " << sink.named(final_fly / "position_x.svg")
           << ", position_y.svg, altitude.svg, velocity_xb/yb/zb.svg (Figs 5.6-5.7); "
           << sink.named(sink.dir.final_path() / "hover" / "progress.svg") << "; "
           << sink.named(sink.dir.final_path() / "identify" / "mse_xdot_b.svg") << "\n";
}

}  // namespace pegasus::heli
