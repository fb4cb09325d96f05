// Noise calibration (IdentifyOptions::calibrate_noise): the noise check's bands split by noise source, the
// fit of the sources' scales, the scaled noise, and what calibration writes.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/random/normal_quantile.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pilot_logs.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::sysid;
using pegasus::sysid::test::logs;
using pegasus::sysid::test::small_search;

// The filter's covariance is linear in the noise covariances: the bands of a model whose noise is scaled by
// source (scaled_noise) are the split bands (noise_band_terms) times the scales, step by step.
TEST(NoiseCheck, BandsAreLinearInTheNoiseScalesBySource) {
  ThreadPool pool(2);
  IdentifyOptions o = small_search();
  o.noise = NoiseModel::kAr1Measurement;
  const IdentifiedModel plain = identify(logs().train, o, pool);
  ASSERT_TRUE(plain.noise_correlation().has_measurement());
  const NoiseBandTerms terms = noise_band_terms(plain, logs().test, 2.0, 0.0, pool);
  ASSERT_EQ(terms.sources, 3 * kBodyVars);  // process, logged error, a white logged error to add
  {
    // The windows are filtered in parallel: one thread gives the same steps, bit for bit.
    ThreadPool one(1);
    const NoiseBandTerms serial = noise_band_terms(plain, logs().test, 2.0, 0.0, one);
    ASSERT_EQ(serial.horizon, terms.horizon);
    for (std::size_t i = 0; i < terms.error.size(); ++i) {
      ASSERT_EQ(serial.error[i], terms.error[i]) << i;
      ASSERT_EQ(serial.band[i], terms.band[i]) << i;
    }
  }
  NoiseScale scale;
  for (int k = 0; k < kBodyVars; ++k) {
    scale.process[k] = 0.25 + 0.5 * k;
    scale.measurement[k] = 3.0 - 0.3 * k;
    scale.measurement_white[k] = 0.1 + 0.2 * k;
  }
  const Eigen::VectorXd scales = terms.scales(scale);
  const auto [sigma2, correlation] = scaled_noise(plain.sigma2(), plain.noise_correlation(), scale);
  const IdentifiedModel scaled(plain.structure(), plain.data(), plain.inv_bandwidth(), sigma2, correlation);
  const NoiseCheck check = noise_check(scaled, logs().test, 2.0, 0.0, pool);
  ASSERT_EQ(check.normalized_errors.size(), terms.error.size());
  ASSERT_GT(terms.error.size(), 300u);
  for (std::size_t i = 0; i < terms.error.size(); ++i)
    for (int k = 0; k < kBodyVars; ++k) {
      const double expected = terms.error[i][k] / std::sqrt(terms.band[i].row(k).dot(scales));
      ASSERT_NEAR(check.normalized_errors[i][k], expected, 1e-9 * expected)
          << "step " << i << ", " << kBodyVarNames[static_cast<std::size_t>(k)];
    }
}

// Overlapping windows (start_spacing_s below reset_s): a window starts every spacing, each is filtered as if
// it were the only one, so the windows that start on the reset grid are the plain check's, bit for bit, and
// the others fill the gaps.
TEST(NoiseCheck, OverlappingWindowsContainThePlainWindowsBitForBit) {
  ThreadPool pool(2);
  IdentifyOptions o = small_search();
  o.noise = NoiseModel::kAr1Measurement;
  const IdentifiedModel model = identify(logs().train, o, pool);
  const double reset_s = 2.0, spacing_s = 0.5;
  const NoiseBandTerms plain = noise_band_terms(model, logs().test, reset_s, 0.0, pool);
  const NoiseBandTerms dense = noise_band_terms(model, logs().test, reset_s, 0.0, pool, spacing_s);
  const auto window_steps = static_cast<std::size_t>(std::lround(reset_s / model.dt()));
  const auto every = static_cast<std::size_t>(std::lround(reset_s / spacing_s));
  // Windows: each starts where the last step counted had horizon 0.
  auto starts = [](const NoiseBandTerms& t) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < t.horizon.size(); ++i)
      if (t.horizon[i] == 0) out.push_back(i);
    return out;
  };
  const auto plain_starts = starts(plain), dense_starts = starts(dense);
  // The 80 s log at 10 Hz: 40 windows of 20 steps on the reset grid, and 3 more between each two.
  ASSERT_EQ(plain_starts.size(), 40u);
  ASSERT_GE(dense_starts.size(), every * (plain_starts.size() - 1) + 1);
  ASSERT_LE(dense_starts.size(), every * plain_starts.size());
  for (std::size_t w = 0; w < plain_starts.size(); ++w) {
    const std::size_t p0 = plain_starts[w], d0 = dense_starts[every * w];
    for (std::size_t t = 0; t < window_steps && p0 + t < plain.horizon.size(); ++t) {
      if (t > 0 && plain.horizon[p0 + t] == 0) break;  // a short last window
      ASSERT_EQ(dense.horizon[d0 + t], plain.horizon[p0 + t]) << "window " << w << ", step " << t;
      ASSERT_EQ(dense.error[d0 + t], plain.error[p0 + t]) << "window " << w << ", step " << t;
      ASSERT_EQ(dense.band[d0 + t], plain.band[p0 + t]) << "window " << w << ", step " << t;
    }
  }
}

