// The hover task of thesis §5.3 from Python: its training options, U-hat of the hover policy class on the
// ground truth or the identified model (HoverProblem), and the starts and rewards derived from a model.
#include "heli_hover.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <memory>

#include "builtin_problem.hpp"
#include "heli_batch.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/quadrotor.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::python {

namespace {

using heli::Aircraft;
using heli::HoverPolicy;
using heli::HoverReward;
using heli::HoverTask;
using heli::SetPoint;
using sysid::LearnedHeliModel;

// U-hat of the hover policy class on a helicopter model, with its per-scenario returns.
class HoverProblemObject final : public Objective {
 public:
  using Returns = std::function<std::vector<double>(const Theta&)>;
  HoverProblemObject(std::unique_ptr<Objective> inner, Returns returns)
      : inner_(std::move(inner)), returns_(std::move(returns)) {}
  const ParameterSpec& parameters() const override { return inner_->parameters(); }
  double evaluate(std::span<const double> theta) override { return inner_->evaluate(theta); }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    inner_->evaluate_batch(thetas, values);
  }
  std::vector<double> returns(const Theta& theta) const { return returns_(theta); }

 private:
  std::unique_ptr<Objective> inner_;
  Returns returns_;
};

template <class M>
std::unique_ptr<HoverProblemObject> hover_problem(const M& model, const SetPoint& target,
                                                  const HoverReward& reward,
                                                  const heli::HoverPolicyInit& init, SeedArg seed,
                                                  std::int64_t scenarios, std::int64_t horizon, double gamma,
                                                  const std::string& variant, std::int64_t threads) {
  std::string error;
  if (!reward.IsValid(&error)) throw py::value_error("reward." + error);
  // With the integral term the task carries the error integral, stepped 0.02 s per (50 Hz) step.
  const heli::ErrorIntegrator integrator{.dt = init.integral_seconds > 0 ? 0.02 : 0.0};
  auto inner = std::make_unique<BuiltinProblem<HoverTask<M>, HoverPolicy>>(
      HoverTask<M>(model, target, reward, integrator), HoverPolicy(init), seed, scenarios, horizon, gamma,
      variant, threads);
  const auto* raw = inner.get();
  return std::make_unique<HoverProblemObject>(std::move(inner),
                                              [raw](const Theta& t) { return raw->returns(t); });
}

}  // namespace

