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

// The model class from the data (issue 48): the candidates' hold-out prediction errors as hover training runs
// them (horizon_mse_as_trained at the controller's rate, noise off, from starts start_spacing_s apart), each
// squared error divided by the variable's variance on the hold-out log and averaged over the 15 report
// variables and the horizons kModelChoiceSeconds: the `score`, lower is better. A candidate whose rollouts
// leave its data's support (the learned model's crash) before the last horizon more often than another's is
// not chosen: its errors count only the rollouts that stayed. The candidates come simplest first, and a later
// one is chosen only when its score is below kModelChoiceMargin times the best earlier one's: a more flexible
// class must earn its keep (on a truly linear system the local fit's extra variance is all it adds, and it
// costs training time and extrapolates worse).
inline constexpr std::array<double, 3> kModelChoiceSeconds = {0.5, 1, 2};
inline constexpr double kModelChoiceMargin = 0.98;
struct ModelClassCandidate {
  std::string name;  // "locally weighted", "global linear"
  double score = 0;
  int starts = 0;                                             // rollouts started
  int reached = 0;                                            // of them, those that reached the last horizon
  std::array<double, kModelChoiceSeconds.size()> score_at{};  // the score at each horizon alone
};
struct ModelClassChoice {
  std::vector<ModelClassCandidate> candidates;  // in the order given
  std::size_t chosen = 0;
  std::string reason;  // "lowest hold-out error" or why the others were set aside
  double control_rate_hz = 0;
  // One line for the terminal: the class chosen and why, with every candidate's figures.
  std::string line() const;
  nlohmann::json to_json() const;
};
// The score of one candidate's errors (h from horizon_mse_as_trained on `test`).
ModelClassCandidate model_class_candidate(const std::string& name, const HorizonMse& h,
                                          const FlightLog& test);
ModelClassChoice choose_model_class(const std::vector<std::pair<std::string, const IdentifiedModel*>>& models,
                                    const FlightLog& test, double control_rate_hz, double start_spacing_s,
                                    ThreadPool& pool);

// The model with each reported control gain moved from its least-squares value to the whitened one
// (closed_loop_bias): each output's targets get (whitened - least_squares) x the control, which moves that
// coefficient by exactly the difference in every weighted least-squares fit, local or global, and leaves the
// others. The noise, bandwidths and records stay the model's.
IdentifiedModel with_whitened_gains(const IdentifiedModel& model, const std::vector<ControlGainBias>& biases);

// The horizons summaries report, s.
inline constexpr std::array<int, 3> kMseReportSeconds = {1, 5, 10};
// The mean-squared errors at kMseReportSeconds ({"1": {"x": ..., ...}, ...}), horizons the rows hold only.
nlohmann::json mse_at_seconds_json(const HorizonMse& h);

// The closed-loop bias of the model's control gains (closed_loop_bias), measured against a fit that whitens
// the model's AR(1) noise, or for a white-noise model the AR(1) estimated for this check alone.
std::vector<ControlGainBias> model_closed_loop_bias(const IdentifiedModel& model, double window_s,
                                                    ThreadPool& pool);

}  // namespace pegasus::sysid
