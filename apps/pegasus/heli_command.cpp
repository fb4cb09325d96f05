// `pegasus heli pilot` and `pegasus heli identify`: the ground-truth aircraft flown by the scripted pilot, and
// system identification by locally weighted regression (thesis §5.1-5.2).
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/runs/output.hpp"
#include "pegasus/runs/svg_plot.hpp"
#include "pegasus/sysid/flight_log.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::cli {
namespace {

using namespace pegasus::heli;
using namespace pegasus::sysid;

// ------------------------------------------------------------------ heli pilot

void declare_pilot(ConfigSchema& s) {
  s.add_double("seconds", 339, "flight length, s (the thesis used 339 s to train, 140 s to test)").range(1, 36000);
  s.add_double("hover_seconds", 10, "plain hover before the sweeps, s").range(0, 36000);
  s.add_bool("sweeps", true, "fly a frequency sweep (0.1 to 3 Hz) in each channel in turn after the hover");
  s.add_double("gust_sigma", 0.5, "turbulence standard deviation per axis, m/s").range(0, 10);
  s.add_bool("estimate_noise", true, "add Kalman-filter-like state-estimate errors to the log");
}

void run_pilot(RunContext& ctx) {
  const auto& c = ctx.config;
  AircraftParams p;
  p.gust_sigma = c.get_double("gust_sigma");
  if (!c.get_bool("estimate_noise")) p.est_sigma_pos = p.est_sigma_vel = p.est_sigma_angle = p.est_sigma_rate = 0;
  const Aircraft aircraft(p);
  PilotOptions o;
  o.hover_seconds = c.get_double("hover_seconds");
  o.sweeps = c.get_bool("sweeps");
  const double seconds = c.get_double("seconds");
  const PilotFlight f = fly_pilot(aircraft, o, seconds, ctx.seed);
  RunDirectory& dir = ctx.run_directory();
  dir.write_text("log.csv", flight_log_csv(f.log));
  FlightLog truth = f.log;
  for (std::size_t i = 0; i < truth.rows(); ++i) truth.states[i] = f.truth[i];
  dir.write_text("truth.csv", flight_log_csv(truth));
  SvgPlot plot;
  plot.title("Pilot flight: position (world, NED)").x_label("time, s").y_label("m");
  for (int v = 0; v < 3; ++v) {
    PlotSeries s{.name = kLogStateColumns[static_cast<std::size_t>(v)], .markers = false};
    for (std::size_t i = 0; i < f.truth.size(); i += 5) {
      s.x.push_back(f.log.time[i]);
      s.y.push_back(f.truth[i][static_cast<std::size_t>(v)]);
    }
    plot.add_series(std::move(s));
  }
  dir.write_text("position.svg", plot.render());
  const auto& trim = aircraft.hover_trim();
  const nlohmann::json summary = {
      {"seconds", static_cast<double>(f.log.rows()) * p.dt},
      {"rows", f.log.rows()},
      {"rate_hz", 1 / p.dt},
      {"crashed", f.crash != CrashReason::kNone},
      {"crash_reason", crash_reason_name(f.crash)},
      {"crash_time", f.crash_time},
      {"trim", {{"a1", trim.controls[0]}, {"a2", trim.controls[1]}, {"a3", trim.controls[2]}, {"a4", trim.controls[3]},
                {"roll", trim.roll}, {"pitch", trim.pitch}}},
      {"log", "log.csv"},
      {"truth", "truth.csv"}};
  dir.write_json("summary.json", summary);
  ctx.out << fmt::format("flew {:.1f} s ({} rows at 50 Hz){}; log: {}\n", summary["seconds"].get<double>(),
                         f.log.rows(), f.crash != CrashReason::kNone ? ", CRASHED: " + crash_reason_name(f.crash) : "",
                         (dir.final_path() / "log.csv").string());
  if (f.crash != CrashReason::kNone)
    throw std::runtime_error(fmt::format("the pilot crashed ({}) at {} s", crash_reason_name(f.crash), f.crash_time));
}

// ------------------------------------------------------------------ heli identify

void declare_identify(ConfigSchema& s) {
  s.add_string("train", "", "training flight log (CSV, see README)");
  s.add_string("test", "", "hold-out flight log (CSV)");
  s.add_double("rate_hz", 10, "identification rate, Hz (the log is downsampled)").range(1, 50);
  s.add_bool("local", true, "locally weighted regression (false: globally linear)");
  s.add_bool("extra_states", true, "use the flapping and yaw-gyro states of the published model");
  s.add_bool("intercept", true, "regress on a constant");
  s.add_bool("templates", true, "fix kinematic and gravity coefficients (thesis 5.2.2)");
  s.add_double("window_s", 16, "cross-validation leaves out this window around each held-out point, s").range(0, 1000);
  s.add_int("cv_points", 300, "held-out points per cross-validation evaluation").range(10, 100000);
  s.add_double_list("scale_grid", {0.5, 1, 2, 4, 8}, "bandwidths tried, in input standard deviations").min(1e-6).min_size(1);
  s.add_int("coordinate_passes", 1, "passes of per-input bandwidth refinement").range(0, 10);
  s.add_double("horizon_s", 10, "longest prediction horizon of the report, s").range(0.1, 100);
  s.add_double("start_spacing_s", 2, "spacing of the open-loop prediction starts on the test log, s").range(0.02, 1000);
  s.add_double("reset_s", 2, "the noise check's EKF is reset to the true state this often, s").range(0.1, 100);
  s.add_bool("variants", true, "also report the model-selection variants of Fig 5.2");
}

nlohmann::json mse_at(const HorizonMse& h) {
  nlohmann::json out;
  for (int sec : {1, 5, 10}) {
    std::size_t best = 0;
    for (std::size_t t = 0; t < h.seconds.size(); ++t)
      if (std::abs(h.seconds[t] - sec) < std::abs(h.seconds[best] - sec)) best = t;
    if (h.seconds.empty() || std::abs(h.seconds[best] - sec) > 1e-9 || h.count[best] == 0) continue;
    nlohmann::json vars;
    for (int v = 0; v < kReportVars; ++v)
      vars[kReportVarNames[static_cast<std::size_t>(v)]] = h.mse[best][static_cast<std::size_t>(v)];
    out[std::to_string(sec)] = vars;
  }
  return out;
}

void run_identify(RunContext& ctx) {
  const auto& c = ctx.config;
  if (c.get_string("train").empty()) throw InputError("--train: a training flight log is required");
  if (c.get_string("test").empty()) throw InputError("--test: a hold-out flight log is required");
  const FlightLog train = read_flight_log(c.get_string("train"));
  const FlightLog test = read_flight_log(c.get_string("test"));
  IdentifyOptions o;
  o.structure.rate_hz = c.get_double("rate_hz");
  o.structure.extra_states = c.get_bool("extra_states");
  o.structure.intercept = c.get_bool("intercept");
  o.structure.templates = c.get_bool("templates");
  o.local = c.get_bool("local");
  o.window_s = c.get_double("window_s");
  o.cv_points = static_cast<int>(c.get_int("cv_points"));
  o.scale_grid = c.get_double_list("scale_grid");
  o.coordinate_passes = static_cast<int>(c.get_int("coordinate_passes"));
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  ThreadPool& pool = ctx.pool();
  RunDirectory& dir = ctx.run_directory();

  IdentifyReport report;
  const IdentifiedModel model = identify(train, o, pool, &report);
  model.save(dir.path() / "model.json");
  CsvWriter cv({"setting", "cv_error"});
  for (const auto& [what, e] : report.cv_trace) cv.add_row({what, e});
  dir.write_csv("cross_validation.csv", cv);

  const double horizon = c.get_double("horizon_s"), spacing = c.get_double("start_spacing_s");
  struct Variant {
    std::string name;
    HorizonMse mse;
  };
  std::vector<Variant> variants;
  variants.push_back({o.local ? "locally weighted (chosen)" : "global linear (chosen)",
                      horizon_mse(model, test, horizon, spacing, pool)});
  // The global linear model of the same template, always.
  auto variant_model = [&](ModelStructure m, bool local) {
    Dataset d = build_dataset(train, m);
    auto inv = local ? model.inv_bandwidth() : std::array<double, kInputs>{};
    if (!m.extra_states) inv[kFlapLon] = inv[kFlapLat] = inv[kGyro] = 0;
    IdentifyOptions vo = o;
    vo.structure = m;
    BodyVec sigma2;
    cv_error(d, output_templates(m), inv, vo, pool, &sigma2);
    return IdentifiedModel(m, std::move(d), inv, sigma2);
  };
  const IdentifiedModel global = variant_model(o.structure, false);
  const HorizonMse global_mse = horizon_mse(global, test, horizon, spacing, pool);
  if (o.local) variants.push_back({"global linear", global_mse});
  if (c.get_bool("variants") && o.local) {
    ModelStructure m = o.structure;
    m.extra_states = !o.structure.extra_states;
    variants.push_back({o.structure.extra_states ? "without a1s, b1s, gyro" : "with a1s, b1s, gyro",
                        horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    m = o.structure;
    m.intercept = !o.structure.intercept;
    variants.push_back({o.structure.intercept ? "without intercept" : "with intercept",
                        horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    for (double hz : {5.0, 10.0, 25.0, 50.0}) {
      if (std::abs(hz - o.structure.rate_hz) < 1e-9) continue;
      m = o.structure;
      m.rate_hz = hz;
      variants.push_back({fmt::format("identified at {} Hz", hz), horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    }
  }
  CsvWriter mse_csv({"model", "seconds", "variable", "mse", "rollouts"});
  for (const auto& v : variants)
    for (std::size_t t = 0; t < v.mse.seconds.size(); ++t)
      for (int k = 0; k < kReportVars; ++k)
        mse_csv.add_row({v.name, v.mse.seconds[t], std::string(kReportVarNames[static_cast<std::size_t>(k)]),
                         v.mse.mse[t][static_cast<std::size_t>(k)], std::int64_t{v.mse.count[t]}});
  dir.write_csv("mse_vs_horizon.csv", mse_csv);
  for (const char* var : {"xdot_b", "pitch_rate", "ydot_b", "z"}) {
    int k = 0;
    while (std::string(kReportVarNames[static_cast<std::size_t>(k)]) != var) ++k;
    SvgPlot plot;
    plot.title(fmt::format("Hold-out MSE of {} vs prediction horizon (Fig 5.2)", var))
        .x_label("horizon, s")
        .y_label("mean squared error");
    for (const auto& v : variants) {
      PlotSeries s{.name = v.name, .markers = false};
      for (std::size_t t = 0; t < v.mse.seconds.size(); ++t) {
        s.x.push_back(v.mse.seconds[t]);
        s.y.push_back(v.mse.mse[t][static_cast<std::size_t>(k)]);
      }
      plot.add_series(std::move(s));
    }
    dir.write_text(fmt::format("mse_{}.svg", var), plot.render());
  }

  const NoiseCheck nc = noise_check(model, test, c.get_double("reset_s"), 10.0);
  CsvWriter nc_csv({"time", "ydot_b_true", "ydot_b_predicted", "sd"});
  for (std::size_t i = 0; i < nc.time.size(); ++i) nc_csv.add_row({nc.time[i], nc.truth[i], nc.mean[i], nc.sd[i]});
  dir.write_csv("noise_check.csv", nc_csv);
  {
    SvgPlot plot;
    plot.title("ydot_b on hold-out data with +-2 sd bands, EKF reset every 2 s (Fig 5.3)").x_label("time, s").y_label("m/s");
    plot.add_series({.name = "true", .x = nc.time, .y = nc.truth, .markers = false});
    std::vector<double> two_sd(nc.sd.size());
    for (std::size_t i = 0; i < nc.sd.size(); ++i) two_sd[i] = 2 * nc.sd[i];
    plot.add_series({.name = "predicted +- 2 sd", .x = nc.time, .y = nc.mean, .error = two_sd, .markers = false});
    dir.write_text("noise_check.svg", plot.render());
  }

  nlohmann::json bandwidth, sigma2, outside;
  for (int j = 0; j < kInputs; ++j) {
    if (j == kOne) continue;
    const double ih = model.inv_bandwidth()[static_cast<std::size_t>(j)];
    bandwidth[kInputNames[static_cast<std::size_t>(j)]] = ih > 0 ? nlohmann::json(1 / ih) : nlohmann::json("inf");
  }
  for (int k = 0; k < kBodyVars; ++k) {
    sigma2[kBodyVarNames[static_cast<std::size_t>(k)]] = model.sigma2()[k];
    outside[kBodyVarNames[static_cast<std::size_t>(k)]] = nc.outside_fraction[k];
  }
  nlohmann::json variant_json = nlohmann::json::array();
  for (const auto& v : variants) variant_json.push_back({{"model", v.name}, {"mse_at_seconds", mse_at(v.mse)}});
  const nlohmann::json summary = {{"train_seconds", train.seconds()},
                                  {"test_seconds", test.seconds()},
                                  {"rate_hz", o.structure.rate_hz},
                                  {"structure", o.structure.describe()},
                                  {"local", o.local},
                                  {"training_rows", model.data().rows()},
                                  {"bandwidth", bandwidth},
                                  {"sigma2", sigma2},
                                  {"mse_at_seconds", mse_at(variants.front().mse)},
                                  {"global_linear", {{"mse_at_seconds", mse_at(global_mse)}}},
                                  {"variants", variant_json},
                                  {"outside_2sigma_fraction", outside},
                                  {"noise_check_steps", nc.steps},
                                  {"cv_seconds", report.cv_seconds},
                                  {"model", "model.json"}};
  dir.write_json("summary.json", summary);
  const auto& m1 = summary["mse_at_seconds"];
  const auto& g1 = summary["global_linear"]["mse_at_seconds"];
  ctx.out << fmt::format("identified on {:.0f} s ({} rows at {} Hz), cross-validation {:.1f} s\n", train.seconds(),
                         model.data().rows(), o.structure.rate_hz, report.cv_seconds);
  if (m1.contains("1") && g1.contains("1"))
    ctx.out << fmt::format("hold-out MSE at 1 s, xdot_b: {:.4g} (chosen) vs {:.4g} (global linear)\n",
                           m1["1"]["xdot_b"].get<double>(), g1["1"]["xdot_b"].get<double>());
  ctx.out << "model: " << (dir.final_path() / "model.json").string() << "\n";
}

}  // namespace

std::vector<Command> heli_commands() {
  return {
      Command{.path = "heli pilot",
              .description = "Fly the ground-truth helicopter with the scripted pilot (hover, then sweeps) and log it at 50 Hz",
              .declare = declare_pilot,
              .run = run_pilot},
      Command{.path = "heli identify",
              .description = "Identify a helicopter model by locally weighted regression from flight logs (thesis 5.2)",
              .declare = declare_identify,
              .run = run_identify},
  };
}

}  // namespace pegasus::cli
