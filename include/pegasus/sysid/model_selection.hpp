#pragma once
// The studies that come with an identified model (thesis §5.2): the model-selection variants of Fig 5.2 (the
// global linear model, the other choice of extra states and of intercept, other identification rates), the
// chosen model as hover training runs it, and the closed-loop bias of its control gains. What `identify`
// reports beside the model; the command only writes the results.
//
//   const ModelSelectionStudy study = model_selection_study(model, train, test, options, {...}, pool);
//   study.variants.front();   // the chosen model's errors against horizon
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid {

struct NamedHorizonMse {
  std::string name;
  HorizonMse mse;
};

struct ModelSelectionOptions {
  double horizon_s = 10;        // longest prediction horizon
  double start_spacing_s = 2;   // spacing of the open-loop prediction starts on the test log
  bool variants = true;         // also the other extra states, intercept and rates (local models only)
  double control_rate_hz = 50;  // the rate hover training steps the model at
};

struct ModelSelectionStudy {
  // The chosen model first, then the global linear model (when the chosen one is local), then the variants.
  std::vector<NamedHorizonMse> variants;
  NamedHorizonMse as_trained;  // the chosen model stepped at control_rate_hz (horizon_mse_as_trained)
  HorizonMse global_linear;    // the global linear model of the same template, always
  std::vector<double> skipped_rates_hz;  // of Fig 5.2's rates, those the logs' rates do not allow
};

// Deterministic for any number of threads; `options` the options `model` was identified with.
ModelSelectionStudy model_selection_study(const IdentifiedModel& model, const FlightLog& train,
                                          const FlightLog& test, const IdentifyOptions& options,
                                          const ModelSelectionOptions& study, ThreadPool& pool);

// The horizons summaries report, s.
inline constexpr std::array<int, 3> kMseReportSeconds = {1, 5, 10};
// The mean-squared errors at kMseReportSeconds ({"1": {"x": ..., ...}, ...}), horizons the rows hold only.
nlohmann::json mse_at_seconds_json(const HorizonMse& h);

// The closed-loop bias of the model's control gains (closed_loop_bias), measured against a fit that whitens
// the model's AR(1) noise, or for a white-noise model the AR(1) estimated for this check alone.
std::vector<ControlGainBias> model_closed_loop_bias(const IdentifiedModel& model, double window_s,
                                                    ThreadPool& pool);

}  // namespace pegasus::sysid