// Errors drawn with known scales on split bands shaped as the filter's are (process parts growing with the
// horizon, some reaching another variable, measurement parts flat): the fit gives the scales back (its small
// pull towards 1 included).
TEST(NoiseCheck, BandMissesReadTheCellsAtWholeStepsAndCountTheLimitsInside) {
  // 10 Hz steps, a reset every 2 s: 20 horizons; cell (t, k) misses (t + 1) / 100 + k / 1000.
  NoiseCheck check;
  check.steps_by_horizon.assign(20, 700);
  check.steps_by_horizon[9] = 0;  // nothing counted at 1 s
  for (int t = 0; t < 20; ++t) {
    BodyVec v;
    for (int k = 0; k < kBodyVars; ++k) v[k] = (t + 1) / 100.0 + k / 1000.0;
    check.outside_by_horizon.push_back(v);
  }
  // 0.5 s is step 5 (index 4) even when given as 0.52 s; 1 s has no steps; 3 s lies beyond the window.
  const auto cells = band_misses(check, 0.1, {0.52, 1.0, 2.0, 3.0});
  ASSERT_EQ(cells.size(), 2u * kBodyVars);
  for (int k = 0; k < kBodyVars; ++k) {
    EXPECT_EQ(cells[k].variable, k);
    EXPECT_EQ(cells[k].seconds, 0.52);
    EXPECT_EQ(cells[k].outside, check.outside_by_horizon[4][k]);
    EXPECT_EQ(cells[kBodyVars + k].seconds, 2.0);
    EXPECT_EQ(cells[kBodyVars + k].outside, check.outside_by_horizon[19][k]);
  }
  // Every horizon with steps: 19 of the 20 (none at 1 s), in nominal steps of a 10 Hz model.
  const auto every = band_misses_at_every_step(check, 10.0);
  ASSERT_EQ(every.size(), 19u * kBodyVars);
  for (std::size_t i = 0; i < every.size(); ++i) {
    const int t = static_cast<int>(i / kBodyVars) + (i / kBodyVars >= 9 ? 1 : 0);
    EXPECT_EQ(every[i].variable, static_cast<int>(i % kBodyVars));
    EXPECT_EQ(every[i].seconds, (t + 1) / 10.0);
    EXPECT_EQ(every[i].outside, check.outside_by_horizon[static_cast<std::size_t>(t)][every[i].variable]);
    EXPECT_EQ(every[i].steps, 700);
  }
  EXPECT_EQ(every[2 * kBodyVars].seconds, 0.3);  // (2 + 1) / 10.0, not 3 * 0.1
  // 21 and 49 of 700 steps are exactly 3% and 7%, inside however the division rounds; a step fewer or more is
  // outside.
  EXPECT_TRUE(honest_misses(21.0 / 700));
  EXPECT_TRUE(honest_misses(49.0 / 700));
  EXPECT_TRUE(honest_misses(0.0455));
  EXPECT_FALSE(honest_misses(20.0 / 700));
  EXPECT_FALSE(honest_misses(50.0 / 700));
}

