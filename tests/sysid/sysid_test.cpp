// System identification: log format and checks, fast vs exact LWR, identification on ground-truth logs,
// the learned simulative model.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <new>
#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/sysid/lwr.hpp"
#include "pegasus/vehicle/flight_log.hpp"

long pegasus_test_allocation_count();  // allocation_counter_test.cpp

namespace {

using namespace pegasus;
using namespace pegasus::sysid;

static_assert(SimulativeModel<LearnedHeliModel>);
static_assert(SimulativeModel<heli::Aircraft>);

FlightLog small_log(double seconds, std::uint64_t seed, bool noise_free = false) {
  heli::AircraftParams p;
  if (noise_free) {
    p.conditions.gust_sigma = 0;
    p.conditions.est_sigma_pos = p.conditions.est_sigma_vel = p.conditions.est_sigma_angle =
        p.conditions.est_sigma_rate = 0;
  }
  const heli::Aircraft heli(p);
  heli::PilotOptions o;
  o.hover_seconds = 4;
  auto f = heli::fly_pilot(heli, o, seconds, seed);
  EXPECT_EQ(f.crash, heli::CrashReason::kNone);
  return f.log;
}

std::string expect_input_error(const std::string& text) {
  try {
    parse_flight_log(text, "log.csv", {.min_rows = 3});
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

const char* kHeader = "time,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4\n";
std::string row(double t, const char* x = "0") {
  return std::to_string(t) + "," + x + ",0,-10,0,0,0,0,0,0,0,0,0,0.1,0,0.2,0.3\n";
}

TEST(FlightLogFormat, RoundTripsExactly) {
  const FlightLog log = small_log(3, 1);
  const FlightLog back = parse_flight_log(flight_log_csv(log), "x.csv");
  EXPECT_EQ(back.time, log.time);
  EXPECT_EQ(back.states, log.states);
  EXPECT_EQ(back.controls, log.controls);
  EXPECT_NEAR(back.dt(), 0.02, 1e-12);
}

TEST(FlightLogFormat, AcceptsColumnsInAnyOrderWithExtras) {
  const std::string text =
      "a4,a3,a2,a1,yaw_rate,pitch_rate,roll_rate,zdot,ydot,xdot,yaw,pitch,roll,z,y,x,time,note\n"
      "0.3,0.2,0,0.1,0,0,0,0,0,0,0,0,0,-10,0,5,0,a\n0.3,0.2,0,0.1,0,0,0,0,0,0,0,0,0,-10,0,5,0.02,b\n"
      "0.3,0.2,0,0.1,0,0,0,0,0,0,0,0,0,-10,0,5,0.04,c\n";
  const auto log = parse_flight_log(text, "f.csv", {.min_rows = 3});
  EXPECT_EQ(log.states[1][0], 5.0);
  EXPECT_EQ(log.controls[2][3], 0.3);
}

TEST(FlightLogFormat, ErrorsNameFileLineAndColumn) {
  EXPECT_NE(expect_input_error("time,x,y\n").find("log.csv:1:z: required column missing"), std::string::npos);
  EXPECT_NE(
      expect_input_error("x," + std::string(kHeader) + "1," + row(0) + "1," + row(0.02) + "1," + row(0.04))
          .find("log.csv:1:x: the column appears twice in the header; expected it once"),
      std::string::npos);
  EXPECT_NE(expect_input_error(std::string(kHeader) + row(0) + row(0.02, "abc") + row(0.04))
                .find("log.csv:3:x: expected a number, found 'abc'"),
            std::string::npos);
  EXPECT_NE(expect_input_error(std::string(kHeader) + row(0) + row(0.02) + row(0.04, "nan"))
                .find("log.csv:4:x: expected a finite"),
            std::string::npos);
  EXPECT_NE(expect_input_error(std::string(kHeader) + row(0) + row(0.02) + row(0.02) + row(0.04))
                .find("log.csv:4:time: expected time to increase strictly"),
            std::string::npos);
  EXPECT_NE(expect_input_error(std::string(kHeader) + row(0) + row(0.02) + row(0.05) + row(0.06))
                .find(":time: expected a constant sample interval"),
            std::string::npos);
  EXPECT_NE(
      expect_input_error(std::string(kHeader) + row(0) + row(0.02)).find("expected at least 3 data rows"),
      std::string::npos);
  EXPECT_NE(
      expect_input_error(std::string(kHeader) + row(0) + "1,2\n" + row(0.04)).find("log.csv:3: expected 17"),
      std::string::npos);
}

TEST(FlightLogFormat, MissingFileIsAnInputError) {
  EXPECT_THROW(read_flight_log("/nonexistent/dir/log.csv"), InputError);
}

struct Fixture {
  FlightLog train = small_log(200, 11);
  FlightLog test = small_log(60, 12);
};
const Fixture& fixture() {
  static const Fixture f;
  return f;
}

double rel_diff(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300}); }

TEST(LocalRegressionPaths, FastAgreesWithExactWithin1e9Relative) {
  const Dataset data = build_dataset(fixture().train, ModelStructure{});
  const auto templates = output_templates(ModelStructure{});
  for (double scale : {1.5, 3.0, 8.0}) {
    std::array<double, kInputs> inv{};
    for (int j = 0; j < kOne; ++j) {
      const double sd = std::sqrt((data.x.col(j).array() - data.x.col(j).mean()).square().mean());
      inv[static_cast<std::size_t>(j)] = 1 / (scale * sd);
    }
    const LocalRegression lwr(&data, templates, inv);
    int compared = 0;
    for (Eigen::Index i = 3; i < data.rows(); i += 97) {
      InputVec q = data.x.row(i).transpose();
      q[kU] += 0.05;
      for (auto [lo, hi] : {std::pair<Eigen::Index, Eigen::Index>{0, 0}, {i - 20, i + 20}}) {
        const LocalFit fast = lwr.fit(q, lo, hi);
        const LocalFit exact = lwr.fit_exact(q, lo, hi);
        ASSERT_EQ(fast.singular, exact.singular);
        if (fast.singular) continue;
        for (int k = 0; k < kBodyVars; ++k) {
          EXPECT_LT(rel_diff(fast.predict(k, q), exact.predict(k, q)), 1e-9) << scale << " " << i << " " << k;
          EXPECT_LT(rel_diff(fast.leverage[k], exact.leverage[k]), 1e-9);
          for (int j = 0; j < kInputs; ++j)
            EXPECT_LE(std::abs(fast.beta[static_cast<std::size_t>(k)][j] -
                               exact.beta[static_cast<std::size_t>(k)][j]),
                      1e-9 * exact.beta[static_cast<std::size_t>(k)].cwiseAbs().maxCoeff() + 1e-300);
        }
        ++compared;
      }
    }
    EXPECT_GT(compared, 20);
  }
}

TEST(LocalRegressionPaths, GlobalModelWithWindowMatchesExact) {
  const Dataset data = build_dataset(fixture().train, ModelStructure{});
  const LocalRegression lwr(&data, output_templates(ModelStructure{}), std::array<double, kInputs>{});
  EXPECT_TRUE(lwr.is_global());
  const InputVec q = data.x.row(100).transpose();
  const LocalFit fast = lwr.fit(q, 50, 250);
  const LocalFit exact = lwr.fit_exact(q, 50, 250);
  for (int k = 2; k < kBodyVars; ++k) EXPECT_LT(rel_diff(fast.predict(k, q), exact.predict(k, q)), 1e-9);
}

TEST(Identification, OneStepPredictionIsAccurateOnNoiseFreeGroundTruth) {
  const FlightLog train = small_log(100, 21, true);
  const FlightLog test = small_log(30, 22, true);
  ThreadPool pool(2);
  IdentifyOptions o;
  o.cv_points = 150;
  o.coordinate_passes = 0;
  const IdentifiedModel model = identify(train, o, pool);
  const Dataset d = build_dataset(test, o.structure);
  for (int k = kU; k < kBodyVars; ++k) {
    double sse = 0, sst = 0;
    const double mean = d.y.col(k).mean();
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      const InputVec x = d.x.row(i).transpose();
      const LocalFit fit = model.regression().fit(x);
      ASSERT_FALSE(fit.singular);
      const double r = d.y(i, k) - fit.predict(k, x);
      sse += r * r;
      sst += (d.y(i, k) - mean) * (d.y(i, k) - mean);
    }
    // At least 90% of the variance of the one-step change that the template leaves is explained.
    EXPECT_LT(sse / sst, 0.1) << kBodyVarNames[static_cast<std::size_t>(k)];
  }
}

