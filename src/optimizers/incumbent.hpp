#pragma once
// Where a search that moves one theta uphill stands (gradient ascent, hill climbing): theta, its U-hat and
// the step length, started from the first theta or resumed from a checkpoint's "theta", "value" and "step".
#include <nlohmann/json.hpp>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

struct Incumbent {
  Theta x;
  double value = 0.0;
  double step = 0.0;

  // The first theta, evaluated and offered as the best so far.
  void Start(const Theta& first, double initial_step, Objective& objective, RunProgress& run) {
    x = first;
    value = objective.evaluate(x);
    run.AddEvaluations(1);
    run.set_initial_value(value);
    run.Offer(x, value);
    step = initial_step;
  }

  void Resume(const nlohmann::json& state, const ParameterSpec& spec) {
    x = VectorFromJson(StateField(state, "theta"), "state.theta");
    if (!spec.contains(x)) throw InputError("checkpoint state.theta: expected a theta inside the bounds");
    value = DoubleFromJson(StateField(state, "value"), "state.value");
    step = DoubleFromJson(StateField(state, "step"), "state.step");
  }

  nlohmann::json State() const {
    return nlohmann::json{
        {"theta", VectorToJson(x)}, {"value", DoubleToJson(value)}, {"step", DoubleToJson(step)}};
  }
};

}  // namespace pegasus