// A cell's misses are a binomial count: a few dozen steps cannot tell an honest band from a 0% or 10% one, a
// thousand can. Honest bands (4.55%) pass the family-wise test in at least 95% of checks of 24 cells, bands
// that miss 15% or 0.5% fail every one.
TEST(NoiseCheck, ACellIsJudgedAgainstWhatChanceGivesOnItsSteps) {
  constexpr double kAlpha = 0.01;
  EXPECT_TRUE(
      misses_consistent_with_honest(0, 30, kAlpha));  // 0% of 30: an honest band does that 25% of flights
  EXPECT_TRUE(misses_consistent_with_honest(3, 30, kAlpha));  // 10% of 30
  EXPECT_TRUE(misses_consistent_with_honest(45, 1000, kAlpha));
  EXPECT_FALSE(misses_consistent_with_honest(5, 1000, kAlpha));    // 0.5% of 1000
  EXPECT_FALSE(misses_consistent_with_honest(120, 1000, kAlpha));  // 12% of 1000
  EXPECT_FALSE(misses_consistent_with_honest(30, 30, kAlpha));
  EXPECT_TRUE(misses_consistent_with_honest(0, 0, kAlpha));  // nothing counted

  const auto checks_passed = [](double miss_rate, int steps, int checks) {
    UniformStream u(7, 0);
    int passed = 0;
    for (int c = 0; c < checks; ++c) {
      std::vector<BandMisses> cells;
      for (int cell = 0; cell < 24; ++cell) {
        int outside = 0;
        for (int i = 0; i < steps; ++i) outside += u.next() < miss_rate;
        cells.push_back({.variable = cell % kBodyVars,
                         .seconds = 0.5,
                         .outside = static_cast<double>(outside) / steps,
                         .steps = steps});
      }
      passed += cells_beyond_chance(cells).empty();
    }
    return passed;
  };
  EXPECT_GE(checks_passed(0.0455, 300, 200), 190);
  EXPECT_EQ(checks_passed(0.15, 300, 50), 0);
  EXPECT_EQ(checks_passed(0.005, 1000, 50), 0);
}

// Terms of 600 windows of 20 steps (10 Hz, reset every 2 s) whose bands `columns(h, band)` fills per step,
// and whose errors are drawn as Gaussians with those bands times the true scales.
template <typename Columns>
NoiseBandTerms drawn_terms(int sources, const NoiseScale& truth, std::uint64_t seed, Columns&& columns) {
  NoiseBandTerms terms;
  terms.sources = sources;
  const Eigen::VectorXd true_scales = terms.scales(truth);
  UniformStream rng(seed, 0);
  for (int window = 0; window < 600; ++window)
    for (int h = 0; h < 20; ++h) {
      Eigen::Matrix<double, kBodyVars, Eigen::Dynamic> band =
          Eigen::Matrix<double, kBodyVars, Eigen::Dynamic>::Zero(kBodyVars, terms.sources);
      columns(h, band);
      BodyVec error;
      for (int k = 0; k < kBodyVars; ++k)
        error[k] = std::abs(normal_quantile(rng.next())) * std::sqrt(band.row(k).dot(true_scales));
      terms.horizon.push_back(h);
      terms.error.push_back(error);
      terms.band.push_back(std::move(band));
    }
  return terms;
}

// The root mean square over the 160 cells (8 variables at each of 20 steps) of the terms' fractions outside
// +-2 sd from 4.55%, with the bands scaled by `scales` and each sd by its step's factor (none: 1).
double rms_miss(const NoiseBandTerms& terms, const Eigen::VectorXd& scales,
                const std::vector<BodyVec>& sd_factors = {}) {
  double sum = 0;
  for (int h = 0; h < 20; ++h)
    for (int k = 0; k < kBodyVars; ++k) {
      const double factor = sd_factors.empty() ? 1.0 : sd_factors[static_cast<std::size_t>(h)][k];
      int n = 0, outside = 0;
      for (std::size_t i = 0; i < terms.error.size(); ++i)
        if (terms.horizon[i] == h) {
          ++n;
          outside += terms.error[i][k] > 2 * factor * std::sqrt(terms.band[i].row(k).dot(scales)) ? 1 : 0;
        }
      sum += std::pow(static_cast<double>(outside) / n - 0.0455, 2);
    }
  return std::sqrt(sum / (20 * kBodyVars));
}