TEST(Identification, LocallyWeightedBeatsGlobalLinearOnWindowedHoldOut) {
  // One-step prediction on data 8 s or more away from the predicted point (the cross-validation windows):
  // the chosen local model beats the global linear one of the same template.
  ThreadPool pool(2);
  IdentifyOptions o;
  o.cv_points = 200;
  o.coordinate_passes = 0;
  IdentifyReport local_report, global_report;
  identify(fixture().train, o, pool, &local_report);
  o.local = false;
  const IdentifiedModel global = identify(fixture().train, o, pool, &global_report);
  double best_local = INFINITY;
  for (const auto& [what, e] : local_report.cv_trace) best_local = std::min(best_local, e);
  ASSERT_EQ(global_report.cv_trace.size(), 1u);
  EXPECT_LT(best_local, global_report.cv_trace[0].second);
  // Open-loop prediction on the hold-out log is reported for horizons 0..1 s by every rollout.
  const HorizonMse mg = horizon_mse(global, fixture().test, 1.0, 1.0, pool);
  EXPECT_EQ(mg.seconds.size(), 11u);
  EXPECT_GT(mg.count.back(), 20);
  EXPECT_EQ(mg.mse.front()[0], 0.0);          // the start state is exact
  EXPECT_GT(mg.mse.back()[6], mg.mse[1][6]);  // errors grow with the horizon
}

