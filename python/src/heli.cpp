// The helicopter of thesis chapter 5 from Python: the ground-truth aircraft (heli/aircraft.hpp) and the
// identified model (sysid/learned_model.hpp) as batch models over numpy rows, and the hover task (§5.3) and
// its PEGASUS U-hat on either. Policy files are in heli_policy.cpp.
#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <memory>

#include "builtin_problem.hpp"
#include "heli_batch.hpp"
#include "heli_policy.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/quadrotor.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::python {

namespace {

using heli::Aircraft;
using heli::AircraftParams;
using heli::AircraftState;
using heli::Controls;
using heli::HoverPolicy;
using heli::HoverReward;
using heli::HoverTask;
using heli::LoggedState;
using heli::SetPoint;
using sysid::IdentifiedModel;
using sysid::LearnedHeliModel;
using sysid::LearnedModelOptions;

// ---- State rows ------------------------------------------------------------------------------------------

// The ground truth's state as a row of 36 numbers (every field of AircraftState, frames as there).
constexpr py::ssize_t kAircraftColumns = 36;
std::vector<std::string> aircraft_columns() {
  std::vector<std::string> c = {"p_W.x",    "p_W.y",    "p_W.z",     "v_B.x",    "v_B.y",    "v_B.z",
                                "roll",     "pitch",    "yaw",       "w_B.x",    "w_B.y",    "w_B.z",
                                "flap_lon", "flap_lat", "gyro_rate", "servo.a1", "servo.a2", "servo.a3",
                                "servo.a4", "gust_W.x", "gust_W.y",  "gust_W.z"};
  for (const char* n : heli::kLoggedStateNames) c.push_back(std::string("estimate_error.") + n);
  c.push_back("time");
  c.push_back("crash");
  return c;
}

void write_row(const AircraftState& s, double* x) {
  for (int i = 0; i < 3; ++i)
    x[i] = s.p_W[i], x[3 + i] = s.v_B[i], x[9 + i] = s.w_B[i], x[19 + i] = s.gust_W[i];
  x[6] = s.attitude.roll, x[7] = s.attitude.pitch, x[8] = s.attitude.yaw;
  x[12] = s.flap_lon, x[13] = s.flap_lat, x[14] = s.gyro_rate;
  for (int i = 0; i < 4; ++i) x[15 + i] = s.servo[static_cast<std::size_t>(i)];
  for (int i = 0; i < kLogged; ++i) x[22 + i] = s.estimate_error[static_cast<std::size_t>(i)];
  x[34] = s.time;
  x[35] = static_cast<double>(static_cast<int>(s.crash));
}

AircraftState aircraft_row(const double* x, py::ssize_t row, const char* name) {
  AircraftState s;
  for (int i = 0; i < 3; ++i)
    s.p_W[i] = x[i], s.v_B[i] = x[3 + i], s.w_B[i] = x[9 + i], s.gust_W[i] = x[19 + i];
  s.attitude = {x[6], x[7], x[8]};
  s.flap_lon = x[12], s.flap_lat = x[13], s.gyro_rate = x[14];
  for (int i = 0; i < 4; ++i) s.servo[static_cast<std::size_t>(i)] = x[15 + i];
  for (int i = 0; i < kLogged; ++i) s.estimate_error[static_cast<std::size_t>(i)] = x[22 + i];
  s.time = x[34];
  const double crash = x[35];
  if (!(crash >= 0 && crash <= static_cast<int>(heli::CrashReason::kModelSupport) &&
        crash == std::floor(crash)))
    throw py::value_error(
        fmt::format("{}: expected a crash code in 0..{} in column 35 (crash), got {} at row {}", name,
                    static_cast<int>(heli::CrashReason::kModelSupport), crash, row));
  s.crash = static_cast<heli::CrashReason>(static_cast<int>(crash));
  return s;
}

// The identified model's state as a row of 153 numbers: the 12 world-frame logged states, the three extra
// states, the held regression coefficients (8 x 16), the predictive variance (8), the step count and the
// crash flag.
constexpr py::ssize_t kLearnedColumns =
    kLogged + 3 + sysid::kBodyVars * sysid::kInputs + 2 * sysid::kBodyVars + 2;
std::vector<std::string> learned_columns() {
  std::vector<std::string> c(heli::kLoggedStateNames.begin(), heli::kLoggedStateNames.end());
  c.insert(c.end(), {"flap_lon", "flap_lat", "gyro"});
  for (const char* v : sysid::kBodyVarNames)
    for (const char* i : sysid::kInputNames) c.push_back(fmt::format("beta.{}.{}", v, i));
  for (const char* v : sysid::kBodyVarNames) c.push_back(fmt::format("variance.{}", v));
  for (const char* v : sysid::kBodyVarNames) c.push_back(fmt::format("colored.{}", v));
  c.push_back("step");
  c.push_back("crashed");
  return c;
}

void write_row(const LearnedHeliModel::State& s, double* x) {
  std::copy(s.sim.world.begin(), s.sim.world.end(), x);
  x += kLogged;
  *x++ = s.sim.flap_lon, *x++ = s.sim.flap_lat, *x++ = s.sim.gyro;
  for (const auto& b : s.beta)
    for (int i = 0; i < sysid::kInputs; ++i) *x++ = b[i];
  for (int v = 0; v < sysid::kBodyVars; ++v) *x++ = s.variance[v];
  for (int v = 0; v < sysid::kBodyVars; ++v) *x++ = s.colored[v];
  *x++ = s.step;
  *x = s.crashed ? 1.0 : 0.0;
}

LearnedHeliModel::State learned_row(const double* x, py::ssize_t row, const char* name) {
  LearnedHeliModel::State s;
  std::copy(x, x + kLogged, s.sim.world.begin());
  const double* y = x + kLogged;
  s.sim.flap_lon = *y++, s.sim.flap_lat = *y++, s.sim.gyro = *y++;
  for (auto& b : s.beta)
    for (int i = 0; i < sysid::kInputs; ++i) b[i] = *y++;
  for (int v = 0; v < sysid::kBodyVars; ++v) s.variance[v] = *y++;
  for (int v = 0; v < sysid::kBodyVars; ++v) s.colored[v] = *y++;
  const double step = *y++, crashed = *y;
  if (!(step >= 0 && step < 2e9 && step == std::floor(step)))
    throw py::value_error(fmt::format("{}: expected a step count >= 0 in column {} (step), got {} at row {}",
                                      name, kLearnedColumns - 2, step, row));
  if (crashed != 0.0 && crashed != 1.0)
    throw py::value_error(fmt::format("{}: expected 0 or 1 in column {} (crashed), got {} at row {}", name,
                                      kLearnedColumns - 1, crashed, row));
  s.step = static_cast<int>(step);
  s.crashed = crashed == 1.0;
  return s;
}

}  // namespace

