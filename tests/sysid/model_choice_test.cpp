// The model class from the data (issue 48): on a truly linear system the global linear fit is chosen, on a
// nonlinear one the locally weighted fit; the recorded figures are the hold-out errors recomputed; model.json
// keeps the comparison and the other class, and the whitened gains move exactly the biased coefficients.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/random/counter_rng.hpp"
#include "pegasus/random/normal_quantile.hpp"
#include "pegasus/sysid/model_selection.hpp"
#include "pilot_logs.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::sysid;

// A yaw-rate system at 10 Hz driven by white random rudder: r' = 0.8 r + 0.5 a4 (linear) or
// r' = 0.5 r + 0.6 tanh(4 a4) (the rudder saturates), plus white noise; every other state at rest.
FlightLog yaw_log(std::uint64_t seed, int rows, bool nonlinear) {
  FlightLog log;
  UniformStream rng(seed, 0);
  auto normal = [&rng] { return normal_quantile(rng.next()); };
  std::array<double, kLogStates> state{};
  state[2] = -10;
  for (int i = 0; i < rows; ++i) {
    log.time.push_back(i * 0.1);
    log.states.push_back(state);
    const std::array<double, 4> a = {0, 0, 0, 0.3 * normal()};
    log.controls.push_back(a);
    const double r = state[11];
    state[11] = (nonlinear ? 0.5 * r + 0.6 * std::tanh(4 * a[3]) : 0.8 * r + 0.5 * a[3]) + 0.02 * normal();
  }
  return log;
}

struct Candidates {
  IdentifiedModel global, local;
};

Candidates identify_both(const FlightLog& train) {
  ThreadPool pool(2);
  IdentifyOptions o = test::small_search();
  o.structure.rate_hz = 10;
  o.structure.extra_states = false;
  o.local = false;
  IdentifiedModel global = identify_mean(train, o, pool);
  o.local = true;
  IdentifiedModel local = identify_mean(train, o, pool);
  return {std::move(global), std::move(local)};
}

ModelClassChoice choose(const Candidates& c, const FlightLog& test) {
  ThreadPool pool(2);
  return choose_model_class({{"global linear", &c.global}, {"locally weighted", &c.local}}, test, 10, 2,
                            pool);
}

TEST(ModelChoice, ALinearSystemGetsTheGlobalModelANonlinearOneTheLocal) {
  const Candidates linear = identify_both(yaw_log(1, 3000, false));
  const ModelClassChoice on_linear = choose(linear, yaw_log(2, 1000, false));
  EXPECT_EQ(on_linear.chosen, 0u) << on_linear.line();
  const Candidates bent = identify_both(yaw_log(3, 3000, true));
  const ModelClassChoice on_bent = choose(bent, yaw_log(4, 1000, true));
  EXPECT_EQ(on_bent.chosen, 1u) << on_bent.line();
  // The local fit earns its keep by a wide margin where the rudder saturates.
  EXPECT_LT(on_bent.candidates[1].score, 0.5 * on_bent.candidates[0].score) << on_bent.line();
  for (const ModelClassChoice* c : {&on_linear, &on_bent}) {
    EXPECT_NE(c->line().find("model class: " + c->candidates[c->chosen].name), std::string::npos)
        << c->line();
    for (const auto& candidate : c->candidates) {
      EXPECT_GT(candidate.starts, 10);
      EXPECT_EQ(candidate.reached, candidate.starts);  // neither leaves its data's support here
    }
  }
}

TEST(ModelChoice, TheRecordedFiguresAreTheHoldOutErrorsRecomputed) {
  const FlightLog test_log = yaw_log(4, 1000, true);
  const Candidates bent = identify_both(yaw_log(3, 3000, true));
  const nlohmann::json recorded = choose(bent, test_log).to_json();
  ThreadPool pool(1);  // another pool size: the same figures
  const std::array<const IdentifiedModel*, 2> models = {&bent.global, &bent.local};
  for (std::size_t i = 0; i < models.size(); ++i) {
    const HorizonMse h = horizon_mse_as_trained(*models[i], test_log, 10, 2, 2, pool);
    // By hand: yaw_rate is the only variable the log moves; its squared error over its variance, at 0.5, 1
    // and 2 s (rows 5, 10 and 20 at 10 Hz).
    double mean = 0, var = 0;
    for (const auto& s : test_log.states) mean += s[11] / static_cast<double>(test_log.rows());
    for (const auto& s : test_log.states)
      var += (s[11] - mean) * (s[11] - mean) / static_cast<double>(test_log.rows());
    const double by_hand = (h.mse[5][11] + h.mse[10][11] + h.mse[20][11]) / (3 * var);
    const nlohmann::json& c = recorded["candidates"][i];
    EXPECT_NEAR(c["score"].get<double>(), by_hand, 1e-12 * by_hand) << c;
    EXPECT_NEAR(c["score_at_seconds"]["1"].get<double>(), h.mse[10][11] / var, 1e-12 * by_hand) << c;
    EXPECT_EQ(c["rollouts"].get<int>(), h.count.front());
  }
  EXPECT_EQ(recorded["chosen"], "locally weighted");
  // model.json keeps the comparison and the class not chosen, and gives it back.
  IdentifiedModel chosen(bent.local.structure(), bent.local.data(), bent.local.inv_bandwidth(),
                         bent.local.sigma2());
  EXPECT_FALSE(chosen.alternative().has_value());
  chosen.set_model_choice(recorded, bent.global.inv_bandwidth());
  const IdentifiedModel back = IdentifiedModel::from_json(chosen.to_json());
  EXPECT_EQ(back.model_choice(), recorded);
  const auto other = back.alternative();
  ASSERT_TRUE(other.has_value());
  EXPECT_TRUE(other->is_global());
  EXPECT_EQ(other->data().y, bent.local.data().y);
}

TEST(ModelChoice, WhitenedGainsMoveExactlyTheBiasedCoefficients) {
  const Candidates linear = identify_both(yaw_log(1, 3000, false));
  const ControlGainBias bias{.output = "yaw_rate",
                             .control = "a4",
                             .least_squares = 0.5,
                             .whitened = 0.7,
                             .relative = 0.5 / 0.7 - 1,
                             .effect_share = 1};
  const IdentifiedModel moved = with_whitened_gains(linear.global, {bias});
  const InputVec x = linear.global.data().x.row(10).transpose();
  const LocalFit before = linear.global.regression().fit(x), after = moved.regression().fit(x);
  ASSERT_FALSE(before.singular || after.singular);
  for (int c = 0; c < kInputs; ++c)
    EXPECT_NEAR(after.beta[kYawRate][c] - before.beta[kYawRate][c], c == kA4 ? 0.2 : 0.0, 1e-9) << c;
  for (int k = 0; k < kBodyVars; ++k) {
    if (k == kYawRate) continue;
    EXPECT_EQ(after.beta[static_cast<std::size_t>(k)], before.beta[static_cast<std::size_t>(k)]) << k;
  }
}

}  // namespace