TEST(Identification, ResultDoesNotDependOnThreads) {
  IdentifyOptions o;
  o.cv_points = 60;
  o.scale_grid = {1, 4};
  o.coordinate_passes = 0;
  ThreadPool one(1), two(2);
  const auto a = identify(fixture().train, o, one).to_json();
  const auto b = identify(fixture().train, o, two).to_json();
  EXPECT_EQ(a.dump(), b.dump());
}

TEST(Identification, ModelFileRoundTrips) {
  IdentifyOptions o;
  o.cv_points = 60;
  o.scale_grid = {2};
  o.coordinate_passes = 0;
  ThreadPool pool(1);
  const auto model = identify(fixture().train, o, pool);
  const auto file = std::filesystem::temp_directory_path() / "pegasus_sysid_model_test.json";
  model.save(file);
  const auto back = IdentifiedModel::load(file);
  std::filesystem::remove(file);
  EXPECT_EQ(back.to_json().dump(), model.to_json().dump());
}

// The model the learned-model tests step: a small identification of the fixture's training flight, made once.
std::shared_ptr<const IdentifiedModel> learned_fixture_model() {
  static const auto model = [] {
    IdentifyOptions o;
    o.cv_points = 60;
    o.scale_grid = {2};
    o.coordinate_passes = 0;
    ThreadPool pool(1);
    return std::make_shared<const IdentifiedModel>(identify(fixture().train, o, pool));
  }();
  return model;
}

TEST(LearnedModel, IsDeterministicAndCrashesOutsideTheData) {
  const auto model = learned_fixture_model();
  LearnedModelOptions lo;
  lo.start = fixture().train.states[500];
  const LearnedHeliModel sim(model, lo);
  std::array<double, 6> p0{0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
  std::array<double, 8> p{0.3, 0.6, 0.5, 0.7, 0.2, 0.5, 0.45, 0.55};
  auto s1 = sim.initial_state(p0);
  auto s2 = sim.initial_state(p0);
  for (int t = 0; t < 50; ++t) {
    const auto a = fixture().train.controls[static_cast<std::size_t>(500 + t)];
    s1 = sim.step(s1, a, p);
    s2 = sim.step(s2, a, p);
  }
  EXPECT_EQ(s1.sim.world, s2.sim.world);
  EXPECT_FALSE(s1.crashed);
  // Steps, refits included, allocate nothing (STYLE.md).
  const long before = pegasus_test_allocation_count();
  for (int t = 0; t < 20; ++t)
    s1 = sim.step(s1, fixture().train.controls[static_cast<std::size_t>(550 + t)], p);
  EXPECT_EQ(pegasus_test_allocation_count(), before);
  // A state far outside anything the pilot flew: 30 m/s sideways at a 0.8 rad roll.
  auto far = s1;
  far.sim.world[7] = 30;
  far.sim.world[3] = 0.8;
  far.step = 0;
  const auto crashed = sim.step(far, {0, 0, 0, 0}, p);
  EXPECT_TRUE(crashed.crashed);
  EXPECT_EQ(sim.reward(far, {0, 0, 0, 0}, crashed), -50000);
  EXPECT_TRUE(sim.terminal(crashed));
}

}  // namespace

namespace {

TEST(LearnedModel, StepNoiseIsTheInverseCdfOfThePredictiveVarianceOverFive) {
  const auto model = learned_fixture_model();
  LearnedModelOptions lo;
  lo.start = fixture().train.states[800];
  const LearnedHeliModel sim(model, lo);
  const auto s0 = sim.initial_state(std::array<double, 6>{0.5, 0.5, 0.5, 0.5, 0.5, 0.5});
  const std::array<double, 4> a = fixture().train.controls[800];
  std::array<double, 8> mid;
  mid.fill(0.5);
  const auto mean = sim.step(s0, a, mid);
  ASSERT_FALSE(mean.crashed);
  const double one_sd = 0.5 * std::erfc(-1 / std::sqrt(2.0));  // Phi(1)
  for (int k = kU; k < kBodyVars; ++k) {
    auto p = mid;
    p[static_cast<std::size_t>(k)] = one_sd;
    const auto up = sim.step(s0, a, p);
    const BodyVec d = body_from_log_state(up.sim.world) - body_from_log_state(mean.sim.world);
    // Eq 5.6 at 50 Hz from a 10 Hz model: one standard deviation is sqrt(var / 5) (§5.2.2).
    EXPECT_NEAR(d[k], std::sqrt(mean.variance[k] * 0.02 / model->dt()), 1e-9) << k;
  }
  // Coefficients are refitted every 5 steps and held in between.
  auto s = mean;
  for (int t = 1; t < 5; ++t) {
    const auto next = sim.step(s, fixture().train.controls[static_cast<std::size_t>(800 + t)], mid);
    EXPECT_EQ(next.beta[2], s.beta[2]);
    s = next;
  }
  const auto refit = sim.step(s, fixture().train.controls[805], mid);
  EXPECT_NE(refit.beta[2], s.beta[2]);
}

}  // namespace