TEST(NoiseCalibration, FitGivesBackTheScalesOfErrorsDrawnWithThem) {
  const double dt = 0.1, reset_s = 2.0;
  NoiseScale truth;
  for (int k = 0; k < kBodyVars; ++k) {
    truth.process[k] = std::pow(2.0, (k % 3) - 1.0);  // 0.5, 1 or 2
    truth.measurement[k] = std::pow(2.0, 1.0 - ((k + 1) % 3));
  }
  // A model's own sources only.
  const NoiseBandTerms terms = drawn_terms(2 * kBodyVars, truth, 7, [](int h, auto& band) {
    for (int k = 0; k < kBodyVars; ++k) {
      band(k, k) = 0.01 * (h + 1);                             // a random walk's variance
      band(k, kBodyVars + k) = 0.05;                           // the log's own error
      if (k < 2) band(k, 5 + k) = 0.0005 * (h + 1) * (h + 1);  // an attitude integrating a rate
    }
  });
  const NoiseScale fitted = fit_noise_scale(terms, dt, reset_s);
  for (int k = 0; k < kBodyVars; ++k) {
    const char* name = kBodyVarNames[static_cast<std::size_t>(k)];
    EXPECT_NEAR(std::log(fitted.process[k] / truth.process[k]), 0, std::log(1.25)) << name;
    EXPECT_NEAR(std::log(fitted.measurement[k] / truth.measurement[k]), 0, std::log(1.25)) << name;
  }
  // The variables a move touches (here the rates' sources reach the attitudes too) evaluated on two threads
  // give the same scales to the bit.
  ThreadPool pool(2);
  const NoiseScale threaded = fit_noise_scale(terms, dt, reset_s, &pool);
  EXPECT_EQ(threaded.process, fitted.process);
  EXPECT_EQ(threaded.measurement, fitted.measurement);
}

// Errors with a large white logged error in half the variables, which the model's own sources cannot shape
// (its AR(1) logged error grows from 0 after a reset, the process noise from one step's): with the white
// sources the fit adds it where it was drawn, hardly any where it was not, and its bands miss near 4.55% at
// every step, much nearer than the fit without them.
TEST(NoiseCalibration, FitAddsTheWhiteLoggedErrorTheErrorsHave) {
  const double dt = 0.1, reset_s = 2.0;
  NoiseScale truth;
  for (int k = 0; k < kBodyVars; ++k) truth.measurement_white[k] = k % 2 == 0 ? 2.0 : 0.0;
  const NoiseBandTerms terms = drawn_terms(3 * kBodyVars, truth, 11, [](int h, auto& band) {
    for (int k = 0; k < kBodyVars; ++k) {
      band(k, k) = 0.01 * (h + 1);                                 // a random walk's variance
      band(k, kBodyVars + k) = 0.05 * (1 - std::pow(0.9, h + 1));  // the log's own AR(1) error
      band(k, 2 * kBodyVars + k) = 0.05;                           // a white logged error of 0.05
    }
  });
  NoiseBandTerms own = terms;  // the same errors, without the white sources
  own.sources = 2 * kBodyVars;
  for (auto& band : own.band) band = band.leftCols(own.sources).eval();
  const NoiseScale fitted = fit_noise_scale(terms, dt, reset_s), without = fit_noise_scale(own, dt, reset_s);
  const double with_white = rms_miss(terms, terms.scales(fitted)),
               own_only = rms_miss(terms, terms.scales(without));
  EXPECT_LT(with_white, 0.5 * own_only) << with_white << " against " << own_only;
  for (int k = 0; k < kBodyVars; ++k) {
    const char* name = kBodyVarNames[static_cast<std::size_t>(k)];
    if (truth.measurement_white[k] > 0)
      EXPECT_NEAR(std::log(fitted.measurement_white[k] / truth.measurement_white[k]), 0, std::log(1.5))
          << name;
    else  // below a tenth of the first step's variance
      EXPECT_LT(fitted.measurement_white[k] * 0.05, 0.1 * (0.01 + 0.005)) << name;
  }
  ThreadPool pool(2);
  EXPECT_EQ(fit_noise_scale(terms, dt, reset_s, &pool).measurement_white, fitted.measurement_white);
}

