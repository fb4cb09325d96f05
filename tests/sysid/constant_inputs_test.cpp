// What identification needed for logs other than the X-Cell's: inputs that never move in the training data
// leave the regression (else X'WX is singular next to the intercept), and the constant-velocity baseline of
// the prediction report.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/model_selection.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::sysid;

FlightLog pilot_log(double seconds, std::uint64_t seed) {
  const heli::Aircraft heli;
  heli::PilotOptions o;
  o.hover_seconds = 4;
  return heli::fly_pilot(heli, o, seconds, seed).log;
}

IdentifyOptions global_fit() {
  IdentifyOptions o;
  o.local = false;
  o.cv_points = 60;
  return o;
}

TEST(ConstantInputs, AControlThatNeverMovesLeavesTheRegressionInsteadOfMakingItSingular) {
  ThreadPool pool(2);
  FlightLog train = pilot_log(60, 5), test = pilot_log(30, 6);
  for (auto* log : {&train, &test})
    for (auto& a : log->controls) a[2] = -1;  // collective pinned, as a disarmed quadrotor's thrust
  const IdentifiedModel model = identify(train, global_fit(), pool);
  for (int j = 0; j < kInputs; ++j)
    EXPECT_EQ(model.structure().constant_inputs[static_cast<std::size_t>(j)], j == kA3) << kInputNames[j];
  for (int k = 0; k < kBodyVars; ++k) EXPECT_FALSE(model.regression().templates()[k].free[kA3]);
  const LocalFit fit = model.regression().fit(model.data().x.row(10).transpose());
  EXPECT_FALSE(fit.singular);
  const HorizonMse h = horizon_mse(model, test, 1.0, 2.0, pool);
  EXPECT_EQ(h.count.back(), h.count.front());  // no rollout stopped on a singular fit
  // The same structure without the rule is singular: the pinned column equals -1 times the intercept's.
  ModelStructure pinned = model.structure();
  pinned.constant_inputs = {};
  const Dataset data = build_dataset(train, pinned);
  const LocalRegression plain(&data, output_templates(pinned), std::array<double, kInputs>{});
  EXPECT_TRUE(plain.fit(data.x.row(10).transpose()).singular);
  // The rule is saved with the model and read back.
  const IdentifiedModel back = IdentifiedModel::from_json(model.to_json());
  EXPECT_EQ(back.structure().constant_inputs, model.structure().constant_inputs);
  EXPECT_NE(model.structure().describe().find("constant in the data (left out): a3"), std::string::npos);
  // The comparison models of Fig 5.2 leave it out too: each rollout reaches every horizon (they were all
  // stopped at once, and the summary's global linear MSE was null).
  IdentifyOptions local = global_fit();
  local.local = true;
  const IdentifiedModel chosen = identify(train, local, pool);
  const ModelSelectionStudy study =
      model_selection_study(chosen, train, test, local, {.horizon_s = 1.0, .start_spacing_s = 2.0}, pool);
  ASSERT_GE(study.variants.size(), 4u);
  for (const NamedHorizonMse& v : study.variants) {
    ASSERT_FALSE(v.mse.count.empty()) << v.name;
    EXPECT_EQ(v.mse.count.back(), v.mse.count.front()) << v.name;
    EXPECT_GT(v.mse.count.back(), 0) << v.name;
  }
  EXPECT_EQ(study.global_linear.count.back(), study.global_linear.count.front());
}

TEST(ConstantInputs, NoneOnTheXCellsOwnLogs) {
  ThreadPool pool(2);
  const IdentifiedModel model = identify(pilot_log(60, 5), global_fit(), pool);
  EXPECT_EQ(model.structure().constant_inputs, (std::array<bool, kInputs>{}));
  EXPECT_FALSE(model.to_json()["structure"].contains("constant_inputs"));  // model files as before
}

