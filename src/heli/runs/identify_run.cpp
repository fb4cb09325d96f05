#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "identify_noise_check.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/sysid/model_selection.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::heli {

using namespace pegasus::sysid;

namespace {

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

// The logs identify reads, all before the identification: a bad file stops the run at once.
struct IdentifyLogs {
  FlightLog train, test;
  std::vector<FlightLog> more_tests;  // --noise-check-logs
};

IdentifyLogs read_logs(const IdentifyRunOptions& options) {
  const bool own_layout = !options.aircraft.from_file();
  const logs::Vehicle& vehicle = options.aircraft.vehicle;
  const auto read_log = [&](const std::string& file) {
    return own_layout ? read_flight_log(file) : logs::read_vehicle_log(file, vehicle);
  };
  IdentifyLogs logs{
      .train = read_log(options.train_log), .test = read_log(options.test_log), .more_tests = {}};
  for (const std::string& file : options.noise_check_logs) logs.more_tests.push_back(read_log(file));
  // A flight given twice would count its steps twice in the pooled check, as if it were two.
  for (std::size_t i = 0; i < logs.more_tests.size(); ++i) {
    auto refuse = [&](const std::string& other, const std::string& option) {
      throw InputError(fmt::format(
          "--noise-check-logs: {} is the same flight as {} ({}); each hold-out flight counts once",
          options.noise_check_logs[i], other, option));
    };
    if (logs.more_tests[i] == logs.test) refuse(options.test_log, "--test");
    if (logs.more_tests[i] == logs.train) refuse(options.train_log, "--train");
    for (std::size_t j = 0; j < i; ++j)
      if (logs.more_tests[i] == logs.more_tests[j]) refuse(options.noise_check_logs[j], "--noise-check-logs");
  }
  return logs;
}

// The identification options valid, and the training log long enough for them.
void check_identify_options(const IdentifyRunOptions& options, const FlightLog& train,
                            const IdentifyOptions& o) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  if (const std::size_t need = sysid::min_training_log_rows(train.dt(), o.structure);
      train.rows() >= 2 && need > 1 && train.rows() < need)
    throw InputError(
        fmt::format("--train: {} has {} rows ({:.1f} s); identification at {} Hz needs at least "
                    "{} rows ({:.1f} s)",
                    options.train_log, train.rows(), train.seconds(), o.structure.rate_hz, need,
                    static_cast<double>(need) * train.dt()));
}

// Where stderr is no terminal, a line on the clock says which part of the identification runs; a bar
// counts the bandwidth cross-validation's steps.
struct IdentifyProgress {
  ProgressStatus phase{"the bandwidth cross-validation"};
  bool enabled;
  ProgressTicker ticker;
  std::unique_ptr<Progress> bar;

  explicit IdentifyProgress(const RunSink& sink)
      : enabled(Progress::default_enabled(sink.quiet, sink.dir.ranks())),
        ticker(
            "identify", [this] { return phase.text(); }, enabled) {}

  void step(int done, int total, bool replayed) {
    phase.set(fmt::format("the bandwidth cross-validation, {} of {} steps", done, total));
    if (!bar) bar = std::make_unique<Progress>("bandwidth cross-validation", total, enabled);
    const auto k = static_cast<std::uint64_t>(done) - bar->done();
    replayed ? bar->skip(k) : bar->advance(k);
  }
};

// The bandwidth search checkpoints after each cross-validation step; --resume replays the saved steps.
IdentifyHooks identify_hooks(RunDirectory& dir, IdentifyProgress& progress) {
  IdentifyHooks hooks;
  if (const auto saved = dir.load_checkpoint(); saved && saved->contains("identify"))
    hooks.resume_from = saved->at("identify");
  hooks.checkpoint = [&dir](const nlohmann::json& state) { dir.save_checkpoint({{"identify", state}}); };
  hooks.progress = [&progress](int done, int total, bool replayed) { progress.step(done, total, replayed); };
  return hooks;
}

void write_cross_validation(RunDirectory& dir, const IdentifyReport& report) {
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
}