// Errors whose sd the sources put right except at some steps after the reset: half the variables' errors are
// half their bands' sd at the first step and 1.4 times it at steps 5-10. The factors give that shape back
// where it was drawn, stay near 1 where none was (their sampling noise shrunk away), and with them the bands
// miss near 4.55% at every step.
TEST(NoiseCalibration, HorizonSdFactorsGiveBackTheShapeTheSourcesMissed) {
  const double dt = 0.1, reset_s = 2.0;
  NoiseScale truth;
  for (int k = 0; k < kBodyVars; ++k) truth.process[k] = 1.5;
  const auto drawn_factor = [](int h, int k) {
    if (k % 2 == 1) return 1.0;
    return h == 0 ? 0.5 : h >= 4 && h <= 9 ? 1.4 : 1.0;
  };
  NoiseBandTerms terms = drawn_terms(kBodyVars, truth, 13, [](int h, auto& band) {
    for (int k = 0; k < kBodyVars; ++k) band(k, k) = 0.01 * (h + 1);
  });
  for (std::size_t i = 0; i < terms.error.size(); ++i)
    for (int k = 0; k < kBodyVars; ++k) terms.error[i][k] *= drawn_factor(terms.horizon[i], k);
  const std::vector<BodyVec> factors = fit_horizon_sd_factors(terms, truth, dt, reset_s);
  ASSERT_EQ(factors.size(), 20u);
  for (int h = 0; h < 20; ++h)
    for (int k = 0; k < kBodyVars; ++k) {
      const double f = factors[static_cast<std::size_t>(h)][k];
      // Steps next to a change of the drawn factor pool both sides of it.
      const bool edge = k % 2 == 0 && (h == 3 || h == 4 || h == 9 || h == 10);
      if (edge) continue;
      EXPECT_NEAR(std::log(f / drawn_factor(h, k)), 0, std::log(1.12))
          << kBodyVarNames[static_cast<std::size_t>(k)] << " step " << h + 1 << ": " << f;
    }
  // Where none was drawn the percentiles' sampling noise is shrunk away: most factors are exactly 1 (53 of
  // 80), and their logs are 0.5% off on average (measured; 1.9% without the shrinking, the percentiles' own
  // noise).
  double log_off = 0;
  int cells = 0, ones = 0;
  for (int h = 0; h < 20; ++h)
    for (int k = 1; k < kBodyVars; k += 2) {
      const double f = factors[static_cast<std::size_t>(h)][k];
      log_off += std::abs(std::log(f));
      ++cells;
      ones += f == 1.0 ? 1 : 0;
    }
  EXPECT_LT(log_off / cells, 0.01) << log_off / cells;
  EXPECT_GT(ones, cells / 2) << ones << " of " << cells;
  // Measured: 1.0 points with them, 4.7 without; a fraction's sampling error over 600 windows is 0.85 points.
  const Eigen::VectorXd scales = terms.scales(truth);
  const double with_factors = rms_miss(terms, scales, factors), without = rms_miss(terms, scales);
  EXPECT_LT(with_factors, 0.0125) << with_factors;
  EXPECT_LT(with_factors, 0.3 * without) << with_factors << " against " << without;
}

