#pragma once
// Objectives with known maxima, for the optimizer tests and benchmarks, and an Objective decorator that
// counts how an optimizer called it.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/optimizers/objective.hpp"

namespace pegasus {

// n parameters x0, x1, ... starting at `initial` inside the box [-bound, bound]^n.
inline ParameterSpec BoxSpec(std::size_t n, double initial, double bound) {
  ParameterSpec spec;
  for (std::size_t i = 0; i < n; ++i)
    spec.add({.name = "x" + std::to_string(i), .initial = initial, .lower = -bound, .upper = bound});
  return spec;
}

// Three parameters whose useful changes (scales) are 0.01, 1 and 100 apart: a test that an optimizer works
// in scaled units.
inline ParameterSpec ThreeScaleSpec() {
  return ParameterSpec(
      {{.name = "small", .initial = 0.0, .lower = -1.0, .upper = 1.0, .scale = 0.01},
       {.name = "unit", .initial = 0.0, .lower = -10.0, .upper = 10.0, .scale = 1.0},
       {.name = "large", .initial = 0.0, .lower = -1000.0, .upper = 1000.0, .scale = 100.0}});
}

// Rosenbrock's classic start (-1.2, 1) inside [-bound, bound]^2.
inline ParameterSpec RosenbrockSpec(double bound = 5.0) {
  return ParameterSpec({{.name = "x", .initial = -1.2, .lower = -bound, .upper = bound},
                        {.name = "y", .initial = 1.0, .lower = -bound, .upper = bound}});
}

// Starts Rastrigin's function on its local maximum near (3, 3) inside its usual box [-5.12, 5.12]^2; the
// global maximum is at the origin.
inline ParameterSpec RastriginSpec() {
  return ParameterSpec({{.name = "x", .initial = 3.0, .lower = -5.12, .upper = 5.12},
                        {.name = "y", .initial = 3.0, .lower = -5.12, .upper = 5.12}});
}

// U(theta) = top - sum_i ((theta_i - peak_i) / width_i)^2: a concave quadratic whose curvature differs per
// parameter, maximal (= top) at `peak` when the peak lies inside the bounds.
inline FunctionObjective ConcaveQuadratic(ParameterSpec spec, Theta peak, Theta width, double top = 0.0) {
  return FunctionObjective(std::move(spec), [peak = std::move(peak), width = std::move(width),
                                             top](std::span<const double> theta) {
    double sum = 0.0;
    for (std::size_t i = 0; i < theta.size(); ++i) {
      const double d = (theta[i] - peak[i]) / width[i];
      sum += d * d;
    }
    return top - sum;
  });
}

// U(theta) = -sum_i [100 (theta_{i+1} - theta_i^2)^2 + (1 - theta_i)^2]: the negated Rosenbrock function,
// maximal (= 0) at (1, ..., 1) at the end of a long curved valley.
inline FunctionObjective NegatedRosenbrock(ParameterSpec spec) {
  return FunctionObjective(std::move(spec), [](std::span<const double> theta) {
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < theta.size(); ++i) {
      const double a = theta[i + 1] - theta[i] * theta[i];
      const double b = 1.0 - theta[i];
      sum += 100.0 * a * a + b * b;
    }
    return -sum;
  });
}

// U(theta) = -sum_i [theta_i^2 - 10 cos(2 pi theta_i) + 10]: the negated Rastrigin function, with a
// local maximum near every integer point and the global maximum 0 at the origin.
inline FunctionObjective NegatedRastrigin(ParameterSpec spec) {
  return FunctionObjective(std::move(spec), [](std::span<const double> theta) {
    double sum = 0.0;
    for (const double t : theta) sum += t * t - 10.0 * std::cos(2.0 * std::numbers::pi * t) + 10.0;
    return -sum;
  });
}

// Forwards to another Objective, counting calls: how many evaluate and evaluate_batch calls, the size of
// each batch, and the total number of thetas evaluated.
class CountingObjective final : public Objective {
 public:
  explicit CountingObjective(Objective& inner) : inner_(inner) {}
  const ParameterSpec& parameters() const override { return inner_.parameters(); }
  double evaluate(std::span<const double> theta) override {
    ++evaluate_calls;
    ++thetas_evaluated;
    return inner_.evaluate(theta);
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    batch_sizes.push_back(thetas.size());
    thetas_evaluated += static_cast<std::int64_t>(thetas.size());
    inner_.evaluate_batch(thetas, values);
  }

  std::int64_t evaluate_calls = 0;
  std::int64_t thetas_evaluated = 0;
  std::vector<std::size_t> batch_sizes;

 private:
  Objective& inner_;
};

}  // namespace pegasus