// The model selection study's prediction errors by horizon: the csv, its charts, and the svgs of four.
void write_mse_vs_horizon(RunDirectory& dir, const ModelSelectionStudy& study) {
  CsvWriter mse_csv({"model", "seconds", "variable", "mse", "rollouts"});
  std::vector<NamedHorizonMse> drawn_models = study.variants;
  drawn_models.push_back(study.as_trained);
  for (const auto& v : drawn_models)
    for (std::size_t t = 0; t < v.mse.seconds.size(); ++t)
      for (int k = 0; k < kReportVars; ++k)
        mse_csv.add_row({v.name, v.mse.seconds[t], std::string(kReportVarNames[static_cast<std::size_t>(k)]),
                         v.mse.mse[t][static_cast<std::size_t>(k)], std::int64_t{v.mse.count[t]}});
  dir.write_csv("mse_vs_horizon.csv", mse_csv);
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

// mse_at_seconds reports whole model steps: at 12.5 Hz there is no 1 s or 5 s.
std::vector<int> horizons_skipped(double rate_hz) {
  std::vector<int> skipped;
  for (const int seconds : sysid::kMseReportSeconds) {
    const double steps = seconds * rate_hz;
    if (std::abs(steps - std::round(steps)) > 1e-9) skipped.push_back(seconds);
  }
  return skipped;
}

// summary.json's figures every identification gives.
nlohmann::json core_summary(const IdentifyLogs& logs, const IdentifyRunOptions& options,
                            const IdentifyOptions& o, const IdentifiedModel& model,
                            const ModelSelectionStudy& study, const HoldOutNoiseCheck& noise,
                            const IdentifyReport& report) {
  nlohmann::json bandwidth, sigma2, outside;
  for (int j = 0; j < kInputs; ++j) {
    if (j == kOne) continue;
    const double ih = model.inv_bandwidth()[static_cast<std::size_t>(j)];
    bandwidth[kInputNames[static_cast<std::size_t>(j)]] =
        ih > 0 ? nlohmann::json(1 / ih) : nlohmann::json("inf");
  }
  for (int k = 0; k < kBodyVars; ++k) {
    sigma2[kBodyVarNames[static_cast<std::size_t>(k)]] = model.sigma2()[k];
    outside[kBodyVarNames[static_cast<std::size_t>(k)]] = noise.pooled.outside_fraction[k];
  }
  // The bands' misses at 0.5, 1 and 2 s after a reset: an honest noise model misses about 5% at every
  // horizon.
  const nlohmann::json outside_by_horizon = outside_by_horizon_json(noise.reported);
  nlohmann::json variant_json = nlohmann::json::array();
  for (const auto& v : study.variants)
    variant_json.push_back({{"model", v.name}, {"mse_at_seconds", mse_at_seconds_json(v.mse)}});
  return {{"train_seconds", logs.train.seconds()},
          {"test_seconds", logs.test.seconds()},
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
          {"noise_check_steps", noise.pooled.steps},
          {"noise_check_cells_beyond_chance", cells_beyond_chance(noise.reported).size()},
          {"noise_check_passes", cells_beyond_chance(noise.reported).empty()},
          {"cross_validation_steps", report.cv_trace.size()},
          {"model", "model.json"}};
}

// The calibration's figures: noise_inflation, noise_scale and horizon_sd_factors.
void add_calibration(nlohmann::json& summary, const IdentifyReport& report, const IdentifiedModel& model) {
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

// The control gains' closed-loop bias, measured against a fit that whitens the residuals' correlation
// (the model's AR(1) noise, or, for a white-noise model, the same fit made for this check alone): the
// warning comes whatever noise model was asked for.
nlohmann::json closed_loop_bias_json(const std::vector<ControlGainBias>& biases) {
  nlohmann::json bias = nlohmann::json::object();
  for (const auto& b : biases)
    bias[b.output + "/" + b.control] = {
        {"least_squares", b.least_squares}, {"whitened", b.whitened}, {"relative", b.relative}};
  return bias;
}

// The warning names the largest bias among the physically large gains (an output's own controls), not a
// coupling near 0 whose relative bias is large only because the gain is small (issue 53).
void warn_of_gain_bias(std::ostream& out, const std::vector<ControlGainBias>& biases, bool whitened,
                       const IdentifyRunOptions& options) {
  const ControlGainBias* worst = largest_large_gain_bias(biases);
  if (worst && std::abs(worst->relative) > 0.2)
    out << fmt::format(
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

nlohmann::json noise_correlation_json(const NoiseCorrelation& c) {
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
  return correlation;
}

// The lines the terminal gets after summary.json: the choices, what was skipped, and the figures.
void print_identify_lines(std::ostream& out, const nlohmann::json& summary, const Choices& choices,
                          const IdentifyReport& report, const ModelSelectionStudy& study,
                          const IdentifyLogs& logs, const IdentifyOptions& o, const IdentifiedModel& model) {
  for (const std::string& line : choices.lines) out << line;
  if (!report.floored_inputs.empty())
    out << fmt::format(
        "bandwidth held at its floor (the logs move these inputs too little for a narrower one): {}\n",
        fmt::join(report.floored_inputs, ", "));
  if (!study.skipped_rates_hz.empty())
    out << fmt::format(
        "variants not identified at {} Hz: the logs' rates ({:.4g} and {:.4g} Hz) are not "
        "multiples\n",
        fmt::join(study.skipped_rates_hz, ", "), 1 / logs.train.dt(), 1 / logs.test.dt());
  if (const std::vector<int> skipped = horizons_skipped(o.structure.rate_hz); !skipped.empty())
    out << fmt::format(
        "no hold-out MSE at {} s: a {} Hz model's steps do not end there (mse_seconds_skipped)\n",
        fmt::join(skipped, ", "), o.structure.rate_hz);
  const auto& m1 = summary["mse_at_seconds"];
  const auto& g1 = summary["global_linear"]["mse_at_seconds"];
  out << fmt::format("identified on {:.0f} s ({} rows at {} Hz), cross-validation {:.1f} s\n",
                     logs.train.seconds(), model.data().rows(), o.structure.rate_hz, report.cv_seconds);
  if (m1.contains("1") && g1.contains("1"))
    out << fmt::format("hold-out MSE at 1 s, xdot_b: {:.4g} (chosen) vs {:.4g} (global linear)\n",
                       m1["1"]["xdot_b"].get<double>(), g1["1"]["xdot_b"].get<double>());
}

}  // namespace

bool IdentifyRunOptions::IsValid(std::string* error) const {
  if (const std::string out = numbers_out_of_bounds(*this); !out.empty()) {
    if (error) *error = "identify: " + out;
    return false;
  }
  return identify.IsValid(error);
}

void run_identify(const IdentifyRunOptions& options, RunSink& sink, ThreadPool& pool) {
  if (options.train_log.empty()) throw InputError("--train: a training flight log is required");
  if (options.test_log.empty()) throw InputError("--test: a hold-out flight log is required");
  if (std::string error; !options.IsValid(&error)) throw InputError(error);
  const bool own_layout = !options.aircraft.from_file();
  const IdentifyLogs logs = read_logs(options);
  Choices choices;
  IdentifyOptions o = noise_from_data(options, logs.train, choices);  // with the classes chosen from the data
  check_identify_options(options, logs.train, o);
  RunDirectory& dir = sink.dir;
  options.aircraft.keep(dir);

  IdentifyReport report;
  IdentifyProgress progress(sink);
  const IdentifyHooks hooks = identify_hooks(dir, progress);
  std::optional<ModelClassChoice> class_choice;
  IdentifiedModel model = model_from_data(options, logs.train, logs.test, pool, report, hooks, o, choices,
                                          class_choice, progress.phase);
  if (!own_layout) model.set_vehicle(options.aircraft.vehicle.name());
  if (progress.bar) progress.bar->finish();
  progress.phase.set("the control gains' closed-loop bias");
  // The control gains' closed-loop bias, measured on the least-squares model.
  const std::vector<ControlGainBias> biases = model_closed_loop_bias(model, o.window_s, pool);
  const bool whitened = gains_from_data(options, biases, logs.test, pool, model, choices);
  model.save(dir.path() / "model.json");
  write_cross_validation(dir, report);

  progress.phase.set("prediction errors by horizon (the model selection study)");
  const ModelSelectionStudy study = model_selection_study(model, logs.train, logs.test, o,
                                                          {.horizon_s = options.horizon_s,
                                                           .start_spacing_s = options.start_spacing_s,
                                                           .variants = options.variants,
                                                           .control_rate_hz = options.control_rate_hz},
                                                          pool);
  write_mse_vs_horizon(dir, study);
  progress.phase.set("the noise check");
  const HoldOutNoiseCheck noise = hold_out_noise_check(model, logs.test, logs.more_tests, options, o, pool);
  write_noise_check(dir, noise, model, o.structure.rate_hz);

  nlohmann::json summary = core_summary(logs, options, o, model, study, noise, report);
  // Only when some were skipped, so that the summaries of 50 Hz logs stay as they were (digests).
  if (!study.skipped_rates_hz.empty()) summary["variant_rates_skipped_hz"] = study.skipped_rates_hz;
  // Only at a rate whose steps miss some of the horizons (digests).
  if (const std::vector<int> skipped = horizons_skipped(o.structure.rate_hz); !skipped.empty())
    summary["mse_seconds_skipped"] = skipped;
  if (!own_layout) summary["vehicle"] = options.aircraft.vehicle.name();  // likewise
  if (noise.checks.size() > 1)                                            // likewise
    summary["noise_check_by_log"] = noise_check_by_log_json(noise, options, model, o.structure.rate_hz, sink);
  if (!report.floored_inputs.empty()) summary["bandwidth_at_floor"] = report.floored_inputs;
  if (o.calibrate_noise) add_calibration(summary, report, model);
  summary["closed_loop_bias"] = closed_loop_bias_json(biases);
  warn_of_gain_bias(sink.out, biases, whitened, options);
  if (const NoiseCorrelation& c = model.noise_correlation(); c.any())
    summary["noise_correlation"] = noise_correlation_json(c);
  if (class_choice) summary["model_choice"] = class_choice->to_json();
  summary["choices"] = choices.json;
  dir.write_json("summary.json", summary);
  print_identify_lines(sink.out, summary, choices, report, study, logs, o, model);
  sink.out << noise.verdict;
  sink.out << "model: " << sink.named(dir.final_path() / "model.json") << "\n";
}

}  // namespace pegasus::heli