// The noise check multiplies each sd by the model's factor at its step after the reset, and the steps past
// the factors' last keep the last: with factors of 1 the check is the plain one, bit for bit; with a huge
// factor from the fourth step on no error there is outside, and the first three steps are as before.
// Several hold-out flights as one check (heli identify --noise-check-logs): every cell is the fraction over
// all the flights' steps, so a flight counted twice changes no fraction, and two flights give the mean of
// their fractions weighted by their steps.
TEST(NoiseCheck, PooledChecksWeighEachFlightByItsSteps) {
  ThreadPool pool(2);
  const IdentifiedModel model = identify(logs().train, small_search(), pool);
  const NoiseCheck test = noise_check(model, logs().test, 2.0, 10.0, pool);
  const NoiseCheck train = noise_check(model, logs().train, 2.0, 0.0, pool);
  ASSERT_GT(test.steps, 0);
  ASSERT_NE(test.steps, train.steps);

  const NoiseCheck alone = pooled_noise_check({test});
  EXPECT_EQ(alone.outside_by_horizon, test.outside_by_horizon);
  EXPECT_EQ(alone.outside_fraction, test.outside_fraction);

  const NoiseCheck twice = pooled_noise_check({test, test});
  EXPECT_EQ(twice.steps, 2 * test.steps);
  EXPECT_EQ(twice.outside_by_horizon, test.outside_by_horizon);  // bit for bit: the same quotients
  EXPECT_EQ(twice.outside_fraction, test.outside_fraction);
  EXPECT_EQ(twice.normalized_errors.size(), 2 * test.normalized_errors.size());
  EXPECT_EQ(twice.time, test.time);  // the first flight's trace, once

  const NoiseCheck both = pooled_noise_check({test, train});
  ASSERT_EQ(both.steps_by_horizon.size(), test.steps_by_horizon.size());
  int differ = 0;
  for (std::size_t t = 0; t < both.steps_by_horizon.size(); ++t) {
    const int n_test = test.steps_by_horizon[t], n_train = train.steps_by_horizon[t];
    EXPECT_EQ(both.steps_by_horizon[t], n_test + n_train);
    for (int k = 0; k < kBodyVars; ++k) {
      // Counts are whole numbers of steps.
      const double weighted =
          test.outside_by_horizon[t][k] * n_test + train.outside_by_horizon[t][k] * n_train;
      EXPECT_NEAR(both.outside_by_horizon[t][k] * (n_test + n_train), weighted, 1e-9) << t << " " << k;
      EXPECT_NEAR(weighted, std::round(weighted), 1e-9);
      differ += test.outside_by_horizon[t][k] != train.outside_by_horizon[t][k];
    }
  }
  EXPECT_GT(differ, 40);  // of 160 cells: the flights' fractions differ, so the weights are tested
  EXPECT_EQ(both.steps, test.steps + train.steps);
  for (int k = 0; k < kBodyVars; ++k)
    EXPECT_NEAR(both.outside_fraction[k] * both.steps,
                test.outside_fraction[k] * test.steps + train.outside_fraction[k] * train.steps, 1e-9);

  // A check with another reset has other cells: refused, not mixed.
  const NoiseCheck other_reset = noise_check(model, logs().test, 1.0, 0.0, pool);
  EXPECT_THROW(pooled_noise_check({test, other_reset}), std::invalid_argument);
  EXPECT_THROW(pooled_noise_check({}), std::invalid_argument);
}

TEST(NoiseCheck, BandsCarryTheModelsHorizonSdFactors) {
  ThreadPool pool(2);
  IdentifyOptions o = small_search();
  o.noise = NoiseModel::kAr1;
  IdentifiedModel model = identify(logs().train, o, pool);
  ASSERT_TRUE(model.horizon_sd_factors().empty());
  const NoiseCheck plain = noise_check(model, logs().test, 2.0, 0.0, pool);
  model.set_horizon_sd_factors(std::vector<BodyVec>(20, BodyVec::Ones()));
  const NoiseCheck ones = noise_check(model, logs().test, 2.0, 0.0, pool);
  EXPECT_EQ(ones.outside_by_horizon, plain.outside_by_horizon);
  EXPECT_EQ(ones.normalized_errors, plain.normalized_errors);
  std::vector<BodyVec> factors(4, BodyVec::Ones());
  factors[3].setConstant(1e9);
  model.set_horizon_sd_factors(factors);
  const NoiseCheck wide = noise_check(model, logs().test, 2.0, 0.0, pool);
  ASSERT_EQ(wide.outside_by_horizon.size(), 20u);
  for (std::size_t t = 0; t < 20; ++t) {
    if (t < 3)
      EXPECT_EQ(wide.outside_by_horizon[t], plain.outside_by_horizon[t]) << t;
    else
      EXPECT_EQ(wide.outside_by_horizon[t], BodyVec::Zero()) << t;
  }
  // Some of those steps were outside without the factor: the check has errors to hide.
  EXPECT_GT(plain.outside_by_horizon[10].sum(), 0.05);
}

