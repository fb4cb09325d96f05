// `pegasus fly` / `heli fly` (run_fly): flights of a policy, the scripted pilot or the ground truth's
// hand-tuned baseline (heli/baselines.hpp) on the vehicle's ground truth, judged by the vehicle file's [cost]
// when it states one.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/baselines.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus::heli {
namespace {

// `with_cost`: the flights were judged (FlightOptions::cost): judged_cost too (only then: digests).
nlohmann::json flight_summary_json(const FlightSummary& s, bool with_cost) {
  nlohmann::json j = {{"flights", s.flights},
                      {"crashes", s.crashes},
                      {"rms_position_m", s.rms_position_m},
                      {"rms_velocity_mps", s.rms_velocity_mps},
                      {"rms_yaw_rad", s.rms_yaw_rad}};
  if (with_cost) j["judged_cost"] = s.judged_cost;
  return j;
}

CsvWriter flights_csv(const std::vector<FlightRecord>& flights) {
  FlightsCsv table;
  for (std::size_t i = 0; i < flights.size(); ++i)
    for (const auto& row : flights[i].trace) table.add(static_cast<std::int64_t>(i), row);
  return table.csv();
}

CsvWriter per_flight_csv(bool with_cost) {
  std::vector<std::string> columns = {"controller", "flight",         "crashed",          "crash_reason",
                                      "crash_time", "rms_position_m", "rms_velocity_mps", "rms_yaw_rad"};
  if (with_cost) columns.emplace_back("judged_cost");
  return CsvWriter(columns);
}

// The judged_cost cell of per_flight.csv: none (no [cost]), the flight's, or empty (the pilot, unjudged).
enum class CostCell { kNone, kValue, kEmpty };

void add_per_flight(CsvWriter& csv, const std::string& who, const std::vector<FlightRecord>& flights,
                    CostCell cost) {
  for (std::size_t i = 0; i < flights.size(); ++i) {
    const auto& f = flights[i];
    const double n = std::max(1, f.steps);
    std::vector<CsvCell> row = {who,
                                static_cast<std::int64_t>(i),
                                std::int64_t{f.crashed ? 1 : 0},
                                crash_reason_name(f.crash),
                                f.crash_time,
                                std::sqrt(f.sum_sq_position / n),
                                std::sqrt(f.sum_sq_velocity / n),
                                std::sqrt(f.sum_sq_yaw / n)};
    if (cost == CostCell::kValue) row.emplace_back(f.judged_cost);
    if (cost == CostCell::kEmpty) row.emplace_back(std::string());
    csv.add_row(row);
  }
}

// Figs 5.6-5.7 (body-frame velocities and world positions of flight 0 against time, the policy against the
// pilot) and the 3-D replay of every traced flight; the SVGs are drawn from the same charts.
void add_flight_charts(RunDirectory& dir, const std::string& main_name, bool with_pilot) {
  std::vector<FlightSeries> files = {{.file = "flights.csv", .label = main_name, .body_velocities = true}};
  if (with_pilot)
    files.push_back({.file = "pilot_flights.csv", .label = "scripted pilot", .body_velocities = true});
  const ChartSection traces = flight_traces_section(
      files, "hover", with_pilot ? "Flights against the pilot (Figs 5.6-5.7)" : "Flight traces",
      with_pilot
          ? "Blue, solid: the learned controller; red, dashed: the scripted pilot; the first flight of "
            "each (all of them are in the 3-D replay). Body-frame velocities (Fig 5.6) and world "
            "positions (Fig 5.7)."
          : "Body-frame velocities and world positions of the first flight; all of them are in the 3-D "
            "replay.");
  dir.add_charts(
      {traces, ChartSection{.id = "replay",
                            .title = "3-D replay",
                            .intro = "Drag to turn the view, scroll to zoom; Play runs the flight in "
                                     "real time (speed adjustable), the slider moves through it.",
                            .charts = {flight_replay_chart(files)}}});
  const char* svgs[] = {"velocity_xb.svg", "velocity_yb.svg", "velocity_zb.svg",
                        "position_x.svg",  "position_y.svg",  "altitude.svg"};
  for (std::size_t i = 0; i < traces.charts.size(); ++i) dir.write_chart_svg(svgs[i], traces.charts[i]);
}

// The policy file's controller, its set point, its rate (0: the aircraft's) and its trim.
struct FlownPolicy {
  std::unique_ptr<HeliController> controller;
  SetPoint target;
  double control_rate_hz = 0;
  Controls trim{};
};

FlownPolicy read_flown_policy(const std::string& policy_path, const logs::Vehicle& vehicle, RunSink& sink) {
  const PolicyFile file = read_policy_file(policy_path);
  FlownPolicy p;
  p.controller = make_controller(file, policy_path);
  p.trim = file.trim;
  if (const std::string w =
          other_vehicle_warning(trained_vehicle(file), policy_path, vehicle.name(), "flying it on");
      !w.empty())
    sink.out << w << "\n";
  p.target = p.controller->target(0);
  if (!(p.target.z < 0))
    throw InputError(
        fmt::format("{}: target.z = {:g} is at or below the ground (NED: z < 0 is above it), "
                    "where every flight would start",
                    policy_path, p.target.z));
  if (const auto it = file.options.find("control_rate_hz"); it != file.options.end()) {
    if (!it->is_number() || !(it->get<double>() > 0))
      throw InputError(
          fmt::format("{}: options.control_rate_hz: expected a number > 0, got {}", policy_path, it->dump()));
    p.control_rate_hz = it->get<double>();
  }
  return p;
}

// Aircraft steps per controller call at `rate_hz` (0: every step).
int control_every(double dt, double rate_hz, const std::string& where) {
  if (!(rate_hz > 0)) return 1;
  // A controller slower than the aircraft's 50 Hz is called at its own rate, its controls held.
  const double ratio = 1 / (dt * rate_hz);
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio || std::round(ratio) < 1)
    throw InputError(fmt::format("{}: {} Hz does not divide the aircraft's {} Hz", where, rate_hz, 1 / dt));
  return static_cast<int>(std::round(ratio));
}

