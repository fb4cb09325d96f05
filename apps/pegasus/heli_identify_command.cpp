// `pegasus heli identify` and `pegasus identify --vehicle`: system identification by locally weighted
// regression from flight logs (thesis §5.2), with the model-selection study of Fig 5.2, the noise check of
// Fig 5.3, the model as hover training will run it, and the closed-loop bias check; and the bandwidth floors
// every identifying command declares.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "pegasus/runs/progress.hpp"
#include "pegasus/sysid/flight_log.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/model_selection.hpp"

namespace pegasus::cli {

using namespace pegasus::heli;
using namespace pegasus::sysid;

void declare_bandwidth_floor(ConfigSchema& s) {
  const BandwidthFloor d;
  s.add_double("bandwidth_floor.angle_rad", d.angle_rad, "narrowest kernel bandwidth of roll and pitch, rad")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.velocity_mps", d.velocity_mps,
               "narrowest kernel bandwidth of the body velocities, m/s")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.rate_radps", d.rate_radps,
               "narrowest kernel bandwidth of the body rates (and the gyro state), rad/s")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.flap_rad", d.flap_rad,
               "narrowest kernel bandwidth of the flapping states, rad")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.control", d.control,
               "narrowest kernel bandwidth of each control, in its [-1, 1] units (a control the pilot barely "
               "moved is not given a bandwidth below this)")
      .range(0, 1e6);
}

BandwidthFloor read_bandwidth_floor(const ConfigSchema& c) {
  return {.angle_rad = c.get_double("bandwidth_floor.angle_rad"),
          .velocity_mps = c.get_double("bandwidth_floor.velocity_mps"),
          .rate_radps = c.get_double("bandwidth_floor.rate_radps"),
          .flap_rad = c.get_double("bandwidth_floor.flap_rad"),
          .control = c.get_double("bandwidth_floor.control")};
}

void declare_identify(ConfigSchema& s) {
  declare_vehicle(s);
  s.add_string("train", "", "training flight log (CSV in the vehicle's layout, see README)");
  s.add_string("test", "", "hold-out flight log (CSV)");
  s.add_double("rate_hz", 10, "identification rate, Hz (the log is downsampled)").range(1, 50);
  s.add_bool("local", true, "locally weighted regression (false: globally linear)");
  s.add_bool("extra_states", true, "use the flapping and yaw-gyro states of the published model");
  s.add_bool("intercept", true, "regress on a constant");
  s.add_bool("templates", true, "fix kinematic and gravity coefficients (thesis 5.2.2)");
  s.add_double("window_s", 16, "cross-validation leaves out this window around each held-out point, s")
      .range(0, 1000);
  s.add_int("cv_points", 300, "held-out points per cross-validation evaluation").range(10, 100000);
  s.add_double_list("scale_grid", {0.5, 1, 2, 4, 8}, "bandwidths tried, in input standard deviations")
      .min(1e-6)
      .min_size(1);
  s.add_int("coordinate_passes", 1, "passes of per-input bandwidth refinement").range(0, 10);
  declare_bandwidth_floor(s);
  s.add_string(
       "noise", "white",
       "the model's noise: white per model step (Eqs 5.5-5.6) or ar1 (each output's noise a white part "
       "plus a first-order autoregressive part fitted to the residuals' autocorrelation up to 2 s)")
      .choices({"white", "ar1"});
  s.add_bool(
      "calibrate_noise", IdentifyOptions{}.calibrate_noise,
      "widen each output's noise until the training log's own noise check has 4.55% of its steps outside "
      "+-2 sd (never narrow it)");
  s.add_double("horizon_s", 10, "longest prediction horizon of the report, s").range(0.1, 100);
  s.add_double("start_spacing_s", 2, "spacing of the open-loop prediction starts on the test log, s")
      .range(0.02, 1000);
  s.add_double("reset_s", 2, "the noise check's EKF is reset to the true state this often, s")
      .range(0.1, 100);
  s.add_bool("variants", true, "also report the model-selection variants of Fig 5.2");
  s.add_double("control_rate_hz", heli::HoverTrainingOptions{}.control_rate_hz,
               "the rate hover training will step the model at (heli hover --control-rate-hz): the chosen "
               "model's errors are also reported as training runs it")
      .greater_than(0)
      .max(1000);
}