// The helicopter's two batch models' rows (heli_batch.hpp).
template <>
struct StateRows<Aircraft> {
  static constexpr py::ssize_t kColumns = kAircraftColumns;
  static void write(const AircraftState& s, double* x) { write_row(s, x); }
  static AircraftState read(const double* x, py::ssize_t r, const char* name) {
    return aircraft_row(x, r, name);
  }
};
template <>
struct StateRows<LearnedHeliModel> {
  static constexpr py::ssize_t kColumns = kLearnedColumns;
  static void write(const LearnedHeliModel::State& s, double* x) { write_row(s, x); }
  static LearnedHeliModel::State read(const double* x, py::ssize_t r, const char* name) {
    return learned_row(x, r, name);
  }
};

namespace {

SetPoint set_point(double x, double y, double z, double yaw) {
  for (const auto& [v, name] : {std::pair{x, "x"}, {y, "y"}, {z, "z"}, {yaw, "yaw"}})
    if (!std::isfinite(v))
      throw py::value_error(fmt::format("{}: expected a finite number, got {}", name, v));
  return {x, y, z, yaw};
}

std::shared_ptr<const IdentifiedModel> identified(py::object model) {
  if (py::isinstance<py::str>(model))
    return std::make_shared<const IdentifiedModel>(IdentifiedModel::load(model.cast<std::string>()));
  try {
    return model.cast<std::shared_ptr<IdentifiedModel>>();
  } catch (const py::cast_error&) {
    throw py::value_error("model: expected a pegasus.IdentifiedModel or the path of a model.json");
  }
}

template <class T, std::size_t N>
void def_array(py::class_<T>& c, const char* name, std::array<double, N> T::*field, const char* doc) {
  c.def_property(
      name, [field](const T& t) { return vector_array(t.*field); },
      [field, name](T& t, py::object v) {
        const Array a = as_vector(v, name, static_cast<py::ssize_t>(N));
        require_finite(a, name);
        std::copy(a.data(), a.data() + N, (t.*field).begin());
      },
      doc);
}

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
                                                  const heli::HoverPolicyInit& init, py::object seed,
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

void bind_hover(py::module_& m) {
  auto options = py::class_<heli::HoverTrainingOptions>(m, "HoverTrainingOptions", R"doc(
`pegasus heli hover`'s training (thesis §5.3): 30 scenarios of 35 s, gamma 0.9995, gradient ascent then hill
climbing, on the identified model (heli/hover_task.hpp).)doc");
  options.def(py::init<>())
      .def_readwrite("scenarios", &heli::HoverTrainingOptions::scenarios)
      .def_readwrite("seconds", &heli::HoverTrainingOptions::seconds)
      .def_readwrite("gamma", &heli::HoverTrainingOptions::gamma)
      .def_readwrite("refit_every", &heli::HoverTrainingOptions::refit_every)
      .def_readwrite("control_rate_hz", &heli::HoverTrainingOptions::control_rate_hz)
      .def_readwrite("lqr_start", &heli::HoverTrainingOptions::lqr_start)
      .def_readwrite("lqr_action_factor", &heli::HoverTrainingOptions::lqr_action_factor)
      .def_readwrite("max_tilt_rad", &heli::HoverTrainingOptions::max_tilt_rad)
      .def_readwrite("target", &heli::HoverTrainingOptions::target)
      .def_readwrite("start_pos_sigma", &heli::HoverTrainingOptions::start_pos_sigma)
      .def_readwrite("start_vel_sigma", &heli::HoverTrainingOptions::start_vel_sigma)
      .def_readwrite("reward", &heli::HoverTrainingOptions::reward)
      .def_readwrite("centre_at_trim", &heli::HoverTrainingOptions::centre_at_trim)
      .def_readwrite("optimizer", &heli::HoverTrainingOptions::optimizer)
      .def_readwrite("then_hill_climb", &heli::HoverTrainingOptions::then_hill_climb)
      .def_readwrite("seed", &heli::HoverTrainingOptions::seed)
      .def_readwrite("max_start_crash_fraction", &heli::HoverTrainingOptions::max_start_crash_fraction)
      .def_readwrite("integral_seconds", &heli::HoverTrainingOptions::integral_seconds)
      .def_readwrite("integral_limit_position", &heli::HoverTrainingOptions::integral_limit_position)
      .def_readwrite("integral_limit_yaw", &heli::HoverTrainingOptions::integral_limit_yaw)
      .def("horizon", &heli::HoverTrainingOptions::horizon, "Steps of 1 / control_rate_hz.")
      .def("gamma_per_step", &heli::HoverTrainingOptions::gamma_per_step, "gamma^(50 / control_rate_hz).")
      .def(
          "refit_steps",
          [](const heli::HoverTrainingOptions& o, py::object model) {
            return o.refit_steps(*identified(model));
          },
          py::arg("model"), "refit_every, or the identified model's rate in steps when 0.")
      .def("is_valid", [](const heli::HoverTrainingOptions& o) {
        std::string error;
        const bool ok = o.IsValid(&error);
        return py::make_tuple(ok, error);
      });
  set_fields(options, {"scenarios",
                       "seconds",
                       "gamma",
                       "refit_every",
                       "control_rate_hz",
                       "lqr_start",
                       "lqr_action_factor",
                       "max_tilt_rad",
                       "target",
                       "start_pos_sigma",
                       "start_vel_sigma",
                       "reward",
                       "centre_at_trim",
                       "optimizer",
                       "then_hill_climb",
                       "seed",
                       "max_start_crash_fraction",
                       "integral_seconds",
                       "integral_limit_position",
                       "integral_limit_yaw"});

  auto problem = py::class_<HoverProblemObject, Objective>(m, "HoverProblem", R"doc(
PEGASUS U-hat (thesis §5.3) of the hover policy class (HoverPolicy(init), 34 weights) on a helicopter model, the
ground truth (Aircraft, Quadrotor) or the identified model (LearnedHeliModel): HoverTask adds the set point `target` and
the reward (Eqs 5.9-5.10) to the model's own; m scenarios of the given seed and variant, `horizon` 50 Hz steps,
discount gamma, evaluated on `threads` threads (the result never depends on them).
HoverProblem.from_training_options(model, options) is the objective `pegasus heli hover` maximises.)doc");
  problem
      .def(py::init([](py::object model, const SetPoint& target, const HoverReward& reward,
                       const heli::HoverPolicyInit& init, py::object seed, std::int64_t scenarios,
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
           py::arg("model"), py::kw_only(), py::arg("target") = SetPoint{}, py::arg("reward") = HoverReward{},
           py::arg("init") = heli::HoverPolicyInit{}, py::arg("seed"), py::arg("scenarios"),
           py::arg("horizon"), py::arg("gamma") = 0.9995, py::arg("variant") = "plain",
           py::arg("threads") = 1)
      .def_static(
          "from_training_options",
          [](py::object model, const heli::HoverTrainingOptions& o, std::int64_t threads) {
            std::string error;
            if (!o.IsValid(&error)) throw py::value_error("options." + error);
            auto inner = heli::hover_objective(identified(model), o, make_pool(threads));
            using Exact = PegasusObjective<HoverTask<LearnedHeliModel>, HoverPolicy>;
            const auto* raw = dynamic_cast<const Exact*>(inner.get());
            if (raw == nullptr) throw std::logic_error("hover_objective: unexpected objective type");
            return std::make_unique<HoverProblemObject>(std::move(inner), [raw](const Theta& t) {
              std::vector<double> out(static_cast<std::size_t>(raw->evaluator().scenarios().size()));
              raw->evaluator().per_scenario(t, out, nullptr);
              return out;
            });
          },
          py::arg("model"), py::arg("options") = heli::HoverTrainingOptions{}, py::kw_only(),
          py::arg("threads") = 1,
          "The objective `pegasus heli hover` maximises on an identified model (or model.json path): "
          "heli::hover_objective, the policy class and reward centred on the logs' trim.");
  bind_returns(problem);

  m.def(
      "hover_init_from_model",
      [](py::object model) { return heli::hover_init_from_model(*identified(model)); }, py::arg("model"),
      "The hover policy's starting weights around the trim estimate of the model's logs.");
  m.def(
      "lqr_hover_init",
      [](py::object model, const heli::HoverTrainingOptions& o) {
        const heli::LqrStart r = heli::lqr_hover_init(*identified(model), o);
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
      py::arg("model"), py::arg("options") = heli::HoverTrainingOptions{},
      "Starting gains by LQR on the identified model at the hover (`heli hover --starting-gains lqr`): a "
      "dict of "
      "init (HoverPolicyInit; the constants when not used), used, reason, spectral_radius, "
      "open_loop_radius.");
  m.def(
      "hover_reward_for",
      [](py::object model, const heli::HoverTrainingOptions& o) {
        return heli::hover_reward_for(*identified(model), o);
      },
      py::arg("model"), py::arg("options") = heli::HoverTrainingOptions{},
      "The reward of options, centred on the logs' trim when options.centre_at_trim.");

  auto start = py::class_<heli::StartingPolicyCheck>(m, "StartingPolicyCheck", R"doc(
The starting weights flown on the training scenarios of the learned model before hover training: train_hover
stops when more than options.max_start_crash_fraction of them crash (heli/hover_task.hpp).)doc");
  start.def_readonly("scenarios", &heli::StartingPolicyCheck::scenarios)
      .def_readonly("crashed", &heli::StartingPolicyCheck::crashed)
      .def_readonly("mean_seconds_to_crash", &heli::StartingPolicyCheck::mean_seconds_to_crash)
      .def_readonly("uhat", &heli::StartingPolicyCheck::uhat);
  set_fields(start, {"scenarios", "crashed", "mean_seconds_to_crash", "uhat"});

  auto result = py::class_<heli::HoverTrainingResult>(m, "HoverTrainingResult",
                                                      "What train_hover returns (heli/hover_task.hpp).");
  result
      .def_property_readonly("theta",
                             [](const heli::HoverTrainingResult& r) { return vector_array(r.theta); })
      .def_readonly("initial_uhat", &heli::HoverTrainingResult::initial_uhat)
      .def_readonly("final_uhat", &heli::HoverTrainingResult::final_uhat)
      .def_readonly("gradient", &heli::HoverTrainingResult::gradient)
      .def_readonly("hill_climb", &heli::HoverTrainingResult::hill_climb)
      .def_readonly("progress", &heli::HoverTrainingResult::progress)
      .def_readonly("start", &heli::HoverTrainingResult::start)
      .def_readonly("lqr_action_factor", &heli::HoverTrainingResult::lqr_action_factor);
  set_fields(result, {"theta", "initial_uhat", "final_uhat", "gradient", "hill_climb", "progress", "start",
                      "lqr_action_factor"});
  m.def(
      "train_hover",
      [](py::object model, const heli::HoverTrainingOptions& o, std::int64_t checkpoint_every,
         py::object on_checkpoint, py::object resume_from, py::object callbacks, std::int64_t threads) {
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
        const auto shared = identified(model);
        const auto pool = make_pool(threads);
        py::gil_scoped_release release;
        return heli::train_hover(shared, o, hooks, *pool);
      },
      py::arg("model"), py::arg("options") = heli::HoverTrainingOptions{}, py::kw_only(),
      py::arg("checkpoint_every") = 1, py::arg("on_checkpoint") = py::none(),
      py::arg("resume_from") = py::none(), py::arg("callbacks") = py::none(), py::arg("threads") = 1,
      "Trains the hover controller as `pegasus heli hover` does (the same plan, checkpoints and bits for any "
      "threads); checkpoints are training-plan checkpoints (dicts).");
}

}  // namespace

void bind_heli(py::module_& m) {
  auto sp = py::class_<SetPoint>(m, "SetPoint",
                                 "Where the helicopter should be: x, y, z in the world frame (NED, m; "
                                 "z < 0 is above the ground) and the heading yaw (rad).");
  sp.def(py::init(&set_point), py::arg("x") = 0.0, py::arg("y") = 0.0, py::arg("z") = -10.0,
         py::arg("yaw") = 0.0)
      .def_readwrite("x", &SetPoint::x)
      .def_readwrite("y", &SetPoint::y)
      .def_readwrite("z", &SetPoint::z)
      .def_readwrite("yaw", &SetPoint::yaw);
  set_fields(sp, {"x", "y", "z", "yaw"});

  auto reward = py::class_<HoverReward>(m, "HoverReward", R"doc(
The hover reward of thesis §5.3 (Eqs 5.9-5.10): minus the weighted squared position, velocity and wrapped yaw
errors, minus the weighted squared controls about `centre` (heli/hover_task.hpp).)doc");
  reward.def(py::init<>());
  def_array(reward, "alpha_pos", &HoverReward::alpha_pos, "Per m^2, x y z.");
  def_array(reward, "alpha_vel", &HoverReward::alpha_vel, "Per (m/s)^2.");
  reward.def_readwrite("alpha_yaw", &HoverReward::alpha_yaw, "Per rad^2.");
  def_array(reward, "alpha_action", &HoverReward::alpha_action, "Per unit^2 about centre.");
  def_array(reward, "centre", &HoverReward::centre, "The controls the action cost is taken about.");
  def_array(reward, "alpha_attitude", &HoverReward::alpha_attitude,
            "Per rad^2 of roll and pitch (about level).");
  def_array(reward, "alpha_rate", &HoverReward::alpha_rate,
            "Per (rad/s)^2 of the roll, pitch and yaw rates.");
  reward
      .def_static(
          "from_typical",
          [](double position_m, double velocity_mps, double yaw_rad, double action, py::object centre) {
            const Array c = as_vector(centre, "centre", 4);
            require_finite(c, "centre");
            return HoverReward::from_typical(position_m, velocity_mps, yaw_rad, action,
                                             controls_row(c.data()));
          },
          py::arg("position_m"), py::arg("velocity_mps"), py::arg("yaw_rad"), py::arg("action"),
          py::arg("centre") = std::vector<double>{0, 0, 0, 0}, "alpha = 1 / typical^2 for each term.")
      .def("is_valid", [](const HoverReward& r) {
        std::string error;
        const bool ok = r.IsValid(&error);
        return py::make_tuple(ok, error);
      });
  set_fields(reward, {"alpha_pos", "alpha_vel", "alpha_yaw", "alpha_action", "centre", "alpha_attitude",
                      "alpha_rate"});

  auto init = py::class_<heli::HoverPolicyInit>(m, "HoverPolicyInit", R"doc(
The hover policy class's starting weights: a linear controller around a trim (heli/hover_policy.hpp).)doc");
  init.def(py::init<>());
  def_array(init, "trim", &heli::HoverPolicyInit::trim, "Controls that hold a hover.");
  init.def_readwrite("trim_roll", &heli::HoverPolicyInit::trim_roll)
      .def_readwrite("trim_pitch", &heli::HoverPolicyInit::trim_pitch)
      .def_readwrite("k_pos", &heli::HoverPolicyInit::k_pos)
      .def_readwrite("k_vel", &heli::HoverPolicyInit::k_vel)
      .def_readwrite("k_att", &heli::HoverPolicyInit::k_att)
      .def_readwrite("k_pos_lat", &heli::HoverPolicyInit::k_pos_lat)
      .def_readwrite("k_vel_lat", &heli::HoverPolicyInit::k_vel_lat)
      .def_readwrite("k_roll", &heli::HoverPolicyInit::k_roll)
      .def_readwrite("k_alt", &heli::HoverPolicyInit::k_alt)
      .def_readwrite("k_climb", &heli::HoverPolicyInit::k_climb)
      .def_readwrite("k_yaw", &heli::HoverPolicyInit::k_yaw)
      .def_readwrite("k_yaw_rate", &heli::HoverPolicyInit::k_yaw_rate)
      .def_readwrite("integral_seconds", &heli::HoverPolicyInit::integral_seconds);
  set_fields(init, {"trim", "trim_roll", "trim_pitch", "k_pos", "k_vel", "k_att", "k_pos_lat", "k_vel_lat",
                    "k_roll", "k_alt", "k_climb", "k_yaw", "k_yaw_rate", "integral_seconds"});

  py::class_<HoverPolicy>(m, "HoverPolicy", R"doc(
The hover policy class of thesis §5.3 (Fig 5.4, Eqs 5.7-5.8): 34 weights, one tanh network per control channel
fed by the body-frame errors, velocities and attitude.)doc")
      .def(py::init<const heli::HoverPolicyInit&>(), py::arg("init") = heli::HoverPolicyInit{})
      .def_property_readonly("parameters", &HoverPolicy::parameters,
                             py::return_value_policy::reference_internal)
      .def(
          "act",
          [](const HoverPolicy& policy, py::object theta, py::object states, const SetPoint& target) {
            const Theta w = as_theta(theta, "theta", policy.parameters());
            const Array s = as_matrix(states, "states", -1, kLogged);
            require_finite(s, "states");
            Array out = matrix(s.shape(0), 4);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              heli::HeliObservation o;
              std::copy(s.data() + r * kLogged, s.data() + (r + 1) * kLogged, o.state.begin());
              o.target = target;
              const Controls u = policy.act(w, o);
              std::copy(u.begin(), u.end(), out.mutable_data() + r * 4);
            }
            return out;
          },
          py::arg("theta"), py::arg("states"), py::arg("target") = SetPoint{},
          "The clipped controls [n, 4] of theta for logged states [n, 12] steering to target.");

  auto params = py::class_<AircraftParams>(m, "AircraftParams", R"doc(
The ground-truth helicopter's parameters (heli/aircraft.hpp: the X-Cell 60 of Gavrilets, Mettler and Feron, rotor,
servos, disturbances, crash limits, integration, start), every field with the C++ name and unit.)doc");
  params.def(py::init<>());
  std::vector<const char*> own;  // the fields this aircraft alone has, in order
#define PEGASUS_PARAM(field) (params.def_readwrite(#field, &AircraftParams::field), own.push_back(#field))
  PEGASUS_PARAM(mass_kg);
  PEGASUS_PARAM(ixx);
  PEGASUS_PARAM(iyy);
  PEGASUS_PARAM(izz);
  PEGASUS_PARAM(gravity);
  PEGASUS_PARAM(air_density);
  PEGASUS_PARAM(omega_mr);
  PEGASUS_PARAM(radius_mr);
  PEGASUS_PARAM(chord_mr);
  PEGASUS_PARAM(lift_slope_mr);
  PEGASUS_PARAM(profile_drag_mr);
  PEGASUS_PARAM(hub_height);
  PEGASUS_PARAM(hub_stiffness);
  PEGASUS_PARAM(tau_flap);
  PEGASUS_PARAM(a_lon);
  PEGASUS_PARAM(b_lat);
  PEGASUS_PARAM(cyclic_max_rad);
  PEGASUS_PARAM(collective_mid_rad);
  PEGASUS_PARAM(collective_span_rad);
  PEGASUS_PARAM(gear_tr);
  PEGASUS_PARAM(radius_tr);
  PEGASUS_PARAM(chord_tr);
  PEGASUS_PARAM(lift_slope_tr);
  PEGASUS_PARAM(arm_tr);
  PEGASUS_PARAM(height_tr);
  PEGASUS_PARAM(tail_mid_rad);
  PEGASUS_PARAM(tail_span_rad);
  PEGASUS_PARAM(gyro_gain);
  PEGASUS_PARAM(gyro_tau);
  PEGASUS_PARAM(fus_area_x);
  PEGASUS_PARAM(fus_area_y);
  PEGASUS_PARAM(fus_area_z);
  PEGASUS_PARAM(servo_rate);
  PEGASUS_PARAM(max_thrust_coeff_over_solidity);
#undef PEGASUS_PARAM
  bind_ground_truth_params(params, std::move(own));

  auto aircraft = py::class_<Aircraft>(m, "Aircraft", R"doc(
The ground-truth helicopter (heli/aircraft.hpp): a nonlinear 6-DOF model of the X-Cell 60 stepped at 50 Hz, with
turbulence and state-estimate errors drawn from the uniforms of each step (noise_dim 15, initial_noise_dim 21).
A state row has 36 columns (STATE_COLUMNS: position p_W and velocity v_B, attitude, rates w_B, flapping, gyro,
servos, gusts, estimate errors, time, crash code); observe() gives the 12 logged states a flight computer sees.)doc");
  aircraft
      .def(py::init([](const AircraftParams& p) {
             std::string error;
             if (!p.IsValid(&error)) throw py::value_error("params." + error);
             return Aircraft(p);
           }),
           py::arg("params") = AircraftParams{})
      .def_property_readonly("params", &Aircraft::params)
      .def_property_readonly_static("STATE_COLUMNS", [](py::object) { return aircraft_columns(); })
      .def_property_readonly(
          "hover_trim",
          [](const Aircraft& a) {
            py::dict d;
            d["controls"] = vector_array(a.hover_trim().controls);
            d["roll"] = a.hover_trim().roll;
            d["pitch"] = a.hover_trim().pitch;
            d["residual"] = a.hover_trim().residual;
            return d;
          },
          "The hover trim (Newton's method): controls, roll, pitch, residual acceleration.")
      .def(
          "true_state",
          [](const Aircraft&, py::object states) {
            const Array s = as_matrix(states, "states", -1, kAircraftColumns);
            Array out = matrix(s.shape(0), kLogged);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const LoggedState x =
                  heli::true_logged_state(aircraft_row(s.data() + r * kAircraftColumns, r, "states"));
              std::copy(x.begin(), x.end(), out.mutable_data() + r * kLogged);
            }
            return out;
          },
          py::arg("states"), "The true 12 logged states (no estimate error), [n, 12].")
      .def(
          "crash_reason",
          [](const Aircraft&, py::object states) {
            const Array s = as_matrix(states, "states", -1, kAircraftColumns);
            std::vector<std::string> out;
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.push_back(
                  heli::crash_reason_name(aircraft_row(s.data() + r * kAircraftColumns, r, "states").crash));
            return out;
          },
          py::arg("states"), "Why each row crashed ('none' when it has not).");
  HeliBatch<Aircraft>::bind(aircraft);

  m.def(
      "fly_pilot",
      [](const std::string& simulator, double seconds, std::uint64_t seed, double gust_sigma,
         bool estimate_noise, double hover_seconds, bool sweeps) {
        heli::GroundTruthSettings settings;
        settings.gust_sigma = gust_sigma;
        settings.estimate_noise = estimate_noise;
        std::unique_ptr<heli::GroundTruth> ground_truth;
        try {
          ground_truth = heli::make_ground_truth(simulator, settings);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        if (!(seconds > 0 && seconds <= 36000))
          throw py::value_error("seconds: expected a number in (0, 36000]");
        heli::PilotOptions options = heli::pilot_options_for(simulator);
        options.hover_seconds = hover_seconds;
        options.sweeps = sweeps;
        std::string error;
        if (!options.IsValid(&error)) throw py::value_error(error);
        heli::PilotFlight f;
        {
          py::gil_scoped_release release;
          f = heli::fly_pilot(*ground_truth, options, seconds, seed);
        }
        Array truth = matrix(static_cast<py::ssize_t>(f.truth.size()), heli::kLoggedStates);
        for (std::size_t r = 0; r < f.truth.size(); ++r)
          std::copy(f.truth[r].begin(), f.truth[r].end(), truth.mutable_data() + r * heli::kLoggedStates);
        py::dict out;
        out["log"] = std::move(f.log);
        out["truth"] = truth;
        out["crash"] = heli::crash_reason_name(f.crash);
        out["crash_time"] = f.crash_time;
        return out;
      },
      py::arg("simulator") = "xcell", py::arg("seconds") = 60.0, py::arg("seed") = 1,
      py::arg("gust_sigma") = -1.0, py::arg("estimate_noise") = true, py::arg("hover_seconds") = 10.0,
      py::arg("sweeps") = true,
      R"doc(The scripted pilot flies a built-in ground truth ("xcell": the X-Cell 60; "crazyflie2": the Crazyflie 2.0
quadrotor) as `pegasus pilot --vehicle` does: a hover, then a frequency sweep in each channel. Returns a dict:
"log" (FlightLog of the state estimates and controls at 50 Hz), "truth" (the true states, rows x 12), "crash"
('none' or why) and "crash_time" (s, -1 without a crash). gust_sigma < 0 keeps the aircraft's own.)doc");

  auto lmo = py::class_<LearnedModelOptions>(m, "LearnedModelOptions", R"doc(
How the identified model is flown as a 50 Hz simulator (sysid/learned_model.hpp): refit period, support margin,
crash penalty (footnote 13), noise on or off, and the start state and its perturbation.)doc");
  lmo.def(py::init<>())
      .def_readwrite("dt", &LearnedModelOptions::dt)
      .def_readwrite("refit_every", &LearnedModelOptions::refit_every)
      .def_readwrite("support_bandwidths", &LearnedModelOptions::support_bandwidths)
      .def_readwrite("crash_reward", &LearnedModelOptions::crash_reward)
      .def_readwrite("max_tilt_rad", &LearnedModelOptions::max_tilt_rad)
      .def_readwrite("noise", &LearnedModelOptions::noise);
  def_array(lmo, "start", &LearnedModelOptions::start, "The 12 logged states before perturbation.");
  lmo.def_readwrite("start_pos_sigma", &LearnedModelOptions::start_pos_sigma)
      .def_readwrite("start_vel_sigma", &LearnedModelOptions::start_vel_sigma)
      .def("is_valid", [](const LearnedModelOptions& o) {
        std::string error;
        const bool ok = o.IsValid(&error);
        return py::make_tuple(ok, error);
      });
  set_fields(lmo, {"dt", "refit_every", "support_bandwidths", "crash_reward", "max_tilt_rad", "noise",
                   "start", "start_pos_sigma", "start_vel_sigma"});

  auto learned = py::class_<LearnedHeliModel>(m, "LearnedHeliModel", R"doc(
The identified helicopter (an IdentifiedModel, or the path of a model.json from `pegasus heli identify`) as a
deterministic 50 Hz simulator g(s, a, p) (thesis §5.2.2): locally weighted regression refitted every refit_every
steps, noise_dim 8, initial_noise_dim 6. A state row has 153 columns (STATE_COLUMNS: the 12 logged states first,
then the extra states, the held coefficients, the predictive variance, the step and the crash flag); reward()
is the crash penalty.)doc");
  learned
      .def(py::init([](py::object model, const LearnedModelOptions& o) {
             std::string error;
             if (!o.IsValid(&error)) throw py::value_error("options." + error);
             return LearnedHeliModel(identified(model), o);
           }),
           py::arg("model"), py::arg("options") = LearnedModelOptions{})
      .def_property_readonly("options", &LearnedHeliModel::options)
      .def_property_readonly_static("STATE_COLUMNS", [](py::object) { return learned_columns(); })
      .def(
          "reward",
          [](const LearnedHeliModel& model, py::object states, py::object actions, py::object next) {
            const Array s = as_matrix(states, "states", -1, kLearnedColumns);
            const Array a = as_matrix(actions, "actions", s.shape(0), 4);
            const Array n = as_matrix(next, "next_states", s.shape(0), kLearnedColumns);
            Array out(s.shape(0));
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.mutable_data()[r] = model.reward(
                  learned_row(s.data() + r * kLearnedColumns, r, "states"), controls_row(a.data() + 4 * r),
                  learned_row(n.data() + r * kLearnedColumns, r, "next_states"));
            return out;
          },
          py::arg("states"), py::arg("actions"), py::arg("next_states"),
          "The crash penalty of each transition (0 unless it crashed).");
  HeliBatch<LearnedHeliModel>::bind(learned);

  bind_hover(m);
  bind_heli_policy_files(m);
}

}  // namespace pegasus::python
