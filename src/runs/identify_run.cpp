#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "pegasus/runs/heli_runs.hpp"
#include "pegasus/sysid/model_selection.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::heli {

using namespace pegasus::sysid;

namespace {

// How many of the cells miss 3-7% no more than honest bands do.
std::size_t honest_cells(const std::vector<BandMisses>& cells) {
  return static_cast<std::size_t>(std::count_if(
      cells.begin(), cells.end(), [](const BandMisses& m) { return honest_misses(m.outside); }));
}

// The cells as summary.json gives them: {seconds: {variable: fraction outside}}.
nlohmann::json outside_by_horizon_json(const std::vector<BandMisses>& cells) {
  nlohmann::json out = nlohmann::json::object();
  for (const BandMisses& m : cells)
    out[format_double(m.seconds)][kBodyVarNames[static_cast<std::size_t>(m.variable)]] = m.outside;
  return out;
}

// One line on whether the bands are honest on the hold-out log (or `flights` of them, pooled): the summary's
// cells outside 3-7%, the widest misses first, then the count at every horizon (model steps at the nominal
// rate), and where some horizon misses and the options left a remedy unused, the options that narrow the
// misses.
std::string noise_check_line(const std::vector<BandMisses>& reported, const NoiseCheck& check, double rate_hz,
                             const IdentifyOptions& options, std::size_t flights) {
  std::vector<BandMisses> wide, narrow;
  for (const BandMisses& m : reported)
    if (!honest_misses(m.outside)) (m.outside < kHonestMissLow ? wide : narrow).push_back(m);
  auto list = [](std::vector<BandMisses> cells, bool most_first) {
    std::stable_sort(cells.begin(), cells.end(), [&](const BandMisses& a, const BandMisses& b) {
      return most_first ? a.outside > b.outside : a.outside < b.outside;
    });
    constexpr std::size_t kShown = 4;
    std::vector<std::string> parts;
    for (std::size_t i = 0; i < std::min(cells.size(), kShown); ++i)
      parts.push_back(fmt::format("{} at {} s {:.1f}%",
                                  kBodyVarNames[static_cast<std::size_t>(cells[i].variable)],
                                  format_double(cells[i].seconds), 100 * cells[i].outside));
    if (cells.size() > kShown) parts.push_back(fmt::format("{} more", cells.size() - kShown));
    return fmt::format("{}", fmt::join(parts, ", "));
  };
  const std::vector<BandMisses> every = band_misses_at_every_step(check, rate_hz);
  const std::size_t every_honest = honest_cells(every);
  std::string line = flights > 1 ? fmt::format("noise check on the {} hold-out logs, pooled: ", flights)
                                 : "noise check on the hold-out log: ";
  if (!reported.empty()) {
    // The answer first: whether any cell misses more or less than chance explains on its steps.
    const auto fewest = std::min_element(reported.begin(), reported.end(),
                                         [](const auto& a, const auto& b) { return a.steps < b.steps; });
    const std::size_t beyond = cells_beyond_chance(reported).size();
    line += fmt::format(
        "the bands {} ({} of the {} cells of outside_2sigma_by_horizon beyond what chance gives with {} "
        "steps "
        "a cell; binomial test, 5% over the cells; noise_check_passes); ",
        beyond == 0 ? "pass" : "fail", beyond == 0 ? std::string("none") : fmt::format("{}", beyond),
        reported.size(), fewest->steps);
    line += fmt::format("{} of the {} cells are outside 3-7%", wide.size() + narrow.size(), reported.size());
    if (!narrow.empty()) line += "; bands too narrow: " + list(narrow, true);
    if (!wide.empty()) line += "; too wide: " + list(wide, false);
    line += "; ";
  }
  line += fmt::format("at every horizon to {} s, {} of {} within 3-7% (noise_check_by_horizon.csv)",
                      format_double(static_cast<double>(check.steps_by_horizon.size()) / rate_hz),
                      every_honest, every.size());
  // White noise misses where gusts or an estimator correlate the errors in time, and an uncalibrated model's
  // parts keep the sizes fitted to one-step residuals: on both shipped aircraft ar1+measurement calibrated
  // left the fewest cells outside (README, Calibrated noise).
  const bool measured = options.noise == NoiseModel::kAr1Measurement;
  if (every_honest < every.size() && !(measured && options.calibrate_noise)) {
    line += "; for more honest bands: ";
    line += !measured && !options.calibrate_noise ? "--noise ar1+measurement --calibrate-noise"
            : !measured                           ? "--noise ar1+measurement"
                                                  : "--calibrate-noise";
    line += " (README, Calibrated noise)";
  }
  return line + "\n";
}

// What identify chose from the data, or the options set: summary.json's `choices`, and the lines that say so.
struct Choices {
  nlohmann::json json = nlohmann::json::object();
  std::vector<std::string> lines;
};

// The identification options with the noise model from the data (IdentifyRunOptions::choose_noise).
IdentifyOptions noise_from_data(const IdentifyRunOptions& options, const FlightLog& train, Choices& choices) {
  IdentifyOptions o = options.identify;
  if (!options.choose_noise) {
    choices.json["noise"] = {{"model", to_string(o.noise) + (o.calibrate_noise ? ", calibrated" : "")},
                             {"by", "option"}};
    return o;
  }
  const bool honest = train.seconds() >= IdentifyRunOptions::kHonestNoiseMinSeconds;
  o.noise = honest ? NoiseModel::kAr1Measurement : NoiseModel::kWhite;
  o.calibrate_noise = honest;
  choices.json["noise"] = {{"model", honest ? "ar1+measurement, calibrated" : "white"},
                           {"by", honest ? "default" : "training log too short"}};
  if (!honest)
    choices.lines.push_back(
        fmt::format("noise: white, as the training log's {:.0f} s are fewer than the {:.0f} s the calibrated "
                    "ar1+measurement noise needs (--noise and --calibrate-noise set it)\n",
                    train.seconds(), IdentifyRunOptions::kHonestNoiseMinSeconds));
  return o;
}

// The model of the class the options set, or (IdentifyRunOptions::choose_class) both classes' regressions,
// the one that predicts the test log better as training runs it, and then its noise; `o.local` the class.
IdentifiedModel model_from_data(const IdentifyRunOptions& options, const FlightLog& train,
                                const FlightLog& test, ThreadPool& pool, IdentifyReport& report,
                                const IdentifyHooks& hooks, IdentifyOptions& o, Choices& choices,
                                std::optional<ModelClassChoice>& class_choice, ProgressStatus& phase) {
  if (!options.choose_class) {
    choices.json["model_class"] = {{"class", o.local ? "locally weighted" : "global linear"},
                                   {"by", "option"}};
    return identify(train, o, pool, &report, hooks);
  }
  IdentifyOptions as_local = o, as_global = o;
  as_local.local = true;
  as_global.local = false;
  const IdentifiedModel local = identify_mean(train, as_local, pool, &report, hooks);
  phase.set("the global linear fit");
  const IdentifiedModel global = identify_mean(train, as_global, pool);
  phase.set("the model classes' hold-out prediction errors");
  class_choice = choose_model_class({{"global linear", &global}, {"locally weighted", &local}}, test,
                                    options.control_rate_hz, options.start_spacing_s, pool);
  o.local = class_choice->chosen == 1;
  if (!o.local) report.floored_inputs.clear();  // the global model has no bandwidths
  phase.set(
      fmt::format("the {} noise model{}", to_string(o.noise), o.calibrate_noise ? " (calibration)" : ""));
  IdentifiedModel chosen = with_noise_model(o.local ? local : global, train, o, pool, &report);
  chosen.set_model_choice(class_choice->to_json(), (o.local ? global : local).inv_bandwidth());
  choices.lines.push_back(class_choice->line());
  choices.json["model_class"] = {{"class", class_choice->candidates[class_choice->chosen].name},
                                 {"by", "hold-out prediction"}};
  return chosen;
}

// Whether the model takes the whitened control gains: when asked (whitened_gains), or by default
// (choose_gains) when they predict the test log better as training runs the model. `model` gets them.
bool gains_from_data(const IdentifyRunOptions& options, const std::vector<ControlGainBias>& biases,
                     const FlightLog& test, ThreadPool& pool, IdentifiedModel& model, Choices& choices) {
  bool whitened = false;
  nlohmann::json gain_choice = {{"by", options.choose_gains ? "hold-out prediction" : "option"}};
  if (!biases.empty() && (options.choose_gains || options.whitened_gains)) {
    IdentifiedModel corrected = with_whitened_gains(model, biases);
    whitened = options.whitened_gains;
    if (options.choose_gains) {
      const auto score = [&](const IdentifiedModel& m, const char* name) {
        return model_class_candidate(
            name,
            horizon_mse_as_trained(m, test, options.control_rate_hz, kModelChoiceSeconds.back(),
                                   options.start_spacing_s, pool),
            test);
      };
      const ModelClassCandidate plain = score(model, "least squares"), fixed = score(corrected, "whitened");
      whitened = fixed.score < plain.score && fixed.reached >= plain.reached;
      gain_choice["score_least_squares"] = plain.score;
      gain_choice["score_whitened"] = fixed.score;
    }
    if (whitened) model = std::move(corrected);
  }
  gain_choice["gains"] = whitened ? "whitened" : "least squares";
  choices.json["control_gains"] = gain_choice;
  return whitened;
}

}  // namespace