namespace {

// A model with AR(1) noise: the learned model carries each variable's AR part in its state, draws it from a
// second uniform per variable, and scales it so that one model step (five 50 Hz steps) sums to the share of
// the identified variance the AR part has, with the identified correlation from one model step to the next.
TEST(LearnedModel, Ar1NoiseSumsToItsShareOverAModelStepWithItsCorrelation) {
  const auto white = learned_fixture_model();
  nlohmann::json j = white->to_json();
  const double share = 0.6, rho = 0.8;
  j["noise"] = {{"model", "ar1"},
                {"share", std::vector<double>(kBodyVars, share)},
                {"rho", std::vector<double>(kBodyVars, rho)}};
  auto model = std::make_shared<const IdentifiedModel>(IdentifiedModel::from_json(j));
  LearnedModelOptions lo;
  lo.start = fixture().train.states[800];
  const LearnedHeliModel sim(model, lo);
  EXPECT_EQ(sim.noise_dim(), 16);
  EXPECT_EQ(sim.initial_noise_dim(), 14);
  EXPECT_EQ(LearnedHeliModel(white, lo).noise_dim(), 8);
  const std::array<double, 4> a = fixture().train.controls[800];
  UniformStream rng(3, 0);
  const int n = 4000;
  BodyVec sum_first = BodyVec::Zero(), sum_second = BodyVec::Zero(), cross = BodyVec::Zero();
  BodyVec variance = BodyVec::Zero();
  std::array<double, 14> p0;
  std::array<double, 16> p;
  for (int i = 0; i < n; ++i) {
    for (double& u : p0) u = rng.next();
    for (int k = 0; k < 6; ++k) p0[static_cast<std::size_t>(k)] = 0.5;  // the same start state each time
    auto s = sim.initial_state(p0);
    BodyVec first = BodyVec::Zero(), second = BodyVec::Zero();
    for (int t = 0; t < 10; ++t) {
      for (double& u : p) u = rng.next();
      for (int k = 0; k < kBodyVars; ++k) p[static_cast<std::size_t>(k)] = 0.5;  // white part off
      s = sim.step(s, a, p);
      ASSERT_FALSE(s.crashed);
      (t < 5 ? first : second) += s.colored;
      if (t == 0) variance = s.variance;
    }
    sum_first += first.cwiseAbs2();
    sum_second += second.cwiseAbs2();
    cross += first.cwiseProduct(second);
  }
  // Per 50 Hz step: correlation r = rho^(1/5) and stationary variance share * var / (5 + 2 sum_j (5 - j)
  // r^j).
  const double r = std::pow(rho, 0.2);
  double sum_factor = 5;
  for (int i = 1; i < 5; ++i) sum_factor += 2 * (5 - i) * std::pow(r, i);
  for (int k = 0; k < kBodyVars; ++k) {
    // The variance of the first 5 steps' sum: the AR part starts from its stationary law at the identified
    // sigma^2 (no fit yet), its innovations use the refit's predictive variance (sigma^2 (1 + leverage));
    // when the two agree this is share * var.
    const double start = model->sigma2()[k] * share / sum_factor,
                 innovation = variance[k] * share / sum_factor;
    double from_start = 0, expected = 0;
    for (int t = 1; t <= 5; ++t) from_start += std::pow(r, t);
    expected = start * from_start * from_start;
    for (int i = 1; i <= 5; ++i) {
      double weight = 0;
      for (int m = 0; m <= 5 - i; ++m) weight += std::pow(r, m);
      expected += innovation * (1 - r * r) * weight * weight;
    }
    EXPECT_NEAR(sum_first[k] / n / expected, 1.0, 0.08) << kBodyVarNames[k];
    // Consecutive model steps' sums are correlated about rho (rho^(1/5) per 50 Hz step).
    EXPECT_NEAR(cross[k] / std::sqrt(sum_first[k] * sum_second[k]), rho, 0.1) << kBodyVarNames[k];
  }
}

}  // namespace
