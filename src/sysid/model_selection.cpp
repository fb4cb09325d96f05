#include "pegasus/sysid/model_selection.hpp"

#include <fmt/format.h>

#include <cmath>

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
