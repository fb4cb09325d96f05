#pragma once
// The deterministic objective theta -> U-hat(theta) that optimizers maximise (ARCHITECTURE.md). Type
// erasure of model and policy happens once, where a problem becomes an Objective, never per step.
#include <functional>
#include <span>
#include <vector>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

class Objective {
 public:
  virtual ~Objective() = default;
  virtual const ParameterSpec& parameters() const = 0;
  // U-hat(theta). Deterministic: the same theta always gives the same bits.
  virtual double evaluate(std::span<const double> theta) = 0;
  // values[k] = evaluate(thetas[k]). Implementations run the batch in parallel (a numerical gradient is
  // 2n evaluations) but must return exactly what evaluate would.
  virtual void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) {
    for (std::size_t k = 0; k < thetas.size(); ++k) values[k] = evaluate(thetas[k]);
  }
};

// An Objective from a plain function, for tests and small problems.
class FunctionObjective final : public Objective {
 public:
  FunctionObjective(ParameterSpec spec, std::function<double(std::span<const double>)> f)
      : spec_(std::move(spec)), f_(std::move(f)) {}
  const ParameterSpec& parameters() const override { return spec_; }
  double evaluate(std::span<const double> theta) override { return f_(theta); }

 private:
  ParameterSpec spec_;
  std::function<double(std::span<const double>)> f_;
};

// Another objective's values passed through unchanged, each evaluation or batch told to `observer` after it
// ran (a progress display's count and best U-hat): the search is the same with or without it.
class ObservedObjective final : public Objective {
 public:
  using Observer = std::function<void(std::span<const double> values)>;
  ObservedObjective(Objective& inner, Observer observer) : inner_(inner), observer_(std::move(observer)) {}
  const ParameterSpec& parameters() const override { return inner_.parameters(); }
  double evaluate(std::span<const double> theta) override {
    const double v = inner_.evaluate(theta);
    if (observer_) observer_(std::span<const double>(&v, 1));
    return v;
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    inner_.evaluate_batch(thetas, values);
    if (observer_) observer_(values.first(thetas.size()));
  }

 private:
  Objective& inner_;
  Observer observer_;
};

}  // namespace pegasus