// The outside aircraft's pilot held collective and tail within a few hundredths of trim: bandwidths in units
// of each input's spread then fell far below any excursion a policy makes, and the local fit at a policy's
// controls had leverages in the thousands. The absolute floor keeps those bandwidths at a useful width.
TEST(BandwidthFloor, ControlsThePilotBarelyMovedGetTheFloorInsteadOfATinyBandwidth) {
  ThreadPool pool(2);
  FlightLog train = pilot_log(120, 5);
  std::array<double, 4> mean{};
  for (const auto& a : train.controls)
    for (std::size_t c = 0; c < 4; ++c) mean[c] += a[c] / static_cast<double>(train.rows());
  for (auto& a : train.controls)
    for (std::size_t c : {2u, 3u}) a[c] = mean[c] + 0.03 * (a[c] - mean[c]);
  IdentifyOptions o;
  o.cv_points = 60;
  o.scale_grid = {0.5, 1, 2};
  o.coordinate_passes = 0;
  IdentifyReport report;
  const IdentifiedModel floored = identify(train, o, pool, &report);
  IdentifyOptions unfloored_options = o;
  unfloored_options.min_bandwidth.control = 0;
  const IdentifiedModel unfloored = identify(train, unfloored_options, pool);
  const double floor = o.min_bandwidth.control;
  for (int j : {kA3, kA4}) {
    EXPECT_DOUBLE_EQ(1 / floored.inv_bandwidth()[static_cast<std::size_t>(j)], floor) << kInputNames[j];
    // Without the floor the search picks a bandwidth narrower than it, so the floor is what held.
    EXPECT_LT(1 / unfloored.inv_bandwidth()[static_cast<std::size_t>(j)], 0.5 * floor) << kInputNames[j];
  }
  EXPECT_EQ(report.floored_inputs, (std::vector<std::string>{"a3", "a4"}));
  // A policy's excursion of 8 spreads in collective (what the outside aircraft's perturbed starts caused)
  // from a row of the log: without the floor the kernel keeps almost no rows and the leverage explodes (the
  // outside aircraft's reached 1600), with it the predictive variance grows by a bounded factor.
  const auto a3 = floored.data().x.col(kA3).array();
  const double spread = std::sqrt((a3 - a3.mean()).square().mean());
  InputVec x = floored.data().x.row(100).transpose();
  x[kA3] += 8 * spread;
  const double floored_leverage = floored.regression().fit(x).leverage.maxCoeff();
  const double unfloored_leverage = unfloored.regression().fit(x).leverage.maxCoeff();
  EXPECT_LT(floored_leverage, 15.0);
  EXPECT_GT(unfloored_leverage, 1000 * floored_leverage);
}

TEST(BandwidthFloor, TheXCellsLogsChooseBandwidthsAboveEveryFloor) {
  ThreadPool pool(2);
  IdentifyOptions o;
  o.cv_points = 60;
  o.scale_grid = {0.5, 1, 2};
  o.coordinate_passes = 1;
  IdentifyReport report;
  const IdentifiedModel model = identify(pilot_log(120, 5), o, pool, &report);
  EXPECT_TRUE(report.floored_inputs.empty());
  const auto floors = o.min_bandwidth.per_input();
  for (std::size_t j = 0; j < kInputs; ++j) {
    if (model.inv_bandwidth()[j] == 0) continue;
    EXPECT_GT(1 / model.inv_bandwidth()[j], floors[j]) << kInputNames[j];
  }
}

// A flight at constant world velocity and attitude is the baseline's exact prediction; with a constant
// acceleration its position error is a t^2 / 2, its velocity error a t.
TEST(ConstantVelocityBaseline, ErrorIsTheUnmodelledAcceleration) {
  FlightLog log;
  const double dt = 0.02, a = 0.3;
  for (int i = 0; i < 500; ++i) {
    const double t = i * dt;
    log.time.push_back(t);
    log.states.push_back({1 + 2 * t, -t + 0.5 * a * t * t, -10, 0.1, -0.05, 0.3, 2, -1 + a * t, 0, 0, 0, 0});
    log.controls.push_back({0, 0, 0, 0});
  }
  const HorizonMse h = constant_velocity_mse(log, 0.1, 2.0, 0.5);
  ASSERT_EQ(h.seconds.size(), 21u);
  const int starts = (500 - 100 - 1) / 25 + 1;
  for (std::size_t t = 0; t < h.seconds.size(); ++t) {
    const double s = h.seconds[t];
    EXPECT_EQ(h.count[t], starts);
    EXPECT_NEAR(h.mse[t][0], 0, 1e-20);                                // x
    EXPECT_NEAR(std::sqrt(h.mse[t][1]), 0.5 * a * s * s, 1e-12) << s;  // y
    EXPECT_NEAR(std::sqrt(h.mse[t][7]), a * s, 1e-12) << s;            // ydot
    EXPECT_NEAR(h.mse[t][3] + h.mse[t][4] + h.mse[t][5], 0, 1e-20);    // attitude held, and it is held
  }
}

}  // namespace