// A check that counted no step (every window's first local fit singular) leaves every scale at 1.
TEST(NoiseCalibration, NoStepsCountedLeavesTheScalesAtOne) {
  NoiseBandTerms terms;
  terms.sources = 2 * kBodyVars;
  const NoiseScale fitted = fit_noise_scale(terms, 0.1, 2.0);
  EXPECT_EQ(fitted.process, BodyVec::Ones());
  EXPECT_EQ(fitted.measurement, BodyVec::Ones());
  terms.sources = 3 * kBodyVars;  // and adds no white logged error
  EXPECT_EQ(fit_noise_scale(terms, 0.1, 2.0).measurement_white, BodyVec::Zero());
  // nor factors other than 1
  EXPECT_EQ(fit_horizon_sd_factors(terms, NoiseScale{}, 0.1, 2.0), std::vector<BodyVec>(20, BodyVec::Ones()));
}

// scaled_noise moves each part of the variance by its own scale: the process part the model flies (white and
// AR(1)) by the process scale, the logged error's (AR(1) and white) by the measurement scale, and adds the
// white logged error measurement_white asks for.
TEST(NoiseCalibration, ScaledNoiseScalesEachPartByItsOwnScale) {
  BodyVec sigma2;
  NoiseCorrelation c;
  NoiseScale scale;
  for (int k = 0; k < kBodyVars; ++k) {
    sigma2[k] = 0.1 * (k + 1);
    c.share[k] = 0.3;
    c.rho[k] = 0.9;
    c.measurement_share[k] = 0.2;
    c.measurement_rho[k] = 0.5;
    c.measurement_persistence[k] = 0.95;
    c.measurement_white_share[k] = 0.1;
    scale.process[k] = 0.5 + k;
    scale.measurement[k] = 4.0 / (k + 1);
    scale.measurement_white[k] = 0.25 * k;
  }
  const auto [s2, out] = scaled_noise(sigma2, c, scale);
  for (int k = 0; k < kBodyVars; ++k) {
    EXPECT_NEAR(out.share[k] * s2[k], scale.process[k] * 0.3 * sigma2[k], 1e-15);
    EXPECT_NEAR(out.white_share(k) * s2[k], scale.process[k] * 0.4 * sigma2[k], 1e-14);
    EXPECT_NEAR(out.measurement_variance(k, s2[k]),
                scale.measurement[k] * c.measurement_variance(k, sigma2[k]), 1e-15);
    // sigma_w^2 = 0.1 sigma2 / (1 + 0.95^2) scaled, plus 0.25 k sigma2.
    EXPECT_NEAR(out.measurement_white_variance(k, s2[k]),
                scale.measurement[k] * 0.1 * sigma2[k] / (1 + 0.95 * 0.95) + 0.25 * k * sigma2[k], 1e-15);
    EXPECT_EQ(out.rho[k], c.rho[k]);
  }
  // A process scale far below the measurement's leaves a white part of (nearly) 0, never below it: the
  // simulator takes its square root.
  // (With these shares the plain quotients leave -1e-16 for 2 of the 8.)
  for (int k = 0; k < kBodyVars; ++k) {
    sigma2[k] = 0.1;
    scale.process[k] = 1e-2;
    scale.measurement[k] = 30;
    c.share[k] = 0.001 + 0.0007 * (k + 1);
    c.measurement_share[k] = 1 - c.share[k];
    c.measurement_white_share[k] = 0;
  }
  const auto [s2_low, low] = scaled_noise(sigma2, c, scale);
  for (int k = 0; k < kBodyVars; ++k) EXPECT_GE(low.white_share(k), 0.0) << k;
}