namespace {

// Binds each setting sysid::Disturbance::VisitFields lists, by its member's name, with its unit and bounds in
// the docstring.
struct DisturbanceBinder {
  py::class_<sysid::Disturbance>& c;
  std::vector<std::string> names;
  static std::string doc(const sysid::DisturbanceSetting& s) {
    return fmt::format("{} (hover's wind.{}; {}).", s.help, s.key, s.range_in_unit());
  }
  void setting(const sysid::DisturbanceSetting& s, double sysid::Disturbance::*member) {
    c.def_readwrite(s.field, member, doc(s).c_str());
    names.emplace_back(s.field);
  }
  void setting(const sysid::DisturbanceSetting& s, std::array<double, 3> sysid::Disturbance::*member) {
    def_array(c, s.field, member, doc(s).c_str());
    names.emplace_back(s.field);
  }
};

// Binds each number heli::HoverTrainingOptions::VisitFields lists, by its name, with the option's help, its
// bounds and unit in the docstring.
struct HoverNumbersBinder {
  py::class_<heli::HoverTrainingOptions>& c;
  std::vector<std::string> names;
  template <class T>
  void setting(const NumberSetting& s, T heli::HoverTrainingOptions::*member) {
    c.def_readwrite(s.key, member,
                    fmt::format("{} (hover's {}; {}).", s.help, s.key, s.range_in_unit()).c_str());
    names.emplace_back(s.key);
  }
};

void bind_disturbance(py::module_& m) {
  auto disturbance = py::class_<sysid::Disturbance>(m, "Disturbance", R"doc(
The wind a learned model flies in during training (sysid/learned_model.hpp): a steady wind, a steady wind drawn
per scenario, and AR(1) gusts, acting on the model's airspeed. All zero: calm, as identified.)doc");
  disturbance.def(py::init<>());
  DisturbanceBinder binder{disturbance, {}};
  sysid::Disturbance::VisitFields(binder);
  disturbance.def("calm", &sysid::Disturbance::calm, "No steady wind, no drawn wind and no gusts.")
      .def("is_valid", is_valid_method<sysid::Disturbance>(), kIsValidDoc);
  set_fields(disturbance, binder.names);
}

}  // namespace

void bind_hover(py::module_& m) {
  bind_disturbance(m);
  auto options = py::class_<heli::HoverTrainingOptions>(m, "HoverTrainingOptions", R"doc(
`pegasus heli hover`'s training (thesis §5.3): 30 scenarios of 35 s, gamma 0.9995, gradient ascent then hill
climbing, on the identified model (heli/hover_task.hpp).)doc");
  options.def(py::init<>());
  HoverNumbersBinder numbers{options, {}};
  heli::HoverTrainingOptions::VisitFields(numbers);
  options
      .def_readwrite(
          "lqr_start", &heli::HoverTrainingOptions::lqr_start,
          "Starting gains from LQR on the identified model (True) or the X-Cell's constants (False).")
      .def_readwrite("lqr_action_factor", &heli::HoverTrainingOptions::lqr_action_factor,
                     "The LQR's action weights are the reward's times this (raised while the start crashes).")
      .def_readwrite("target", &heli::HoverTrainingOptions::target,
                     "The set point to hover at (the model's start is it plus the perturbation).")
      .def_readwrite("reward", &heli::HoverTrainingOptions::reward,
                     "The reward (Eqs 5.9-5.10, plus optional attitude and rate terms).")
      .def_readwrite("disturbance", &heli::HoverTrainingOptions::disturbance,
                     "The wind the scenarios fly in (Disturbance; calm by default, as `hover` without a "
                     "vehicle file).")
      .def_readwrite("centre_at_trim", &heli::HoverTrainingOptions::centre_at_trim,
                     "Take the action cost about the logs' trim (True) or about the reward's centre (False).")
      .def_readwrite("optimizer", &heli::HoverTrainingOptions::optimizer,
                     "The optimizer; gradient ascent by default (§5.3).")
      .def_readwrite(
          "then_hill_climb", &heli::HoverTrainingOptions::then_hill_climb,
          "After gradient ascent, hill climbing from its result (when optimizer.method is gradient).")
      .def_readwrite("seed", &heli::HoverTrainingOptions::seed,
                     "Root of the scenarios' numbers (and hill climbing's stream).")
      .def("horizon", &heli::HoverTrainingOptions::horizon, "Steps of 1 / control_rate_hz.")
      .def("gamma_per_step", &heli::HoverTrainingOptions::gamma_per_step, "gamma^(50 / control_rate_hz).")
      .def(
          "refit_steps",
          [](const heli::HoverTrainingOptions& o, IdentifiedModelArg model) {
            return o.refit_steps(*identified_model(model));
          },
          py::arg("model"), "refit_every, or the steps of 0.1 s when 0.")
      .def("is_valid", is_valid_method<heli::HoverTrainingOptions>(), kIsValidDoc);
  std::vector<std::string> fields = numbers.names;
  for (const char* other : {"lqr_start", "lqr_action_factor", "target", "reward", "disturbance",
                            "centre_at_trim", "optimizer", "then_hill_climb", "seed"})
    fields.emplace_back(other);
  set_fields(options, fields);

  auto problem = py::class_<HoverProblemObject, Objective>(m, "HoverProblem", R"doc(
PEGASUS U-hat (thesis §5.3) of the hover policy class (HoverPolicy(init), 34 weights) on a helicopter model, the
ground truth (Aircraft, Quadrotor) or the identified model (LearnedHeliModel): HoverTask adds the set point `target` and
the reward (Eqs 5.9-5.10) to the model's own; m scenarios of the given seed and variant, `horizon` 50 Hz steps,
discount gamma, evaluated on `threads` threads (the result never depends on them).
HoverProblem.from_training_options(model, options) is the objective `pegasus heli hover` maximises.)doc");
  problem
      .def(py::init([](HeliModelArg model, const SetPoint& target, const HoverReward& reward,
                       const heli::HoverPolicyInit& init, SeedArg seed, std::int64_t scenarios,
                       std::int64_t horizon, double gamma, const std::string& variant, std::int64_t threads) {
             if (py::isinstance<Aircraft>(model))
               return hover_problem(model.cast<const Aircraft&>(), target, reward, init, seed, scenarios,
                                    horizon, gamma, variant, threads);
             if (py::isinstance<LearnedHeliModel>(model))
               return hover_problem(model.cast<const LearnedHeliModel&>(), target, reward, init, seed,
                                    scenarios, horizon, gamma, variant, threads);
             if (py::isinstance<heli::Quadrotor>(model))
               return hover_problem(model.cast<const heli::Quadrotor&>(), target, reward, init, seed,
                                    scenarios, horizon, gamma, variant, threads);
             throw py::value_error(
                 "model: expected a pegasus.Aircraft, a pegasus.Quadrotor or a pegasus.LearnedHeliModel");
           }),
           py::arg("model"), py::kw_only(), py::arg_v("target", SetPoint{}, "SetPoint()"),
           py::arg_v("reward", HoverReward{}, "HoverReward()"),
           py::arg_v("init", heli::HoverPolicyInit{}, "HoverPolicyInit()"), py::arg("seed"),
           py::arg("scenarios"), py::arg("horizon"), py::arg("gamma") = 0.9995, py::arg("variant") = "plain",
           py::arg("threads") = 1)
      .def_static(
          "from_training_options",
          [](IdentifiedModelArg model, const heli::HoverTrainingOptions& o, std::int64_t threads) {
            std::string error;
            if (!o.IsValid(&error)) throw py::value_error("options." + error);
            auto inner = heli::hover_objective(identified_model(model), o, make_pool(threads));
            using Exact = PegasusObjective<HoverTask<LearnedHeliModel>, HoverPolicy>;
            const auto* raw = dynamic_cast<const Exact*>(inner.get());
            if (raw == nullptr) throw std::logic_error("hover_objective: unexpected objective type");
            return std::make_unique<HoverProblemObject>(std::move(inner), [raw](const Theta& t) {
              std::vector<double> out(static_cast<std::size_t>(raw->evaluator().scenarios().size()));
              raw->evaluator().per_scenario(t, out, nullptr);
              return out;
            });
          },
          py::arg("model"), py::arg_v("options", heli::HoverTrainingOptions{}, "HoverTrainingOptions()"),
          py::kw_only(), py::arg("threads") = 1,
          "The objective `pegasus heli hover` maximises on an identified model (or model.json path): "
          "heli::hover_objective, the policy class and reward centred on the logs' trim.");
  bind_returns(problem);

  m.def(
      "hover_init_from_model",
      [](IdentifiedModelArg model) { return heli::hover_init_from_model(*identified_model(model)); },
      py::arg("model"), "The hover policy's starting weights around the trim estimate of the model's logs.");
  m.def(
      "lqr_hover_init",
      [](IdentifiedModelArg model, const heli::HoverTrainingOptions& o) {
        const heli::LqrStart r = heli::lqr_hover_init(*identified_model(model), o);
        py::dict out;
        out["init"] = r.init;
        out["used"] = r.used;
        out["reason"] = r.reason;
        out["spectral_radius"] = r.spectral_radius;
        out["open_loop_radius"] = r.open_loop_radius;
        out["integral_seconds"] = r.integral_seconds;
        out["integral_radius"] = r.integral_radius;
        return out;
      },
      py::arg("model"), py::arg_v("options", heli::HoverTrainingOptions{}, "HoverTrainingOptions()"),
      "Starting gains by LQR on the identified model at the hover (`heli hover --starting-gains lqr`): a "
      "dict of "
      "init (HoverPolicyInit; the constants when not used), used, reason, spectral_radius, "
      "open_loop_radius.");
  m.def(
      "hover_reward_for",
      [](IdentifiedModelArg model, const heli::HoverTrainingOptions& o) {
        return heli::hover_reward_for(*identified_model(model), o);
      },
      py::arg("model"), py::arg_v("options", heli::HoverTrainingOptions{}, "HoverTrainingOptions()"),
      "The reward of options, centred on the logs' trim when options.centre_at_trim.");

  auto start = py::class_<heli::StartingPolicyCheck>(m, "StartingPolicyCheck", R"doc(
The starting weights flown on the training scenarios of the learned model before hover training: train_hover
stops when more than options.max_start_crash_fraction of them crash (heli/hover_task.hpp).)doc");
  start.def_readonly("scenarios", &heli::StartingPolicyCheck::scenarios, "Training scenarios flown.")
      .def_readonly("crashed", &heli::StartingPolicyCheck::crashed,
                    "Scenarios whose rollout ended in the model's crash state.")
      .def_readonly("mean_seconds_to_crash", &heli::StartingPolicyCheck::mean_seconds_to_crash,
                    "Mean flight time before the crash over the crashed scenarios, s (0 when none crashed).")
      .def_readonly("uhat", &heli::StartingPolicyCheck::uhat,
                    "U-hat of the starting weights on the training scenarios.");
  set_fields(start, {"scenarios", "crashed", "mean_seconds_to_crash", "uhat"});

  auto result = py::class_<heli::HoverTrainingResult>(m, "HoverTrainingResult",
                                                      "What train_hover returns (heli/hover_task.hpp).");
  result
      .def_property_readonly(
          "theta", [](const heli::HoverTrainingResult& r) { return vector_array(r.theta); },
          "The best weights (HoverPolicy's parameters).")
      .def_readonly("initial_uhat", &heli::HoverTrainingResult::initial_uhat,
                    "U-hat of the starting weights.")
      .def_readonly("final_uhat", &heli::HoverTrainingResult::final_uhat, "U-hat of the returned weights.")
      .def_readonly("gradient", &heli::HoverTrainingResult::gradient,
                    "The first phase's summary (gradient ascent, or the optimizer chosen instead).")
      .def_readonly("hill_climb", &heli::HoverTrainingResult::hill_climb,
                    "The hill-climbing phase's summary (method empty when it did not run).")
      .def_readonly("progress", &heli::HoverTrainingResult::progress,
                    "Both phases' iterations, with iterations and evaluations counted on.")
      .def_readonly("start", &heli::HoverTrainingResult::start,
                    "The starting weights flown on the training scenarios, before training.")
      .def_readonly("lqr_action_factor", &heli::HoverTrainingResult::lqr_action_factor,
                    "The LQR start's action factor after train_hover raised it (the options' otherwise).");
  set_fields(result, {"theta", "initial_uhat", "final_uhat", "gradient", "hill_climb", "progress", "start",
                      "lqr_action_factor"});
  m.def(
      "train_hover",
      [](IdentifiedModelArg model, const heli::HoverTrainingOptions& o, std::int64_t checkpoint_every,
         CheckpointCallbackArg on_checkpoint, OptionalCheckpointArg resume_from,
         IterationCallbacksArg callbacks, std::int64_t threads) {
        std::string error;
        if (!o.IsValid(&error)) throw py::value_error("options." + error);
        if (checkpoint_every < 0)
          throw py::value_error(
              fmt::format("checkpoint_every: expected an integer >= 0, got {}", checkpoint_every));
        heli::HoverTrainingHooks hooks;
        hooks.checkpoint_every = on_checkpoint.is_none() ? 0 : checkpoint_every;
        hooks.on_checkpoint = checkpoint_callback(on_checkpoint);
        if (!resume_from.is_none()) hooks.resume_from = from_python(resume_from, "resume_from");
        const IterationCallbackList list(callbacks);
        hooks.callbacks = list.pointers();
        const auto shared = identified_model(model);
        const auto pool = make_pool(threads);
        ReleaseGilInterruptibly release;
        return heli::train_hover(shared, o, hooks, *pool);
      },
      py::arg("model"), py::arg_v("options", heli::HoverTrainingOptions{}, "HoverTrainingOptions()"),
      py::kw_only(), py::arg("checkpoint_every") = 1, py::arg("on_checkpoint") = py::none(),
      py::arg("resume_from") = py::none(), py::arg("callbacks") = py::none(), py::arg("threads") = 1,
      "Trains the hover controller as `pegasus heli hover` does (the same plan, checkpoints and bits for any "
      "threads); checkpoints are training-plan checkpoints (dicts).");
}

}  // namespace pegasus::python
