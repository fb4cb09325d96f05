// Built-in environments as objects: the bicycle (thesis §4.6) and Pendulum-v1 as batch models, the gridworlds
// (§3.4, §4.6), their policy classes and PEGASUS problems, and the bicycle training of
// experiments/bicycle_experiment.hpp.
#include <fmt/format.h>

#include <memory>

#include "builtin_problem.hpp"
#include "pegasus/envs/bicycle.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/envs/pomdp_gridworld.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus::python {

namespace {

constexpr py::ssize_t kBicycleStateColumns = 9;  // omega, omega_dot, theta, theta_dot, xf, yf, xb, yb, psi

BicycleState bicycle_state(const double* x) {
  BicycleState s;
  s.omega = x[0], s.omega_dot = x[1], s.theta = x[2], s.theta_dot = x[3];
  s.xf = x[4], s.yf = x[5], s.xb = x[6], s.yb = x[7], s.psi = x[8];
  s.sin_theta = std::sin(s.theta), s.cos_theta = std::cos(s.theta), s.trig_of = s.theta;
  return s;
}
void write_bicycle_state(const BicycleState& s, double* x) {
  const double v[] = {s.omega, s.omega_dot, s.theta, s.theta_dot, s.xf, s.yf, s.xb, s.yb, s.psi};
  std::copy(std::begin(v), std::end(v), x);
}

using BicycleProblem = BuiltinProblem<Bicycle, BicyclePolicy>;
using PendulumProblem = BuiltinProblem<Pendulum, PendulumSwingUpPolicy>;
using GridworldProblem = BuiltinProblem<GridWorld, TablePolicy>;
using PomdpGridworldProblem = BuiltinProblem<PomdpGridworld, TablePolicy>;

GridWorld checked_corner_gridworld(std::int64_t n, double intended) {
  if (n < 2 || n > 10000)
    throw py::value_error(fmt::format("n: expected an integer in [2, 10000], got {}", n));
  if (!(intended > 0.0 && intended <= 1.0))
    throw py::value_error(fmt::format("intended: expected a number in (0, 1], got {}", intended));
  return corner_gridworld(static_cast<int>(n), intended);
}

}  // namespace

