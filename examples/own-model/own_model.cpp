// Your own model, a program policy and an optimizer: a cart on a rail pushed by noisy wind, held at x = 0
// by a PD controller whose two gains PEGASUS tunes on 20 fixed scenarios (thesis §4.4).
#include <array>
#include <cstdio>
#include <memory>
#include <pegasus/pegasus.hpp>

struct Cart {  // state (x, v); the wind is uniform in [-1, 1] N per 0.1 s step
  using State = std::array<double, 2>;
  using Action = std::array<double, 1>;
  using Observation = State;
  int state_dim() const { return 2; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 1; }
  pegasus::ActionSpace action_space() const { return pegasus::ActionSpace::box({-5}, {5}); }
  State initial_state(std::span<const double> p0) const { return {4 * p0[0] - 2, 0}; }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    const double force = std::clamp(a[0], -5.0, 5.0) + (2 * p[0] - 1);
    return {s[0] + 0.1 * s[1], s[1] + 0.1 * force};
  }
  bool terminal(const State&) const { return false; }
  Observation observe(const State& s) const { return s; }
  double reward(const State& s, const Action& a) const { return -s[0] * s[0] - 0.01 * a[0] * a[0]; }
};

int main() {
  auto pd = pegasus::make_program_policy<Cart::State>(
      pegasus::ParameterSpec({{.name = "kp", .initial = 0.1, .lower = 0, .upper = 50},
                              {.name = "kd", .initial = 0.1, .lower = 0, .upper = 50}}),
      [](std::span<const double> k, const Cart::State& s) {
        return Cart::Action{-k[0] * s[0] - k[1] * s[1]};
      });
  pegasus::ScenarioSet scenarios(
      {.seed = 7, .count = 20, .horizon = 100, .noise_dim = 1, .initial_noise_dim = 1});
  pegasus::PegasusObjective objective(
      pegasus::PegasusEvaluator(Cart{}, pd, scenarios, {.gamma = 0.99, .horizon = 100}),
      std::make_shared<pegasus::ThreadPool>(2));
  pegasus::OptimizerOptions options;  // CMA-ES; "gradient", "hill-climb", "bobyqa", ... work the same way
  options.cmaes.max_iterations = 50;
  pegasus::Theta theta;  // empty: start from the spec's initial values
  pegasus::OptimizerSummary summary;
  pegasus::Solve(options, objective, &theta, &summary);
  std::printf("%s\nkp %.4g kd %.4g U-hat %.6g (start %.6g)\n", summary.BriefReport().c_str(), theta[0],
              theta[1], summary.best_value, summary.initial_value);
  return summary.best_value > summary.initial_value ? 0 : 1;
}