void run_identify(const IdentifyRunOptions& options, RunSink& sink, ThreadPool& pool) {
  if (options.train_log.empty()) throw InputError("--train: a training flight log is required");
  if (options.test_log.empty()) throw InputError("--test: a hold-out flight log is required");
  const bool own_layout = !options.aircraft.from_file();
  const logs::Vehicle& vehicle = options.aircraft.vehicle;
  const FlightLog train =
      own_layout ? read_flight_log(options.train_log) : logs::read_vehicle_log(options.train_log, vehicle);
  const auto read_log = [&](const std::string& file) {
    return own_layout ? read_flight_log(file) : logs::read_vehicle_log(file, vehicle);
  };
  const FlightLog test = read_log(options.test_log);
  std::vector<FlightLog> more_tests;  // read before the identification: a bad file stops the run at once
  for (const std::string& file : options.noise_check_logs) more_tests.push_back(read_log(file));
  // A flight given twice would count its steps twice in the pooled check, as if it were two.
  for (std::size_t i = 0; i < more_tests.size(); ++i) {
    auto refuse = [&](const std::string& other, const std::string& option) {
      throw InputError(fmt::format(
          "--noise-check-logs: {} is the same flight as {} ({}); each hold-out flight counts once",
          options.noise_check_logs[i], other, option));
    };
    if (more_tests[i] == test) refuse(options.test_log, "--test");
    if (more_tests[i] == train) refuse(options.train_log, "--train");
    for (std::size_t j = 0; j < i; ++j)
      if (more_tests[i] == more_tests[j]) refuse(options.noise_check_logs[j], "--noise-check-logs");
  }
  Choices choices;
  IdentifyOptions o = noise_from_data(options, train, choices);  // with the classes chosen from the data
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  if (const std::size_t need = sysid::min_training_log_rows(train.dt(), o.structure);
      train.rows() >= 2 && need > 1 && train.rows() < need)
    throw InputError(
        fmt::format("--train: {} has {} rows ({:.1f} s); identification at {} Hz needs at least "
                    "{} rows ({:.1f} s)",
                    options.train_log, train.rows(), train.seconds(), o.structure.rate_hz, need,
                    static_cast<double>(need) * train.dt()));
  RunDirectory& dir = sink.dir;
  options.aircraft.keep(dir);

  IdentifyReport report;
  // The bandwidth search checkpoints after each cross-validation step; --resume replays the saved steps.
  IdentifyHooks hooks;
  if (const auto saved = dir.load_checkpoint(); saved && saved->contains("identify"))
    hooks.resume_from = saved->at("identify");
  hooks.checkpoint = [&dir](const nlohmann::json& state) { dir.save_checkpoint({{"identify", state}}); };
  // Where stderr is no terminal, a line on the clock says which part of the identification runs.
  ProgressStatus phase("the bandwidth cross-validation");
  const ProgressTicker ticker(
      "identify", [&] { return phase.text(); }, Progress::default_enabled(sink.quiet, sink.dir.ranks()));
  std::unique_ptr<Progress> bar;
  hooks.progress = [&](int done, int total, bool replayed) {
    phase.set(fmt::format("the bandwidth cross-validation, {} of {} steps", done, total));
    if (!bar)
      bar = std::make_unique<Progress>("bandwidth cross-validation", total,
                                       Progress::default_enabled(sink.quiet, sink.dir.ranks()));
    const auto k = static_cast<std::uint64_t>(done) - bar->done();
    replayed ? bar->skip(k) : bar->advance(k);
  };
  std::optional<ModelClassChoice> class_choice;
  IdentifiedModel model =
      model_from_data(options, train, test, pool, report, hooks, o, choices, class_choice, phase);
  if (!own_layout) model.set_vehicle(vehicle.name());
  if (bar) bar->finish();
  phase.set("the control gains' closed-loop bias");
  // The control gains' closed-loop bias, measured on the least-squares model.
  const std::vector<ControlGainBias> biases = model_closed_loop_bias(model, o.window_s, pool);
  const bool whitened = gains_from_data(options, biases, test, pool, model, choices);
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

  phase.set("prediction errors by horizon (the model selection study)");
  const ModelSelectionStudy study = model_selection_study(model, train, test, o,
                                                          {.horizon_s = options.horizon_s,
                                                           .start_spacing_s = options.start_spacing_s,
                                                           .variants = options.variants,
                                                           .control_rate_hz = options.control_rate_hz},
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

  // The summary's cells are 0.5, 1 and 2 s after a reset.
  const std::vector<double> reported_seconds = {0.5, 1.0, 2.0};
  phase.set("the noise check");
  std::vector<NoiseCheck> checks = {noise_check(model, test, options.reset_s, 10.0, pool)};
  for (const FlightLog& log : more_tests)
    checks.push_back(noise_check(model, log, options.reset_s, 0.0, pool));
  const NoiseCheck nc = pooled_noise_check(checks);  // one flight's: its own check
  // The verdict the terminal and the report give.
  const std::vector<BandMisses> reported_misses = band_misses(nc, model.dt(), reported_seconds);
  const std::string noise_verdict =
      noise_check_line(reported_misses, nc, o.structure.rate_hz, o, checks.size());
  CsvWriter nc_csv({"time", "ydot_b_true", "ydot_b_predicted", "sd"});
  for (std::size_t i = 0; i < nc.time.size(); ++i)
    nc_csv.add_row({nc.time[i], nc.truth[i], nc.mean[i], nc.sd[i]});
  dir.write_csv("noise_check.csv", nc_csv);
  // The misses at every horizon: honest bands miss 3-7% at each, not only at the summary's three.
  CsvWriter by_horizon_csv({"seconds", "variable", "outside_2sigma", "steps"});
  for (const BandMisses& m : band_misses_at_every_step(nc, o.structure.rate_hz))
    by_horizon_csv.add_row({m.seconds, std::string(kBodyVarNames[static_cast<std::size_t>(m.variable)]),
                            m.outside, std::int64_t{m.steps}});
  dir.write_csv("noise_check_by_horizon.csv", by_horizon_csv);
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
    const Chart misses{.title = "Hold-out steps outside +-2 sd by the time since the reset",
                       .x = {"time since the reset (s)"},
                       .y = {"fraction outside +-2 sd"},
                       .traces = {{.file = "noise_check_by_horizon.csv",
                                   .x = "seconds",
                                   .y = "outside_2sigma",
                                   .group_by = {"variable"},
                                   .mode = "lines+markers"}},
                       .references = {{.y = kHonestMissLow, .name = "3%", .dash = "dash"},
                                      {.y = kHonestMissHigh, .name = "7%", .dash = "dash"}}};
    dir.add_charts(ChartSection{
        .id = "noise-check",
        .title = "Prediction with 2-sigma bands (Fig 5.3)",
        .intro =
            "The model's prediction from the true state, reset to the truth every few seconds; the band is 2 "
            "standard deviations of the predicted state (noise_check.csv). Below, each body variable's "
            "share of the hold-out steps outside its band at each time since a reset "
            "(noise_check_by_horizon.csv): honest bands miss about 4.55%, 3-7% on a flight of some "
            "minutes. " +
            (checks.size() > 1
                 ? fmt::format("The steps of the {} hold-out logs are pooled (noise_check_by_log in "
                               "summary.json gives each alone); the band above is the test log's. ",
                               checks.size())
                 : std::string()) +
            (model.horizon_sd_factors().empty()
                 ? std::string()
                 : "The bands carry the calibration's factor on each sd at each step after a reset, measured "
                   "on the training log (horizon_sd_factors in summary.json). ") +
            "The " + noise_verdict.substr(0, noise_verdict.size() - 1) + ".",
        .charts = {chart, misses}});
    dir.write_chart_svg("noise_check.svg", chart);
    dir.write_chart_svg("noise_check_by_horizon.svg", misses);
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
  const nlohmann::json outside_by_horizon = outside_by_horizon_json(reported_misses);
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
                            {"control_rate_hz", options.control_rate_hz},
                            {"global_linear", {{"mse_at_seconds", mse_at_seconds_json(study.global_linear)}}},
                            {"variants", variant_json},
                            {"outside_2sigma_fraction", outside},
                            {"outside_2sigma_by_horizon", outside_by_horizon},
                            {"noise", to_string(o.noise)},
                            {"noise_check_steps", nc.steps},
                            {"noise_check_cells_beyond_chance", cells_beyond_chance(reported_misses).size()},
                            {"noise_check_passes", cells_beyond_chance(reported_misses).empty()},
                            {"cross_validation_steps", report.cv_trace.size()},
                            {"model", "model.json"}};
  // Only when some were skipped, so that the summaries of 50 Hz logs stay as they were (digests).
  if (!study.skipped_rates_hz.empty()) summary["variant_rates_skipped_hz"] = study.skipped_rates_hz;
  // mse_at_seconds reports whole model steps: at 12.5 Hz there is no 1 s or 5 s. Only then (digests).
  std::vector<int> horizons_skipped;
  for (const int seconds : sysid::kMseReportSeconds) {
    const double steps = seconds * o.structure.rate_hz;
    if (std::abs(steps - std::round(steps)) > 1e-9) horizons_skipped.push_back(seconds);
  }
  if (!horizons_skipped.empty()) summary["mse_seconds_skipped"] = horizons_skipped;
  if (!own_layout) summary["vehicle"] = vehicle.name();  // likewise
  if (checks.size() > 1) {  // likewise: each hold-out log's check alone, the test log's first
    nlohmann::json by_log = nlohmann::json::array();
    std::vector<std::string> files = {options.test_log};
    files.insert(files.end(), options.noise_check_logs.begin(), options.noise_check_logs.end());
    for (std::size_t i = 0; i < checks.size(); ++i) {
      const std::vector<BandMisses> cells = band_misses(checks[i], model.dt(), reported_seconds);
      const std::vector<BandMisses> every = band_misses_at_every_step(checks[i], o.structure.rate_hz);
      by_log.push_back({{"log", files[i]},
                        {"steps", checks[i].steps},
                        {"outside_2sigma_by_horizon", outside_by_horizon_json(cells)},
                        {"cells_within_3_7", honest_cells(cells)},
                        {"cells", cells.size()},
                        {"every_step_cells_within_3_7", honest_cells(every)},
                        {"every_step_cells", every.size()}});
    }
    summary["noise_check_by_log"] = by_log;
  }
  if (!report.floored_inputs.empty()) summary["bandwidth_at_floor"] = report.floored_inputs;
  if (o.calibrate_noise) {
    nlohmann::json inflation;
    for (int k = 0; k < kBodyVars; ++k)
      inflation[kBodyVarNames[static_cast<std::size_t>(k)]] = report.noise_inflation[k];
    summary["noise_inflation"] = inflation;
    // The variance scales by source (sysid::fit_noise_scale): the measurement ones only where the model has a
    // measurement error.
    nlohmann::json process, measurement, white;
    for (int k = 0; k < kBodyVars; ++k) {
      const char* name = kBodyVarNames[static_cast<std::size_t>(k)];
      process[name] = report.noise_scale.process[k];
      if (model.noise_correlation().has_measurement()) {
        measurement[name] = report.noise_scale.measurement[k];
        white[name] = report.noise_scale.measurement_white[k];
      }
    }
    summary["noise_scale"] = {{"process", process}};
    if (!measurement.is_null()) {
      summary["noise_scale"]["measurement"] = measurement;
      summary["noise_scale"]["measurement_white"] = white;  // added, in units of the one-step variance
    }
    // The factors on each output's sd by model step after a reset (sysid::fit_horizon_sd_factors).
    if (!model.horizon_sd_factors().empty()) {
      nlohmann::json factors;
      for (int k = 0; k < kBodyVars; ++k) {
        auto& series = factors[kBodyVarNames[static_cast<std::size_t>(k)]] = nlohmann::json::array();
        for (const BodyVec& f : model.horizon_sd_factors()) series.push_back(f[k]);
      }
      summary["horizon_sd_factors"] = factors;
    }
  }
  {
    // The control gains' closed-loop bias, measured against a fit that whitens the residuals' correlation
    // (the model's AR(1) noise, or, for a white-noise model, the same fit made for this check alone): the
    // warning comes whatever noise model was asked for.
    // The warning names the largest bias among the physically large gains (an output's own controls), not a
    // coupling near 0 whose relative bias is large only because the gain is small (issue 53).
    nlohmann::json bias = nlohmann::json::object();
    for (const auto& b : biases)
      bias[b.output + "/" + b.control] = {
          {"least_squares", b.least_squares}, {"whitened", b.whitened}, {"relative", b.relative}};
    summary["closed_loop_bias"] = bias;
    const ControlGainBias* worst = largest_large_gain_bias(biases);
    if (worst && std::abs(worst->relative) > 0.2)
      sink.out << fmt::format(
          "warning: the control gains look biased by closed-loop data: {} per {} is {:.0f}% {} in the "
          "least-squares fit than in one that whitens the correlated noise ({:.4g} against {:.4g}; the "
          "largest among the gains that move their output at least {:.0f}% as much as its strongest control "
          "does; closed_loop_bias in summary.json); {}\n",
          worst->output, worst->control, 100 * std::abs(worst->relative),
          worst->relative < 0 ? "smaller" : "larger", worst->least_squares, worst->whitened,
          100 * kLargeGainShare,
          whitened ? (options.choose_gains ? "the model uses the whitened gains, which predict the test log "
                                             "better (--whitened-gains=false keeps least squares)"
                                           : "the model uses the whitened gains (--whitened-gains)")
                   : (options.choose_gains ? "the model keeps least squares, which predicts the test log "
                                             "better; --whitened-gains uses the whitened ones"
                                           : "--whitened-gains uses the whitened ones"));
  }
  if (const NoiseCorrelation& c = model.noise_correlation(); c.any()) {
    nlohmann::json correlation;
    for (int k = 0; k < kBodyVars; ++k) {
      auto& entry = correlation[kBodyVarNames[static_cast<std::size_t>(k)]];
      entry = {{"share", c.share[k]}, {"rho", c.rho[k]}};
      if (c.has_measurement()) {
        entry["measurement_share"] = c.measurement_share[k];
        entry["measurement_rho"] = c.measurement_rho[k];
        entry["measurement_persistence"] = c.measurement_persistence[k];
        entry["measurement_white_share"] = c.measurement_white_share[k];
      }
    }
    summary["noise_correlation"] = correlation;
  }
  if (class_choice) summary["model_choice"] = class_choice->to_json();
  summary["choices"] = choices.json;
  dir.write_json("summary.json", summary);
  for (const std::string& line : choices.lines) sink.out << line;
  if (!report.floored_inputs.empty())
    sink.out << fmt::format(
        "bandwidth held at its floor (the logs move these inputs too little for a narrower one): {}\n",
        fmt::join(report.floored_inputs, ", "));
  if (!study.skipped_rates_hz.empty())
    sink.out << fmt::format(
        "variants not identified at {} Hz: the logs' rates ({:.4g} and {:.4g} Hz) are not "
        "multiples\n",
        fmt::join(study.skipped_rates_hz, ", "), 1 / train.dt(), 1 / test.dt());
  if (!horizons_skipped.empty())
    sink.out << fmt::format(
        "no hold-out MSE at {} s: a {} Hz model's steps do not end there (mse_seconds_skipped)\n",
        fmt::join(horizons_skipped, ", "), o.structure.rate_hz);
  const auto& m1 = summary["mse_at_seconds"];
  const auto& g1 = summary["global_linear"]["mse_at_seconds"];
  sink.out << fmt::format("identified on {:.0f} s ({} rows at {} Hz), cross-validation {:.1f} s\n",
                          train.seconds(), model.data().rows(), o.structure.rate_hz, report.cv_seconds);
  if (m1.contains("1") && g1.contains("1"))
    sink.out << fmt::format("hold-out MSE at 1 s, xdot_b: {:.4g} (chosen) vs {:.4g} (global linear)\n",
                            m1["1"]["xdot_b"].get<double>(), g1["1"]["xdot_b"].get<double>());
  sink.out << noise_verdict;
  sink.out << "model: " << (dir.final_path() / "model.json").string() << "\n";
}

}  // namespace pegasus::heli