void resolve_identify(ConfigSchema& s) {
  if (s.get_string("vehicle").empty()) return;
  const logs::Vehicle v = logs::read_vehicle(s.get_string("vehicle"));
  from_vehicle(s, v, "rate_hz", v.log.model_rate_hz, "log.model_rate_hz");
  from_vehicle(s, v, "extra_states", v.xcell_latent_states, "vehicle.latent_states");
  from_vehicle(s, v, "control_rate_hz", v.control_rate_hz, "control.rate_hz");
}

void run_identify(RunContext& ctx) {
  const auto& c = ctx.config;
  if (c.get_string("train").empty()) throw InputError("--train: a training flight log is required");
  if (c.get_string("test").empty()) throw InputError("--test: a hold-out flight log is required");
  const bool own_layout = c.get_string("vehicle").empty();
  const logs::Vehicle vehicle = vehicle_of(c);
  const FlightLog train = own_layout ? read_flight_log(c.get_string("train"))
                                     : logs::read_vehicle_log(c.get_string("train"), vehicle);
  const FlightLog test = own_layout ? read_flight_log(c.get_string("test"))
                                    : logs::read_vehicle_log(c.get_string("test"), vehicle);
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
  o.min_bandwidth = read_bandwidth_floor(c);
  o.noise = parse_noise_model(c.get_string("noise"));
  o.calibrate_noise = c.get_bool("calibrate_noise");
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  ThreadPool& pool = ctx.pool();
  RunDirectory& dir = ctx.run_directory();
  keep_vehicle_file(c, dir);

  IdentifyReport report;
  // The bandwidth search checkpoints after each cross-validation step; --resume replays the saved steps.
  IdentifyHooks hooks;
  if (const auto saved = dir.load_checkpoint(); saved && saved->contains("identify"))
    hooks.resume_from = saved->at("identify");
  hooks.checkpoint = [&dir](const nlohmann::json& state) { dir.save_checkpoint({{"identify", state}}); };
  std::unique_ptr<Progress> bar;
  hooks.progress = [&](int done, int total, bool replayed) {
    if (!bar)
      bar = std::make_unique<Progress>("bandwidth cross-validation", total,
                                       Progress::default_enabled(ctx.quiet));
    const auto k = static_cast<std::uint64_t>(done) - bar->done();
    replayed ? bar->skip(k) : bar->advance(k);
  };
  IdentifiedModel model = identify(train, o, pool, &report, hooks);
  if (!own_layout) model.set_vehicle(vehicle.name());
  if (bar) bar->finish();
  model.save(dir.path() / "model.json");
  CsvWriter cv({"setting", "cv_error"});
  for (const auto& [what, e] : report.cv_trace) cv.add_row({what, e});
  dir.write_csv("cross_validation.csv", cv);
  dir.add_charts(
      ChartSection{.id = "cross-validation",
                   .title = "Bandwidth cross-validation",
                   .intro = "(cross_validation.csv)",
                   .charts = {{.kind = ChartKind::kBar,
                               .title = "Cross-validation error by setting",
                               .x = {"setting"},
                               .y = {"cross-validation error", AxisScale::kLog10},
                               .traces = {{.file = "cross_validation.csv", .x = "setting", .y = "cv_error"}},
                               .categorical = true}}});

  const ModelSelectionStudy study =
      model_selection_study(model, train, test, o,
                            {.horizon_s = c.get_double("horizon_s"),
                             .start_spacing_s = c.get_double("start_spacing_s"),
                             .variants = c.get_bool("variants"),
                             .control_rate_hz = c.get_double("control_rate_hz")},
                            pool);
  CsvWriter mse_csv({"model", "seconds", "variable", "mse", "rollouts"});
  std::vector<NamedHorizonMse> drawn_models = study.variants;
  drawn_models.push_back(study.as_trained);
  for (const auto& v : drawn_models)
    for (std::size_t t = 0; t < v.mse.seconds.size(); ++t)
      for (int k = 0; k < kReportVars; ++k)
        mse_csv.add_row({v.name, v.mse.seconds[t], std::string(kReportVarNames[static_cast<std::size_t>(k)]),
                         v.mse.mse[t][static_cast<std::size_t>(k)], std::int64_t{v.mse.count[t]}});
  dir.write_csv("mse_vs_horizon.csv", mse_csv);
  {
    const std::vector<std::string> drawn = {"xdot_b", "pitch_rate", "ydot_b", "z"};
    std::vector<std::string> all(kReportVarNames.begin(), kReportVarNames.end());
    const ChartSection mse = mse_vs_horizon_section("mse_vs_horizon.csv", all);
    dir.add_charts(mse);
    for (const auto& chart : mse.charts) {
      const std::string& var = chart.traces.front().where.at("variable");
      if (std::find(drawn.begin(), drawn.end(), var) != drawn.end())
        dir.write_chart_svg(fmt::format("mse_{}.svg", var), chart);
    }
  }

  const NoiseCheck nc = noise_check(model, test, c.get_double("reset_s"), 10.0);
  CsvWriter nc_csv({"time", "ydot_b_true", "ydot_b_predicted", "sd"});
  for (std::size_t i = 0; i < nc.time.size(); ++i)
    nc_csv.add_row({nc.time[i], nc.truth[i], nc.mean[i], nc.sd[i]});
  dir.write_csv("noise_check.csv", nc_csv);
  {
    const Chart chart{.title = "ydot_b on hold-out data with +-2 sd bands, EKF reset every 2 s (Fig 5.3)",
                      .x = {"time (s)"},
                      .y = {"ydot_b (m/s)"},
                      .traces = {{.file = "noise_check.csv", .x = "time", .y = "ydot_b_true", .name = "true"},
                                 {.file = "noise_check.csv",
                                  .x = "time",
                                  .y = "ydot_b_predicted",
                                  .name = "predicted",
                                  .band = "sd",
                                  .band_factor = 2,
                                  .band_name = "+-2 standard deviations",
                                  .dash = "dashdot"}}};
    dir.add_charts(ChartSection{
        .id = "noise-check",
        .title = "Prediction with 2-sigma bands (Fig 5.3)",
        .intro =
            "The model's prediction from the true state, reset to the truth every few seconds; the band is 2 "
            "standard deviations of the predicted state (noise_check.csv).",
        .charts = {chart}});
    dir.write_chart_svg("noise_check.svg", chart);
  }

  nlohmann::json bandwidth, sigma2, outside;
  for (int j = 0; j < kInputs; ++j) {
    if (j == kOne) continue;
    const double ih = model.inv_bandwidth()[static_cast<std::size_t>(j)];
    bandwidth[kInputNames[static_cast<std::size_t>(j)]] =
        ih > 0 ? nlohmann::json(1 / ih) : nlohmann::json("inf");
  }
  for (int k = 0; k < kBodyVars; ++k) {
    sigma2[kBodyVarNames[static_cast<std::size_t>(k)]] = model.sigma2()[k];
    outside[kBodyVarNames[static_cast<std::size_t>(k)]] = nc.outside_fraction[k];
  }
  // The bands' misses at 0.5, 1 and 2 s after a reset: an honest noise model misses about 5% at every
  // horizon.
  nlohmann::json outside_by_horizon = nlohmann::json::object();
  for (double seconds : {0.5, 1.0, 2.0}) {
    const auto t = static_cast<std::size_t>(std::lround(seconds / model.dt())) - 1;
    if (t >= nc.steps_by_horizon.size() || nc.steps_by_horizon[t] == 0) continue;
    nlohmann::json at;
    for (int k = 0; k < kBodyVars; ++k)
      at[kBodyVarNames[static_cast<std::size_t>(k)]] = nc.outside_by_horizon[t][k];
    outside_by_horizon[format_double(seconds)] = at;
  }
  nlohmann::json variant_json = nlohmann::json::array();
  for (const auto& v : study.variants)
    variant_json.push_back({{"model", v.name}, {"mse_at_seconds", mse_at_seconds_json(v.mse)}});
  nlohmann::json summary = {{"train_seconds", train.seconds()},
                            {"test_seconds", test.seconds()},
                            {"rate_hz", o.structure.rate_hz},
                            {"structure", o.structure.describe()},
                            {"local", o.local},
                            {"training_rows", model.data().rows()},
                            {"bandwidth", bandwidth},
                            {"sigma2", sigma2},
                            {"mse_at_seconds", mse_at_seconds_json(study.variants.front().mse)},
                            {"mse_at_seconds_as_trained", mse_at_seconds_json(study.as_trained.mse)},
                            {"control_rate_hz", c.get_double("control_rate_hz")},
                            {"global_linear", {{"mse_at_seconds", mse_at_seconds_json(study.global_linear)}}},
                            {"variants", variant_json},
                            {"outside_2sigma_fraction", outside},
                            {"outside_2sigma_by_horizon", outside_by_horizon},
                            {"noise", to_string(o.noise)},
                            {"noise_check_steps", nc.steps},
                            {"cross_validation_steps", report.cv_trace.size()},
                            {"model", "model.json"}};
  // Only when some were skipped, so that the summaries of 50 Hz logs stay as they were (digests).
  if (!study.skipped_rates_hz.empty()) summary["variant_rates_skipped_hz"] = study.skipped_rates_hz;
  if (!own_layout) summary["vehicle"] = vehicle.name();  // likewise
  if (!report.floored_inputs.empty()) summary["bandwidth_at_floor"] = report.floored_inputs;
  if (o.calibrate_noise) {
    nlohmann::json inflation;
    for (int k = 0; k < kBodyVars; ++k)
      inflation[kBodyVarNames[static_cast<std::size_t>(k)]] = report.noise_inflation[k];
    summary["noise_inflation"] = inflation;
  }
  {
    // The control gains' closed-loop bias, measured against a fit that whitens the residuals' correlation
    // (the model's AR(1) noise, or, for a white-noise model, the same fit made for this check alone): the
    // warning comes whatever noise model was asked for.
    nlohmann::json bias = nlohmann::json::object();
    const ControlGainBias* worst = nullptr;
    const auto biases = model_closed_loop_bias(model, o.window_s, pool);
    for (const auto& b : biases) {
      bias[b.output + "/" + b.control] = {
          {"least_squares", b.least_squares}, {"whitened", b.whitened}, {"relative", b.relative}};
      if (!worst || std::abs(b.relative) > std::abs(worst->relative)) worst = &b;
    }
    summary["closed_loop_bias"] = bias;
    if (worst && std::abs(worst->relative) > 0.2)
      ctx.out << fmt::format(
          "warning: the control gains look biased by closed-loop data: {} per {} is {:.0f}% {} in the "
          "least-squares fit than in one that whitens the correlated noise ({:.4g} against {:.4g}; "
          "closed_loop_bias in summary.json)\n",
          worst->output, worst->control, 100 * std::abs(worst->relative),
          worst->relative < 0 ? "smaller" : "larger", worst->least_squares, worst->whitened);
  }
  if (model.noise_correlation().any()) {
    nlohmann::json correlation;
    for (int k = 0; k < kBodyVars; ++k)
      correlation[kBodyVarNames[static_cast<std::size_t>(k)]] = {
          {"share", model.noise_correlation().share[k]}, {"rho", model.noise_correlation().rho[k]}};
    summary["noise_correlation"] = correlation;
  }
  dir.write_json("summary.json", summary);
  if (!report.floored_inputs.empty())
    ctx.out << fmt::format(
        "bandwidth held at its floor (the logs move these inputs too little for a narrower one): {}\n",
        fmt::join(report.floored_inputs, ", "));
  if (!study.skipped_rates_hz.empty())
    ctx.out << fmt::format(
        "variants not identified at {} Hz: the logs' rates ({:.4g} and {:.4g} Hz) are not "
        "multiples\n",
        fmt::join(study.skipped_rates_hz, ", "), 1 / train.dt(), 1 / test.dt());
  const auto& m1 = summary["mse_at_seconds"];
  const auto& g1 = summary["global_linear"]["mse_at_seconds"];
  ctx.out << fmt::format("identified on {:.0f} s ({} rows at {} Hz), cross-validation {:.1f} s\n",
                         train.seconds(), model.data().rows(), o.structure.rate_hz, report.cv_seconds);
  if (m1.contains("1") && g1.contains("1"))
    ctx.out << fmt::format("hold-out MSE at 1 s, xdot_b: {:.4g} (chosen) vs {:.4g} (global linear)\n",
                           m1["1"]["xdot_b"].get<double>(), g1["1"]["xdot_b"].get<double>());
  ctx.out << "model: " << (dir.final_path() / "model.json").string() << "\n";
}

}  // namespace pegasus::cli
