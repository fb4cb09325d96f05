// Wind in the learned model's scenarios (issue 53 item 2; sysid::Disturbance): calm is the model as it was,
// bit for bit and draw for draw; a steady wind is the calm model queried at the airspeed; the per-scenario
// wind and the AR(1) gusts have the stated statistics; the envelope's limits crash the model at its penalty.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "pegasus/random/counter_rng.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "pilot_logs.hpp"

namespace pegasus::sysid::wind_test {
namespace {

namespace logged = heli::logged;

std::shared_ptr<const IdentifiedModel> wind_model() {
  static const auto model = [] {
    IdentifyOptions o = test::small_search();
    o.scale_grid = {2};
    o.coordinate_passes = 0;
    ThreadPool pool(1);
    return std::make_shared<const IdentifiedModel>(identify(test::logs().train, o, pool));
  }();
  return model;
}

LearnedModelOptions options_at(std::size_t row) {
  LearnedModelOptions lo;
  lo.start = test::logs().train.states[row];
  return lo;
}

std::vector<double> uniforms(int n, double first) {
  std::vector<double> p(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) p[static_cast<std::size_t>(i)] = std::fmod(first + 0.173 * i, 0.9) + 0.05;
  return p;
}

TEST(LearnedModelWind, CalmIsTheModelAsItWasAndASteadyWindIsTheAirspeedQuery) {
  const auto model = wind_model();
  const std::size_t row = 600;
  const LearnedModelOptions calm = options_at(row);
  LearnedModelOptions windy = calm;
  windy.disturbance.wind = {2.0, -1.5, 0.3};
  const LearnedHeliModel a(model, calm), b(model, windy);
  EXPECT_EQ(b.noise_dim(), a.noise_dim());  // a steady wind draws nothing
  EXPECT_EQ(b.initial_noise_dim(), a.initial_noise_dim());
  const auto p0 = uniforms(a.initial_noise_dim(), 0.31);
  const auto p = uniforms(a.noise_dim(), 0.57);
  const auto controls = test::logs().train.controls[row];
  // In the wind, at ground velocity v; calm, at v - wind: the same airspeed, so the same body changes.
  auto in_wind = b.initial_state(p0);
  auto calm_air = a.initial_state(p0);
  for (std::size_t i = 0; i < 3; ++i) calm_air.sim.world[logged::xdot + i] -= windy.disturbance.wind[i];
  const auto n_wind = b.step(in_wind, controls, p), n_calm = a.step(calm_air, controls, p);
  ASSERT_FALSE(n_wind.crashed || n_calm.crashed);
  // Attitude and rates as the calm model's; velocity the calm one's plus the wind; position blown wind x dt.
  for (std::size_t i = 0; i < static_cast<std::size_t>(kLogStates); ++i) {
    double expected = n_calm.sim.world[i];
    if (i >= logged::xdot && i < logged::xdot + 3) expected += windy.disturbance.wind[i - logged::xdot];
    if (i < logged::x + 3)
      expected += in_wind.sim.world[i] - calm_air.sim.world[i] + windy.disturbance.wind[i] * calm.dt;
    EXPECT_NEAR(n_wind.sim.world[i], expected, 1e-12) << i;
  }
  // Calm stated explicitly: the same steps bit for bit.
  LearnedModelOptions zero = calm;
  zero.disturbance = Disturbance{.wind = {0, 0, 0}, .wind_sigma = 0, .gust_sigma = 0, .gust_tau_s = 7};
  const LearnedHeliModel c(model, zero);
  auto s1 = a.initial_state(p0), s2 = c.initial_state(p0);
  for (int t = 0; t < 20; ++t) {
    s1 = a.step(s1, test::logs().train.controls[row + static_cast<std::size_t>(t)], p);
    s2 = c.step(s2, test::logs().train.controls[row + static_cast<std::size_t>(t)], p);
  }
  EXPECT_EQ(s1.sim.world, s2.sim.world);
}

TEST(LearnedModelWind, ScenarioWindAndGustsHaveTheirStatedStatistics) {
  const auto model = wind_model();
  LearnedModelOptions lo = options_at(700);
  lo.disturbance = {.wind = {1, 0, 0}, .wind_sigma = 0.5, .gust_sigma = 0.8, .gust_tau_s = 1.5};
  const LearnedHeliModel m(model, lo);
  const LearnedHeliModel calm(model, options_at(700));
  ASSERT_EQ(m.noise_dim(), calm.noise_dim() + 3);  // the gusts' draws after the model's own
  ASSERT_EQ(m.initial_noise_dim(), calm.initial_noise_dim() + 5);
  // Many scenarios' starts and first steps, with counter-based uniforms as a scenario set draws them.
  const int n = 1500;
  const double rho = std::exp(-lo.dt / lo.disturbance.gust_tau_s);
  const CounterRng rng(11);
  std::vector<double> north, gust0, gust1_residual;
  for (int i = 0; i < n; ++i) {
    std::vector<double> p0(static_cast<std::size_t>(m.initial_noise_dim()));
    std::vector<double> p(static_cast<std::size_t>(m.noise_dim()));
    const auto u = static_cast<std::uint32_t>(i);
    for (std::size_t k = 0; k < p0.size(); ++k)
      p0[k] = rng.uniform2(RngDomain::kStream, u, 0, static_cast<std::uint32_t>(k))[0];
    for (std::size_t k = 0; k < p.size(); ++k)
      p[k] = rng.uniform2(RngDomain::kStream, u, 1, static_cast<std::uint32_t>(k))[0];
    const auto s = m.initial_state(p0);
    const auto next = m.step(s, test::logs().train.controls[700], p);
    north.push_back(s.wind[0]);
    gust0.push_back(s.gust[1]);
    gust1_residual.push_back(next.gust[1] - rho * s.gust[1]);
    EXPECT_EQ(s.wind[2], 0);  // the drawn wind is horizontal
  }
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  };
  const auto sd = [&](const std::vector<double>& v) {
    const double m0 = mean(v);
    double ss = 0;
    for (double x : v) ss += (x - m0) * (x - m0);
    return std::sqrt(ss / (v.size() - 1));
  };
  // 1500 draws: the standard error of a standard deviation is about 2%, of a mean sd / 39.
  EXPECT_NEAR(mean(north), 1.0, 4 * 0.5 / std::sqrt(n));
  EXPECT_NEAR(sd(north), 0.5, 0.5 * 0.08);
  EXPECT_NEAR(sd(gust0), 0.8, 0.8 * 0.08);  // stationary from the start
  EXPECT_NEAR(sd(gust1_residual), 0.8 * std::sqrt(1 - rho * rho), 0.8 * std::sqrt(1 - rho * rho) * 0.08);
}

TEST(LearnedModelWind, EnvelopeLimitsCrashTheModelAtItsPenalty) {
  const auto model = wind_model();
  LearnedModelOptions lo = options_at(650);
  lo.max_speed_mps = 0.5;
  lo.crash_reward = -123;
  const LearnedHeliModel m(model, lo);
  auto s = m.initial_state(uniforms(m.initial_noise_dim(), 0.5));
  s.sim.world[logged::xdot] = 3;  // 3 m/s: past the 0.5 m/s limit after one step
  const auto p = uniforms(m.noise_dim(), 0.5);
  const auto next = m.step(s, test::logs().train.controls[650], p);
  EXPECT_TRUE(next.crashed);
  EXPECT_EQ(m.reward(s, {0, 0, 0, 0}, next), -123);
  LearnedModelOptions far = options_at(650);
  far.max_position_error_m = 0.01;
  const LearnedHeliModel f(model, far);
  auto moved = f.initial_state(uniforms(f.initial_noise_dim(), 0.5));
  moved.sim.world[logged::x] += 1;
  EXPECT_TRUE(f.step(moved, test::logs().train.controls[650], p).crashed);
  LearnedModelOptions wide = options_at(650);  // limits far beyond the state: no crash
  wide.max_speed_mps = wide.max_position_error_m = wide.max_rate_radps = 100;
  const LearnedHeliModel w(model, wide);
  EXPECT_FALSE(
      w.step(w.initial_state(uniforms(w.initial_noise_dim(), 0.5)), test::logs().train.controls[650], p)
          .crashed);
}

}  // namespace
}  // namespace pegasus::sysid::wind_test