// One controller at a time, and a baseline only for a ground truth that has one: bad input otherwise.
void check_controllers(const FlyRunOptions& options) {
  if (options.pilot_only && options.baseline_only)
    throw InputError("--pilot, --baseline: expected one of them, not both");
  if (!options.pilot_only && !options.baseline_only && options.policy_file.empty())
    throw InputError(
        "--policy: expected a policy file (policy.json of pegasus heli hover), --pilot or --baseline");
  if (options.baseline_only || options.compare_baseline) {
    try {
      baseline_name(options.aircraft.simulator());
    } catch (const std::invalid_argument& e) {
      throw InputError(std::string("--baseline: ") + e.what());
    }
  }
}

// The flights of the policy and the baseline: at the policy's rate (the vehicle's controller rate without a
// policy), judged per control step by the vehicle's [cost] when it states one (not with --pilot: the pilot
// flies at the aircraft's rate, unjudged).
FlightOptions controller_flights(const FlyRunOptions& options, const FlownPolicy* policy,
                                 const GroundTruth& aircraft) {
  const logs::Vehicle& vehicle = options.aircraft.vehicle;
  const double dt = aircraft.step_seconds();
  FlightOptions o = options.flights;
  o.control_every =
      policy ? control_every(dt, policy->control_rate_hz, options.policy_file + ": options.control_rate_hz")
             : control_every(dt, options.aircraft.from_file() ? vehicle.control_rate_hz : 0,
                             "vehicle: control.rate_hz");
  if (vehicle.cost && !options.pilot_only) {
    FlightCost cost{.reward = logs::judged_reward(vehicle), .crash = vehicle.cost->crash};
    if (vehicle.cost->controls_about_trim)  // the logs' mean controls: the policy's trim, or the aircraft's
      cost.reward.centre = policy ? policy->trim : aircraft.hover_point().controls;
    o.cost = cost;
  }
  return o;
}

std::string flights_line(const std::string& who, const FlightSummary& f, bool with_cost) {
  return fmt::format(
      "{}: {} flights, {} crashes, RMS position {:.3f} m, velocity {:.3f} m/s, yaw {:.4f} rad{}\n", who,
      f.flights, f.crashes, f.rms_position_m, f.rms_velocity_mps, f.rms_yaw_rad,
      with_cost ? fmt::format(", judged cost {:.6g} per flight", f.judged_cost) : "");
}

// The comparison of the main flights with the baseline's: summary keys baseline_ratio and
// better_than_baseline, and one printed line.
std::string compare_with_baseline(const FlightSummary& s, const FlightSummary& b, bool with_cost,
                                  nlohmann::json& summary) {
  const double position = s.rms_position_m > 0 ? b.rms_position_m / s.rms_position_m : 0.0;
  summary["baseline_ratio"] = {{"rms_position", position}};
  summary["better_than_baseline"] = {{"position", s.rms_position_m < b.rms_position_m},
                                     {"crashes", s.crashes <= b.crashes}};
  std::string cost;
  if (with_cost) {
    const double ratio = s.judged_cost > 0 ? b.judged_cost / s.judged_cost : 0.0;
    summary["baseline_ratio"]["judged_cost"] = ratio;
    summary["better_than_baseline"]["judged_cost"] = s.judged_cost < b.judged_cost;
    cost = fmt::format(", judged cost {:.3g}x", ratio);
  }
  return fmt::format("against the baseline: RMS position {:.3g}x{} (the baseline's over this controller's)\n",
                     position, cost);
}

// The ground truth of the run's settings, started at the set point.
std::unique_ptr<GroundTruth> ground_truth_at(const FlyRunOptions& options, const SetPoint& target) {
  GroundTruthSettings settings = options.settings;
  settings.set_start = true;
  settings.start_p_W = Vec3(target.x, target.y, target.z);
  settings.start_yaw = target.yaw;
  return options.aircraft.ground_truth(settings);
}

}  // namespace