// calibrate_noise: on the training log itself, with windows every calibration_spacing_s each predicted by
// fits that leave it and calibration_leave_out_s / 2 on either side out, the calibrated model's fractions of
// steps outside +-2 sd per variable and model step after a reset (its sd factors by horizon included) are
// nearer a Gaussian's 4.55% than the model's as identified (root mean square over the 160 cells), and the
// model keeps the fitted scales.
TEST(NoiseCalibration, CalibratedBandsFitTheTrainingLogsErrorsBetter) {
  ThreadPool pool(2);
  IdentifyOptions o = small_search();
  o.noise = NoiseModel::kAr1Measurement;
  const IdentifiedModel plain = identify(logs().train, o, pool);
  o.calibrate_noise = true;
  IdentifyReport report;
  const IdentifiedModel calibrated = identify(logs().train, o, pool, &report);
  const auto [sigma2, correlation] =
      scaled_noise(plain.sigma2(), plain.noise_correlation(), report.noise_scale);
  for (int k = 0; k < kBodyVars; ++k) {
    EXPECT_DOUBLE_EQ(calibrated.sigma2()[k], sigma2[k]);
    EXPECT_DOUBLE_EQ(calibrated.noise_correlation().measurement_share[k], correlation.measurement_share[k]);
    EXPECT_DOUBLE_EQ(report.noise_inflation[k], std::sqrt(sigma2[k] / plain.sigma2()[k]));
  }
  const auto training_rms_miss = [&](const IdentifiedModel& m) {
    const NoiseBandTerms terms =
        noise_band_terms(m, logs().train, 2.0, o.calibration_leave_out_s, pool, o.calibration_spacing_s);
    return rms_miss(terms, terms.scales(NoiseScale{}), m.horizon_sd_factors());
  };
  // Measured: 3.4 points before, 0.7 after (1.2 without the sd factors by horizon, 1.4 without the white
  // logged error the fit may add either, 1.5 with the fit of three spans of the reset window).
  const double before = training_rms_miss(plain), after = training_rms_miss(calibrated);
  EXPECT_LT(after, 0.3 * before) << "before " << before << ", after " << after;
  ASSERT_EQ(calibrated.horizon_sd_factors().size(), 20u);
}

// What calibration writes, its file gives back (the loader's check of the shares is the simulator's: a white
// part not below 0), and the simulator flies it with finite noise.
TEST(NoiseCalibration, ACalibratedModelRoundTripsItsFileAndFlies) {
  ThreadPool pool(2);
  IdentifyOptions o = small_search();
  o.noise = NoiseModel::kAr1Measurement;
  o.calibrate_noise = true;
  const auto model = std::make_shared<const IdentifiedModel>(identify(logs().train, o, pool));
  const nlohmann::json file = model->to_json();
  EXPECT_EQ(IdentifiedModel::from_json(file).to_json(), file);
  // The calibration added a white logged error here, and the file keeps it. A share beyond what the process
  // and the AR(1) logged error leave is refused, naming the field.
  ASSERT_TRUE(file.at("noise").contains("measurement_white_share")) << file.at("noise").dump();
  ASSERT_TRUE(file.contains("horizon_sd_factors"));
  {
    nlohmann::json bad = file;
    bad["horizon_sd_factors"][2][5] = 0.0;
    try {
      (void)IdentifiedModel::from_json(bad);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "model.json: horizon_sd_factors[2][5]: expected a number > 0, got 0.0");
    }
  }
  {
    nlohmann::json bad = file;
    const double left =
        1 - file["noise"]["share"][3].get<double>() - file["noise"]["measurement_share"][3].get<double>();
    bad["noise"]["measurement_white_share"][3] = left + 0.01;
    try {
      (void)IdentifiedModel::from_json(bad);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(
                    "model.json: noise.measurement_white_share[3]: expected a number in [0, ", 0),
                0u)
          << e.what();
    }
  }
  LearnedModelOptions lo;
  lo.start = logs().train.states[400];
  const LearnedHeliModel sim(model, lo);
  std::vector<double> p0(static_cast<std::size_t>(sim.initial_noise_dim()), 0.5);
  auto s = sim.initial_state(p0);
  UniformStream rng(3, 0);
  std::vector<double> p(static_cast<std::size_t>(sim.noise_dim()));
  for (int t = 0; t < 100; ++t) {
    for (double& u : p) u = rng.next();
    s = sim.step(s, logs().train.controls[static_cast<std::size_t>(400 + t)], p);
    ASSERT_FALSE(s.crashed) << "step " << t;
    for (double v : s.sim.world) ASSERT_TRUE(std::isfinite(v)) << "step " << t;
  }
}

}  // namespace
