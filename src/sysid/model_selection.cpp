#include "pegasus/sysid/model_selection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pegasus/io/json_csv.hpp"

namespace pegasus::sysid {

ModelSelectionStudy model_selection_study(const IdentifiedModel& model, const FlightLog& train,
                                          const FlightLog& test, const IdentifyOptions& options,
                                          const ModelSelectionOptions& study, ThreadPool& pool) {
  const double horizon = study.horizon_s, spacing = study.start_spacing_s;
  ModelSelectionStudy out;
  out.variants.push_back({options.local ? "locally weighted (chosen)" : "global linear (chosen)",
                          horizon_mse(model, test, horizon, spacing, pool)});
  // A variant: the chosen bandwidths (or none) on another structure, its noise from cross-validation.
  auto variant_model = [&](ModelStructure m, bool local) {
    Dataset d = build_dataset(train, m);
    // As identify does: an input the log never moves is left out, or it would make X'WX singular.
    m.constant_inputs = constant_inputs(d);
    auto inv = local ? model.inv_bandwidth() : std::array<double, kInputs>{};
    if (!m.extra_states) inv[kFlapLon] = inv[kFlapLat] = inv[kGyro] = 0;
    IdentifyOptions vo = options;
    vo.structure = m;
    BodyVec sigma2;
    cv_error(d, output_templates(m), inv, vo, pool, &sigma2);
    return IdentifiedModel(m, std::move(d), inv, sigma2);
  };
  out.global_linear = horizon_mse(variant_model(options.structure, false), test, horizon, spacing, pool);
  if (options.local) out.variants.push_back({"global linear", out.global_linear});
  if (study.variants && options.local) {
    ModelStructure m = options.structure;
    m.extra_states = !options.structure.extra_states;
    out.variants.push_back({options.structure.extra_states ? "without a1s, b1s, gyro" : "with a1s, b1s, gyro",
                            horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    m = options.structure;
    m.intercept = !options.structure.intercept;
    out.variants.push_back({options.structure.intercept ? "without intercept" : "with intercept",
                            horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    // Fig 5.2's rates, where both logs hold a whole number of rows per model step (a 10 Hz log has no 25 or
    // 50 Hz model).
    for (double hz : {5.0, 10.0, 25.0, 50.0}) {
      if (std::abs(hz - options.structure.rate_hz) < 1e-9) continue;
      if (log_rows_per_model_step(train.dt(), hz) == 0 || log_rows_per_model_step(test.dt(), hz) == 0) {
        out.skipped_rates_hz.push_back(hz);
        continue;
      }
      m = options.structure;
      m.rate_hz = hz;
      out.variants.push_back({fmt::format("identified at {} Hz", hz),
                              horizon_mse(variant_model(m, true), test, horizon, spacing, pool)});
    }
  }
  // The chosen model as hover training runs it: the learned model at the controller's rate, refitted at the
  // model's (the variants above step at their own identification rate).
  out.as_trained = {fmt::format("chosen, as training runs it ({} Hz)", study.control_rate_hz),
                    horizon_mse_as_trained(model, test, study.control_rate_hz, horizon, spacing, pool)};
  return out;
}

ModelClassCandidate model_class_candidate(const std::string& name, const HorizonMse& h,
                                          const FlightLog& test) {
  // Each report variable's variance on the hold-out log, about its first value (so that a variable the log
  // holds constant has exactly none, and is left out): the errors of every variable count alike.
  std::array<double, kReportVars> mean{}, var{};
  const ReportState first = test.rows() > 0 ? report_state(test.states.front()) : ReportState{};
  const auto n = static_cast<double>(test.rows());
  for (const auto& row : test.states) {
    const ReportState r = report_state(row);
    for (std::size_t v = 0; v < kReportVars; ++v) {
      mean[v] += (r[v] - first[v]) / n;
      var[v] += (r[v] - first[v]) * (r[v] - first[v]) / n;
    }
  }
  for (std::size_t v = 0; v < kReportVars; ++v) var[v] -= mean[v] * mean[v];
  ModelClassCandidate c;
  c.name = name;
  if (h.seconds.empty()) return c;
  c.starts = h.count.front();
  int cells = 0;
  for (std::size_t i = 0; i < kModelChoiceSeconds.size(); ++i) {
    std::size_t t = 0;  // the row nearest the horizon
    for (std::size_t r = 0; r < h.seconds.size(); ++r)
      if (std::abs(h.seconds[r] - kModelChoiceSeconds[i]) < std::abs(h.seconds[t] - kModelChoiceSeconds[i]))
        t = r;
    if (i + 1 == kModelChoiceSeconds.size()) c.reached = h.count[t];
    int vars = 0;
    for (std::size_t v = 0; v < kReportVars; ++v) {
      if (!(var[v] > 0)) continue;  // a variable the log never moves
      c.score_at[i] += h.mse[t][v] / var[v];
      ++vars;
    }
    c.score += c.score_at[i];
    cells += vars;
    if (vars > 0) c.score_at[i] /= vars;
  }
  if (cells > 0) c.score /= cells;
  return c;
}

ModelClassChoice choose_model_class(const std::vector<std::pair<std::string, const IdentifiedModel*>>& models,
                                    const FlightLog& test, double control_rate_hz, double start_spacing_s,
                                    ThreadPool& pool) {
  ModelClassChoice out;
  out.control_rate_hz = control_rate_hz;
  for (const auto& [name, model] : models)
    out.candidates.push_back(
        model_class_candidate(name,
                              horizon_mse_as_trained(*model, test, control_rate_hz,
                                                     kModelChoiceSeconds.back(), start_spacing_s, pool),
                              test));
  int most = 0;
  for (const auto& c : out.candidates) most = std::max(most, c.reached);
  std::vector<std::string> set_aside;
  bool found = false;
  for (std::size_t i = 0; i < out.candidates.size(); ++i) {
    const ModelClassCandidate& c = out.candidates[i];
    if (c.reached < most) {
      set_aside.push_back(fmt::format("{} left its data's support in {} of {} rollouts before {} s", c.name,
                                      c.starts - c.reached, c.starts, kModelChoiceSeconds.back()));
      continue;
    }
    if (!found || c.score < kModelChoiceMargin * out.candidates[out.chosen].score) out.chosen = i;
    found = true;
  }
  out.reason = set_aside.empty()
                   ? fmt::format("the lowest hold-out error (a more flexible class must be {:.0f}% lower)",
                                 100 * (1 - kModelChoiceMargin))
                   : fmt::format("{}", fmt::join(set_aside, "; "));
  return out;
}

std::string ModelClassChoice::line() const {
  std::vector<std::string> figures;
  for (const auto& c : candidates)
    figures.push_back(fmt::format("{} {:.4g} ({} of {} rollouts to {} s)", c.name, c.score, c.reached,
                                  c.starts, kModelChoiceSeconds.back()));
  return fmt::format(
      "model class: {}, by {}: hold-out error {} (squared errors over each variable's hold-out variance, "
      "mean "
      "over the 15 variables at 0.5, 1 and 2 s, stepped at {} Hz as hover training runs it; model_choice in "
      "summary.json; --local to set the class)\n",
      candidates[chosen].name, reason, fmt::join(figures, " vs "), control_rate_hz);
}

nlohmann::json ModelClassChoice::to_json() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : candidates) {
    nlohmann::json at;
    for (std::size_t i = 0; i < kModelChoiceSeconds.size(); ++i)
      at[format_double(kModelChoiceSeconds[i])] = c.score_at[i];
    list.push_back({{"class", c.name},
                    {"score", c.score},
                    {"score_at_seconds", at},
                    {"rollouts", c.starts},
                    {"rollouts_reaching_last", c.reached}});
  }
  return {{"chosen", candidates[chosen].name},  {"by", "hold-out prediction"},    {"reason", reason},
          {"control_rate_hz", control_rate_hz}, {"seconds", kModelChoiceSeconds}, {"candidates", list}};
}

IdentifiedModel with_whitened_gains(const IdentifiedModel& model,
                                    const std::vector<ControlGainBias>& biases) {
  Dataset d = model.data();
  const auto index = [](const auto& names, const std::string& name) {
    return static_cast<Eigen::Index>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  for (const ControlGainBias& b : biases)
    d.y.col(index(kBodyVarNames, b.output)) +=
        (b.whitened - b.least_squares) * d.x.col(index(kInputNames, b.control));
  IdentifiedModel out(model.structure(), std::move(d), model.inv_bandwidth(), model.sigma2(),
                      model.noise_correlation());
  out.set_horizon_sd_factors(model.horizon_sd_factors());
  out.set_model_choice(model.model_choice(), model.alternative_inv_bandwidth());
  out.set_vehicle(model.vehicle());
  return out;
}

nlohmann::json mse_at_seconds_json(const HorizonMse& h) {
  nlohmann::json out;
  for (const int sec : kMseReportSeconds) {
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

std::vector<ControlGainBias> model_closed_loop_bias(const IdentifiedModel& model, double window_s,
                                                    ThreadPool& pool) {
  const NoiseCorrelation correlation =
      model.noise_correlation().any()
          ? model.noise_correlation()
          : estimate_noise_correlation(model.data(), model.regression().templates(), model.inv_bandwidth(),
                                       window_s, pool);
  return closed_loop_bias(model.data(), model.regression().templates(), correlation);
}

}  // namespace pegasus::sysid