void bind_envs(py::module_& m) {
  py::class_<BicycleGoal>(m, "BicycleGoal", "A goal circle, or a direction at infinity (§4.6 footnote 15).")
      .def_static("circle", &BicycleGoal::circle, py::arg("x"), py::arg("y"), py::arg("radius"))
      .def_static("infinitely_far", &BicycleGoal::infinitely_far, py::arg("direction"))
      .def_readwrite("at_infinity", &BicycleGoal::at_infinity,
                     "True: a direction at infinity (direction); False: a circle (x, y, radius).")
      .def_readwrite("x", &BicycleGoal::x, "The circle's centre, m (bike.c: 1000).")
      .def_readwrite("y", &BicycleGoal::y, "The circle's centre, m (bike.c: 0).")
      .def_readwrite("radius", &BicycleGoal::radius, "The circle's radius, m; entering it ends the ride.")
      .def_readwrite("direction", &BicycleGoal::direction,
                     "At infinity: the goal's direction, counter-clockwise from +x, rad.");
  py::class_<BicycleStart>(m, "BicycleStart", "Half-widths of the uniform initial-state distribution.")
      .def(py::init<>())
      .def_readwrite("omega", &BicycleStart::omega, "Half-width of the initial tilt from vertical, rad.")
      .def_readwrite("omega_dot", &BicycleStart::omega_dot, "Half-width of its initial rate, rad/s.")
      .def_readwrite("theta", &BicycleStart::theta, "Half-width of the initial handlebar angle, rad.")
      .def_readwrite("theta_dot", &BicycleStart::theta_dot, "Half-width of its initial rate, rad/s.")
      .def_readwrite("goal_angle", &BicycleStart::goal_angle,
                     "Half-width of the initial heading relative to the goal, rad (pi: any heading).");
  py::class_<BicycleOptions>(m, "BicycleOptions",
                             "The bicycle's goal, start distribution, rewards and noise.")
      .def(py::init<>())
      .def_readwrite("goal", &BicycleOptions::goal, "Where the ride goes (a BicycleGoal).")
      .def_readwrite("start", &BicycleOptions::start, "The initial-state distribution (a BicycleStart).")
      .def_readwrite("fall_reward", &BicycleOptions::fall_reward,
                     "Reward of the transition into a fall (|value| <= 1e12).")
      .def_readwrite("goal_reward", &BicycleOptions::goal_reward,
                     "Reward of the transition into the goal circle (|value| <= 1e12).")
      .def_readwrite("noise", &BicycleOptions::noise,
                     "Half-width of the uniform noise on the rider's displacement d, m.")
      .def("is_valid", is_valid_method<BicycleOptions>(), kIsValidDoc);

  py::class_<Bicycle>(m, "Bicycle", R"doc(
Randlov and Alstrom's bicycle (thesis §4.6) as a batch model. A state row is
[omega, omega_dot, theta, theta_dot, xf, yf, xb, yb, psi] (radians, metres, world frame); an action row
[T, d]; one uniform of noise per step, five for the initial state.)doc")
      .def(py::init([](const BicycleOptions& o) { return Bicycle(o); }),
           py::arg_v("options", BicycleOptions{}, "BicycleOptions()"))
      .def_property_readonly("options", &Bicycle::options, py::return_value_policy::copy,
                             "The BicycleOptions it was built with (goal, start, rewards, noise).")
      .def_property_readonly("noise_dim", &Bicycle::noise_dim, kNoiseDimDoc)
      .def_property_readonly("initial_noise_dim", &Bicycle::initial_noise_dim, kInitialNoiseDimDoc)
      .def(
          "initial_state",
          [](const Bicycle& b, ArrayLikeArg noise) {
            const Array p = as_matrix(noise, "noise", -1, 5);
            require_finite(p, "noise");
            Array out = matrix(p.shape(0), kBicycleStateColumns);
            for (py::ssize_t r = 0; r < p.shape(0); ++r)
              write_bicycle_state(b.initial_state(std::span<const double>(p.data() + r * 5, 5)),
                                  out.mutable_data() + r * kBicycleStateColumns);
            return out;
          },
          py::arg("noise"),
          "States (rows of omega, omega_dot, theta, theta_dot, xf, yf, xb, yb, psi) drawn from rows of 5 "
          "uniforms.")
      .def(
          "step",
          [](const Bicycle& b, ArrayLikeArg states, ArrayLikeArg actions, ArrayLikeArg noise) {
            const Array s = as_matrix(states, "states", -1, kBicycleStateColumns);
            const Array a = as_matrix(actions, "actions", s.shape(0), 2);
            const Array p = as_matrix(noise, "noise", s.shape(0), 1);
            require_finite(s, "states"), require_finite(a, "actions"), require_finite(p, "noise");
            Array out = matrix(s.shape(0), kBicycleStateColumns);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const BicycleState next =
                  b.step(bicycle_state(s.data() + r * kBicycleStateColumns),
                         {a.data()[2 * r], a.data()[2 * r + 1]}, std::span<const double>(p.data() + r, 1));
              write_bicycle_state(next, out.mutable_data() + r * kBicycleStateColumns);
            }
            return out;
          },
          py::arg("states"), py::arg("actions"), py::arg("noise"),
          "The next states (one 0.01 s step each) from states, actions (rows of torque, displacement) and "
          "one noise uniform per row.")
      .def(
          "observe",
          [](const Bicycle& b, ArrayLikeArg states) {
            const Array s = as_matrix(states, "states", -1, kBicycleStateColumns);
            Array out = matrix(s.shape(0), 5);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const BicycleObservation o = b.observe(bicycle_state(s.data() + r * kBicycleStateColumns));
              const double v[] = {o.omega, o.omega_dot, o.theta, o.theta_dot, o.goal_angle};
              std::copy(std::begin(v), std::end(v), out.mutable_data() + r * 5);
            }
            return out;
          },
          py::arg("states"), "[omega, omega_dot, theta, theta_dot, goal_angle] of each row.");

  m.def(
      "bicycle_features",
      [](ArrayLikeArg observations) {
        const Array o = as_matrix(observations, "observations", -1, 5);
        Array out = matrix(o.shape(0), BicycleFeatures::kCount);
        const BicycleFeatures f;
        for (py::ssize_t r = 0; r < o.shape(0); ++r) {
          const double* x = o.data() + r * 5;
          f(BicycleObservation{x[0], x[1], x[2], x[3], x[4]},
            std::span<double>(out.mutable_data() + r * BicycleFeatures::kCount, BicycleFeatures::kCount));
        }
        return out;
      },
      py::arg("observations"), "The bicycle policy's 15 features (envs/bicycle_policy.hpp) of each row.");
  m.def(
      "bicycle_policy_parameters", [] { return make_bicycle_policy().parameters(); },
      "The bicycle policy class's 30 parameters w.T.<feature>, w.d.<feature>.");
  m.def(
      "read_bicycle_policy", [](const std::string& path) { return vector_array(read_bicycle_policy(path)); },
      py::arg("path"),
      "The weights of a bicycle policy file (`pegasus bicycle train`'s policy.json); ValueError naming the "
      "file and "
      "field when it is not one.");
  m.def(
      "bicycle_controls",
      [](ArrayLikeArg theta, ArrayLikeArg observations) {
        const BicyclePolicy policy = make_bicycle_policy();
        const Theta w = as_theta(theta, "theta", policy.parameters());
        const Array o = as_matrix(observations, "observations", -1, 5);
        require_finite(o, "observations");
        Array out = matrix(o.shape(0), 2);
        for (py::ssize_t r = 0; r < o.shape(0); ++r) {
          const double* x = o.data() + r * 5;
          const auto a = policy.act(w, BicycleObservation{x[0], x[1], x[2], x[3], x[4]});
          out.mutable_data()[2 * r] = a[0], out.mutable_data()[2 * r + 1] = a[1];
        }
        return out;
      },
      py::arg("theta"), py::arg("observations"),
      "The controls [T, d] of the bicycle policy theta for each row of observations [omega, omega_dot, "
      "theta, "
      "theta_dot, goal_angle].");
  m.def(
      "bicycle_balancing_theta", [] { return vector_array(bicycle_balancing_theta()); },
      "A crude hand-set balancing policy of the bicycle class (ignores the goal).");

  auto bicycle_problem = py::class_<BicycleProblem, Objective>(m, "BicycleProblem", R"doc(
PEGASUS U-hat of the bicycle policy class on the (unshaped) C++ bicycle: m scenarios of the given seed and
variant, horizon H, discount gamma, evaluated on `threads` threads (the result never depends on them).)doc");
  bicycle_problem.def(
      py::init([](const BicycleOptions& bicycle, SeedArg seed, std::int64_t scenarios, std::int64_t horizon,
                  double gamma, const std::string& variant, std::int64_t threads) {
        return std::make_unique<BicycleProblem>(Bicycle(bicycle), make_bicycle_policy(), seed, scenarios,
                                                horizon, gamma, variant, threads);
      }),
      py::arg_v("bicycle", BicycleOptions{}, "BicycleOptions()"), py::kw_only(), py::arg("seed"),
      py::arg("scenarios"), py::arg("horizon"), py::arg("gamma") = 1.0, py::arg("variant") = "plain",
      py::arg("threads") = 1);
  bind_returns(bicycle_problem);

  py::class_<Pendulum>(m, "Pendulum", R"doc(
Gymnasium's Pendulum-v1 (envs/pendulum.hpp) as a batch model: a state row is [theta, theta_dot], an action row
[torque]; no noise per step, two uniforms for the initial state.)doc")
      .def(py::init<>())
      .def_property_readonly("noise_dim", &Pendulum::noise_dim, kNoiseDimDoc)
      .def_property_readonly("initial_noise_dim", &Pendulum::initial_noise_dim, kInitialNoiseDimDoc)
      .def(
          "initial_state",
          [](const Pendulum& pendulum, ArrayLikeArg noise) {
            const Array p = as_matrix(noise, "noise", -1, 2);
            require_finite(p, "noise");
            Array out = matrix(p.shape(0), 2);
            for (py::ssize_t r = 0; r < p.shape(0); ++r) {
              const PendulumState s = pendulum.initial_state(std::span<const double>(p.data() + 2 * r, 2));
              out.mutable_data()[2 * r] = s.theta, out.mutable_data()[2 * r + 1] = s.theta_dot;
            }
            return out;
          },
          py::arg("noise"), "States (rows of theta, theta_dot) drawn from rows of 2 uniforms.")
      .def(
          "step",
          [](const Pendulum& pendulum, ArrayLikeArg states, ArrayLikeArg actions) {
            const Array s = as_matrix(states, "states", -1, 2);
            const Array a = as_matrix(actions, "actions", s.shape(0), 1);
            require_finite(s, "states");
            require_finite(a, "actions");
            Array out = matrix(s.shape(0), 2);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const PendulumState next = pendulum.step({s.data()[2 * r], s.data()[2 * r + 1]}, a.data()[r],
                                                       std::span<const double>());
              out.mutable_data()[2 * r] = next.theta, out.mutable_data()[2 * r + 1] = next.theta_dot;
            }
            return out;
          },
          py::arg("states"), py::arg("actions"),
          "The next states (rows of theta, theta_dot) from states and actions (one torque per row).")
      .def(
          "reward",
          [](const Pendulum& pendulum, ArrayLikeArg states, ArrayLikeArg actions) {
            const Array s = as_matrix(states, "states", -1, 2);
            const Array a = as_matrix(actions, "actions", s.shape(0), 1);
            Array out(s.shape(0));
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.mutable_data()[r] = pendulum.reward({s.data()[2 * r], s.data()[2 * r + 1]}, a.data()[r]);
            return out;
          },
          py::arg("states"), py::arg("actions"), "The reward of each row's state and action.");
  m.def(
      "pendulum_policy_parameters",
      [](bool refinements) { return PendulumSwingUpPolicy(refinements).parameters(); },
      py::arg("refinements") = true, "The swing-up policy class's parameters (envs/pendulum_policy.hpp).");

  auto pendulum_problem = py::class_<PendulumProblem, Objective>(m, "PendulumProblem", R"doc(
PEGASUS U-hat of the swing-up policy class (refinements: the full seven-number class, else the five-number one)
on Pendulum-v1: m scenarios, horizon H, discount gamma, on `threads` threads.)doc");
  pendulum_problem.def(
      py::init([](SeedArg seed, std::int64_t scenarios, std::int64_t horizon, double gamma,
                  const std::string& variant, std::int64_t threads, bool refinements) {
        return std::make_unique<PendulumProblem>(Pendulum(), PendulumSwingUpPolicy(refinements), seed,
                                                 scenarios, horizon, gamma, variant, threads);
      }),
      py::kw_only(), py::arg("seed"), py::arg("scenarios"), py::arg("horizon"), py::arg("gamma") = 1.0,
      py::arg("variant") = "plain", py::arg("threads") = 1, py::arg("refinements") = true);
  bind_returns(pendulum_problem);

  m.def(
      "corner_gridworld_mdp",
      [](std::int64_t n, double intended, double gamma) {
        return to_finite_mdp(checked_corner_gridworld(n, intended), gamma);
      },
      py::arg("n"), py::arg("intended") = 0.8, py::arg("gamma") = 1.0,
      "The §3.4 gridworld (n x n, start (0, 0), goal (n-1, n-1), moves as intended with probability "
      "`intended`, "
      "-1 per step) as a FiniteMdp; state = y * n + x.");
  m.def(
      "corner_gridworld_potential",
      [](std::int64_t n, double intended, double scale) {
        return vector_array(manhattan_potential(checked_corner_gridworld(n, intended), scale));
      },
      py::arg("n"), py::arg("intended") = 0.8, py::arg("scale") = 1.0,
      "Phi0(s) = -scale * manhattan(s, goal) / intended, the §3.4 estimate of V*; Phi(goal) = 0.");
  auto gridworld_problem = py::class_<GridworldProblem, Objective>(m, "GridworldProblem", R"doc(
PEGASUS U-hat of table policies (one integer action per cell, TablePolicy) on the §3.4 corner gridworld,
m scenarios of the given seed, horizon H, discount gamma, on `threads` threads.)doc");
  gridworld_problem.def(
      py::init([](std::int64_t n, double intended, SeedArg seed, std::int64_t scenarios, std::int64_t horizon,
                  double gamma, const std::string& variant, std::int64_t threads) {
        GridWorld world = checked_corner_gridworld(n, intended);
        TablePolicy policy(world.num_states(), world.num_actions());
        return std::make_unique<GridworldProblem>(std::move(world), std::move(policy), seed, scenarios,
                                                  horizon, gamma, variant, threads);
      }),
      py::arg("n"), py::arg("intended") = 0.8, py::kw_only(), py::arg("seed"), py::arg("scenarios"),
      py::arg("horizon"), py::arg("gamma") = 1.0, py::arg("variant") = "plain", py::arg("threads") = 1);
  bind_returns(gridworld_problem);
  auto pomdp_problem = py::class_<PomdpGridworldProblem, Objective>(m, "PomdpGridworldProblem", R"doc(
PEGASUS U-hat of memoryless table policies (one integer action per wall-pattern observation) on the POMDP
gridworld of thesis §4.6 (width x height, open grid, start (0, 0), goal at the far corner).)doc");
  pomdp_problem.def(
      py::init([](std::int64_t width, std::int64_t height, SeedArg seed, std::int64_t scenarios,
                  std::int64_t horizon, double gamma, const std::string& variant, std::int64_t threads) {
        if (width < 2 || width > 1000 || height < 2 || height > 1000)
          throw py::value_error(
              fmt::format("width, height: expected integers in [2, 1000], got {} and {}", width, height));
        PomdpGridworld::Layout layout;
        layout.width = static_cast<int>(width), layout.height = static_cast<int>(height);
        layout.goal = {layout.width - 1, layout.height - 1};
        PomdpGridworld world(layout);
        TablePolicy policy(world.observations(), PomdpGridworld::kActions);
        return std::make_unique<PomdpGridworldProblem>(std::move(world), std::move(policy), seed, scenarios,
                                                       horizon, gamma, variant, threads);
      }),
      py::arg("width") = 5, py::arg("height") = 5, py::kw_only(), py::arg("seed"), py::arg("scenarios"),
      py::arg("horizon"), py::arg("gamma") = 1.0, py::arg("variant") = "plain", py::arg("threads") = 1);
  bind_returns(pomdp_problem);

  py::class_<BicycleTrainingOptions>(m, "BicycleTrainingOptions", "The bicycle experiment's training (§4.6).")
      .def(py::init<>())
      .def_readwrite("scenarios", &BicycleTrainingOptions::scenarios, "PEGASUS scenarios m.")
      .def_readwrite("gamma", &BicycleTrainingOptions::gamma, "Discount per 0.01 s step.")
      .def_readwrite("horizon", &BicycleTrainingOptions::horizon, "Rollout length H, steps of 0.01 s.")
      .def_readwrite("shaping", &BicycleTrainingOptions::shaping,
                     "\"potential\", \"progress-bonus\" or \"none\".")
      .def_readwrite("shaping_per_metre", &BicycleTrainingOptions::shaping_per_metre,
                     "Phi = this times the progress towards the goal, m (the bonus: this times v dt).")
      .def_readwrite("estimator", &BicycleTrainingOptions::estimator,
                     "\"pegasus\" (fixed scenarios) or \"montecarlo\" (fresh numbers per evaluation).")
      .def_property(
          "variant", [](const BicycleTrainingOptions& o) { return to_string(o.variant); },
          [](BicycleTrainingOptions& o, const std::string& v) { o.variant = parse_scenario_variant(v); },
          "Scenario variant: \"plain\", \"antithetic\", \"stratified\" or \"sobol\".")
      .def_readwrite("initial_policy", &BicycleTrainingOptions::initial_policy,
                     "\"balance\" (bicycle_balancing_theta) or \"zero\".")
      .def_readwrite("bicycle", &BicycleTrainingOptions::bicycle,
                     "The training bicycle (by default its goal is infinitely far to the east).")
      .def_readwrite("optimizer", &BicycleTrainingOptions::optimizer,
                     "The optimizer; bounded-step gradient ascent by default.")
      .def_readwrite("seed", &BicycleTrainingOptions::seed,
                     "Root of the scenarios (PEGASUS) or of the Monte Carlo streams.")
      .def_readwrite("threads", &BicycleTrainingOptions::threads, "Worker threads, as --threads.")
      .def("is_valid", is_valid_method<BicycleTrainingOptions>(), kIsValidDoc);
  m.def(
      "train_bicycle",
      [](const BicycleTrainingOptions& options, std::int64_t checkpoint_every,
         CheckpointCallbackArg on_checkpoint, OptionalCheckpointArg resume_from,
         IterationCallbacksArg callbacks) {
        const IterationCallbackList list(callbacks);
        BicycleTrainingHooks hooks;
        hooks.callbacks = list.pointers();
        hooks.checkpoint_every = checkpoint_every;
        OptimizerOptions carrier;  // converts the Python callable and dict as OptimizerOptions does
        py::cast(&carrier, py::return_value_policy::reference)
            .attr("set_checkpointing")(checkpoint_every, on_checkpoint, resume_from);
        hooks.on_checkpoint = carrier.gradient.on_checkpoint;
        hooks.resume_from = carrier.gradient.resume_from;
        std::string error;
        if (!options.IsValid(&error)) throw py::value_error("options." + error);
        BicycleTrainingResult result;
        {
          ReleaseGilInterruptibly release;
          result = train_bicycle(options, hooks);
        }
        return py::make_tuple(vector_array(result.theta), result.summary);
      },
      py::arg("options"), py::kw_only(), py::arg("checkpoint_every") = 0,
      py::arg("on_checkpoint") = py::none(), py::arg("resume_from") = py::none(),
      py::arg("callbacks") = py::none(),
      "Trains the bicycle policy as `pegasus bicycle train` does; returns (theta, OptimizerSummary). "
      "callbacks: as solve's, told after every iteration.");
  m.def(
      "bicycle_training_problem",
      [](const BicycleTrainingOptions& o) -> std::unique_ptr<Objective> {
        std::string error;
        if (!o.IsValid(&error)) throw py::value_error("options." + error);
        if (o.estimator != "pegasus")
          throw py::value_error("options.estimator: expected \"pegasus\" for bicycle_training_problem");
        const Bicycle bike(o.bicycle);
        ScenarioSet scenarios({.seed = o.seed,
                               .count = o.scenarios,
                               .horizon = o.horizon,
                               .noise_dim = 1,
                               .initial_noise_dim = 5,
                               .variant = o.variant});
        const Discounting d{.gamma = o.gamma, .horizon = o.horizon};
        auto pool = make_pool(o.threads);
        if (o.shaping == "potential") {
          auto model = shape(bike, BicycleProgressPotential{bike, o.shaping_per_metre}, o.gamma);
          using Model = decltype(model);
          return std::make_unique<BuiltinProblem<Model, BicyclePolicy>>(
              PegasusEvaluator<Model, BicyclePolicy>(model, make_bicycle_policy(), std::move(scenarios), d),
              pool);
        }
        if (o.shaping == "none")
          return std::make_unique<BicycleProblem>(
              PegasusEvaluator<Bicycle, BicyclePolicy>(bike, make_bicycle_policy(), std::move(scenarios), d),
              pool);
        throw py::value_error(
            "options.shaping: expected \"potential\" or \"none\" for bicycle_training_problem");
      },
      py::arg("options"), R"doc(
The objective train_bicycle maximises (PEGASUS estimator, shaping "potential" or "none") as an Objective evaluated
by the C++ PegasusEvaluator on options.threads threads: the same U-hat as bicycle_uhat, bit for bit, and with
uhat_batch the C++ side of the numpy-bicycle benchmark (bench/bicycle_bench.cpp BM_BicycleUhatBatch_31x30_H500).)doc");
  m.def(
      "bicycle_uhat",
      [](const BicycleTrainingOptions& options, ArrayLikeArg theta) {
        const Theta t = as_theta(theta, "theta", make_bicycle_policy().parameters());
        ReleaseGilInterruptibly release;
        return bicycle_uhat(options, t);
      },
      py::arg("options"), py::arg("theta"),
      "U-hat of theta on the training problem train_bicycle maximises.");
}

}  // namespace pegasus::python