void run_fly(const FlyRunOptions& options, RunSink& sink, ThreadPool& pool) {
  const logs::Vehicle& vehicle = options.aircraft.vehicle;
  const bool pilot_only = options.pilot_only, baseline_only = options.baseline_only;
  const std::string& policy_path = options.policy_file;
  check_controllers(options);
  const bool with_baseline = baseline_only || options.compare_baseline;
  std::optional<FlownPolicy> policy;
  SetPoint target;
  if (!policy_path.empty()) {
    policy = read_flown_policy(policy_path, vehicle, sink);
    target = policy->target;
  } else if (baseline_only) {
    target = {vehicle.target[0], vehicle.target[1], vehicle.target[2], vehicle.target[3]};
  }
  const std::unique_ptr<GroundTruth> aircraft = ground_truth_at(options, target);
  const double dt = aircraft->step_seconds();
  const FlightOptions& fo = options.flights;
  const FlightOptions controller_options =
      controller_flights(options, policy ? &*policy : nullptr, *aircraft);
  const bool with_cost = controller_options.cost.has_value();
  RunDirectory& dir = sink.dir;

  const bool with_pilot = pilot_only || options.compare_pilot;
  std::vector<FlightRecord> flown, pilot, baseline;
  if (policy) flown = fly_controller(*aircraft, *policy->controller, controller_options, &pool);
  if (with_pilot) pilot = fly_pilot_hover(*aircraft, pilot_options_for(vehicle.simulator), target, fo, &pool);
  if (with_baseline) {
    const auto b = make_baseline(vehicle.simulator, *aircraft, target, dt * controller_options.control_every);
    baseline = fly_controller(*aircraft, *b, controller_options, &pool);
  }
  const std::string baseline_label = with_baseline ? "baseline:" + baseline_name(vehicle.simulator) : "";
  const std::string main_who = pilot_only ? "pilot" : baseline_only ? "baseline" : "policy";
  const std::vector<FlightRecord>& main = pilot_only ? pilot : baseline_only ? baseline : flown;
  const FlightSummary s = summarize_flights(main);
  nlohmann::json summary = flight_summary_json(s, with_cost);
  summary["controller"] = pilot_only ? "pilot" : baseline_only ? baseline_label : sink.named(policy_path);
  summary["seconds"] = fo.seconds;
  if (options.aircraft.from_file()) summary["vehicle"] = vehicle.name();
  if (const Vec3& wind = options.settings.mean_wind_W; !wind.isZero(0))  // only then: digests
    summary["wind"] = std::vector<double>{wind.x(), wind.y(), wind.z()};
  options.aircraft.keep(dir);
  CsvWriter per_flight = per_flight_csv(with_cost);
  const CostCell judged = with_cost ? CostCell::kValue : CostCell::kNone;
  add_per_flight(per_flight, main_who, main, judged);
  dir.write_csv("flights.csv", flights_csv(main));
  const bool pilot_beside = with_pilot && !pilot_only;
  if (pilot_beside) {
    const FlightSummary ps = summarize_flights(pilot);
    summary["pilot"] = flight_summary_json(ps, false);
    summary["better_than_pilot"] = {{"position", s.rms_position_m < ps.rms_position_m},
                                    {"velocity", s.rms_velocity_mps < ps.rms_velocity_mps}};
    add_per_flight(per_flight, "pilot", pilot, with_cost ? CostCell::kEmpty : CostCell::kNone);
    dir.write_csv("pilot_flights.csv", flights_csv(pilot));
  }
  std::optional<FlightSummary> bs;
  std::string comparison;
  if (with_baseline && !baseline_only) {
    bs = summarize_flights(baseline);
    summary["baseline"] = flight_summary_json(*bs, with_cost);
    summary["baseline"]["controller"] = baseline_label;
    comparison = compare_with_baseline(s, *bs, with_cost, summary);
    add_per_flight(per_flight, "baseline", baseline, judged);
    dir.write_csv("baseline_flights.csv", flights_csv(baseline));
  }
  dir.write_csv("per_flight.csv", per_flight);
  add_flight_charts(dir,
                    pilot_only      ? "scripted pilot"
                    : baseline_only ? baseline_label
                                    : "learned policy",
                    pilot_beside);
  dir.write_json("summary.json", summary);
  sink.out << flights_line(main_who, s, with_cost);
  if (pilot_beside) sink.out << flights_line("pilot", summarize_flights(pilot), false);
  if (bs) sink.out << flights_line(baseline_label, *bs, with_cost) << comparison;
  sink.out << "plots: " << sink.named(dir.final_path() / "position_x.svg")
           << " (and position_y.svg, altitude.svg, velocity_*.svg)\n";
}

}  // namespace pegasus::heli
