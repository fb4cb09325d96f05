// Simulators and policies written in Python over a batch of rollouts (numpy), evaluated by PEGASUS on fixed
// scenarios (thesis §4.4.2, Eq 4.22). Every (theta, scenario) pair of an evaluation is one row of the batch,
// so a gradient's 2n+1 policies over m scenarios cost a handful of Python calls per time step, not one per
// rollout.
#include <fmt/format.h>

#include <cmath>
#include <numeric>

#include "builtin_problem.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/policies/policies.hpp"

namespace pegasus::python {

namespace {

// a = squash(W o) on a box action space: LinearPolicy (clip) and SigmoidPolicy (low + (high - low) sigmoid)
// of policies/policies.hpp with the observation itself as the features, over a batch of rows.
class BoxPolicy {
 public:
  BoxPolicy(std::int64_t observation_dim, const std::vector<double>& low, const std::vector<double>& high,
            bool sigmoid, double scale)
      : observation_dim_(static_cast<int>(observation_dim)), low_(low), high_(high), sigmoid_(sigmoid) {
    if (observation_dim < 1 || observation_dim > 100000)
      throw py::value_error(
          fmt::format("observation_dim: expected an integer in [1, 100000], got {}", observation_dim));
    if (low.empty() || low.size() != high.size())
      throw py::value_error("low, high: expected two non-empty lists of the same length");
    for (std::size_t k = 0; k < low.size(); ++k)
      if (!(std::isfinite(low[k]) && std::isfinite(high[k]) && low[k] <= high[k]))
        throw py::value_error(
            fmt::format("low, high: expected finite bounds with low <= high, got [{}, {}] for "
                        "action {}",
                        low[k], high[k], k));
    if (!(scale > 0.0 && std::isfinite(scale)))
      throw py::value_error(fmt::format("scale: expected a finite number > 0, got {}", scale));
    spec_ = detail::weight_spec(static_cast<int>(low.size()), observation_dim_, {}, {}, scale);
  }
  const ParameterSpec& parameters() const { return spec_; }
  int observation_dim() const { return observation_dim_; }
  int action_dim() const { return static_cast<int>(low_.size()); }
  bool sigmoid() const { return sigmoid_; }

  // actions[j] = policy(theta_of(j), observations[j]) for each row j.
  template <class ThetaOf>
  void act(ThetaOf theta_of, const double* observations, std::size_t rows, double* actions) const {
    const auto n = static_cast<std::size_t>(observation_dim_), na = low_.size();
    for (std::size_t j = 0; j < rows; ++j) {
      const double* w = theta_of(j);
      const double* o = observations + j * n;
      for (std::size_t k = 0; k < na; ++k) {
        double z = 0;
        for (std::size_t f = 0; f < n; ++f) z += w[k * n + f] * o[f];
        actions[j * na + k] =
            sigmoid_ ? SigmoidToBox{}(z, low_[k], high_[k]) : ClipToBox{}(z, low_[k], high_[k]);
      }
    }
  }

  Array act_py(ArrayLikeArg thetas, ArrayLikeArg observations) const {
    const Array o = as_matrix(observations, "observations", -1, observation_dim_);
    const auto rows = o.shape(0);
    Array th = as_array(thetas, "thetas");
    const auto np = static_cast<py::ssize_t>(spec_.size());
    if (th.ndim() == 1)
      th = as_matrix(th.reshape({py::ssize_t{1}, th.shape(0)}), "thetas", 1, np);
    else
      th = as_matrix(th, "thetas", rows, np);
    require_finite(th, "thetas");
    const bool one = th.shape(0) == 1;
    Array out = matrix(rows, action_dim());
    act([&](std::size_t j) { return th.data() + (one ? 0 : static_cast<py::ssize_t>(j) * np); }, o.data(),
        static_cast<std::size_t>(rows), out.mutable_data());
    return out;
  }

 private:
  int observation_dim_;
  std::vector<double> low_, high_;
  bool sigmoid_;
  ParameterSpec spec_;
};

// A read-only view of `a` for a user's method: the rollout keeps using the array afterwards, so a method
// that changed its argument in place (`o *= 2`) would change the rollout behind the caller's back.
py::object read_only(const Array& a) {
  py::object view = a.attr("view")();
  view.attr("setflags")(py::arg("write") = false);
  return view;
}

int int_attribute(const UserObjectArg& model, const char* name) {
  if (!py::hasattr(model, name)) throw py::value_error(fmt::format("model: expected an attribute {}", name));
  const py::object value = model.attr(name);
  if (!py::isinstance<py::int_>(value))
    throw py::value_error(fmt::format("model.{}: expected an integer", name));
  const auto v = value.cast<long long>();
  if (v < 0 || v > 100000)
    throw py::value_error(fmt::format("model.{}: expected an integer in [0, 100000], got {}", name, v));
  return static_cast<int>(v);
}

py::object method(const py::object& object, const char* owner, const char* name, bool required) {
  if (!py::hasattr(object, name)) {
    if (required) throw py::value_error(fmt::format("{}: expected a method {}", owner, name));
    return py::none();
  }
  py::object f = object.attr(name);
  if (!PyCallable_Check(f.ptr())) throw py::value_error(fmt::format("{}.{}: expected a method", owner, name));
  return f;
}

// The PEGASUS objective of a Python model and a Python or built-in policy (see the module docstring).
class VectorizedProblem final : public Objective {
 public:
  VectorizedProblem(UserObjectArg model, UserObjectArg policy, SeedArg seed, std::int64_t scenarios,
                    std::int64_t horizon, double gamma, const std::string& variant, std::int64_t threads)
      : pool_(make_pool(threads)),
        model_(std::move(model)),
        policy_(std::move(policy)),
        scenarios_(make_scenario_set(seed, scenarios, horizon, int_attribute(model_, "noise_dim"),
                                     int_attribute(model_, "initial_noise_dim"), variant, "scenarios")),
        discounting_{gamma, static_cast<int>(horizon)} {
    if (!(gamma >= 0.0 && gamma <= 1.0))
      throw py::value_error(fmt::format("gamma: expected a number in [0, 1], got {}", gamma));
    initial_state_ = method(model_, "model", "initial_state", true);
    step_ = method(model_, "model", "step", true);
    reward_ = method(model_, "model", "reward", true);
    terminal_ = method(model_, "model", "terminal", false);
    observe_ = method(model_, "model", "observe", false);
    event_fraction_ = method(model_, "model", "event_fraction", false);
    if (py::isinstance<BoxPolicy>(policy_)) {
      box_ = policy_.cast<const BoxPolicy*>();
      spec_ = box_->parameters();
    } else {
      act_ = method(policy_, "policy", "act", true);
      if (!py::hasattr(policy_, "parameters"))
        throw py::value_error("policy: expected an attribute parameters (a ParameterSpec)");
      try {
        spec_ = policy_.attr("parameters").cast<ParameterSpec>();
      } catch (const py::cast_error&) {
        throw py::value_error("policy.parameters: expected a pegasus.ParameterSpec");
      }
    }
  }

  const ParameterSpec& parameters() const override { return spec_; }
  const ScenarioSet& scenarios() const { return scenarios_; }
  const Discounting& discounting() const { return discounting_; }
  int threads() const { return pool_->size(); }

  double evaluate(std::span<const double> theta) override {
    const Theta t(theta.begin(), theta.end());
    double value = 0.0;
    evaluate_batch(std::span<const Theta>(&t, 1), std::span<double>(&value, 1));
    return value;
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    const auto m = static_cast<std::size_t>(scenarios_.size());
    const std::vector<double> returns = rollouts(thetas);
    for (std::size_t k = 0; k < thetas.size(); ++k)
      values[k] = ordered_mean(std::span<const double>(returns.data() + k * m, m));
  }

  // The return of every (theta k, scenario i) pair at [k * m + i]. Takes the GIL.
  std::vector<double> rollouts(std::span<const Theta> thetas) {
    py::gil_scoped_acquire gil;
    if (busy_)
      throw std::runtime_error(
          "VectorizedProblem: already evaluating (one evaluation at a time per problem; make one per "
          "thread)");
    busy_ = true;
    struct Done {
      bool& busy;
      ~Done() { busy = false; }
    } release_busy{busy_};
    const auto m = static_cast<std::size_t>(scenarios_.size());
    const std::size_t n = thetas.size() * m;
    const auto d0 = static_cast<std::size_t>(scenarios_.initial_noise_dim());
    const auto dp = static_cast<std::size_t>(scenarios_.noise_dim());
    std::vector<double> returns(n, 0.0);
    if (n == 0) return returns;
    std::vector<std::size_t> rows(n);  // the pair of each live rollout, in pair order
    std::iota(rows.begin(), rows.end(), std::size_t{0});

    Array noise0 = matrix(static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(d0));
    double* p0 = noise0.mutable_data();
    pool_->parallel_for(n, [&](std::size_t r) {
      scenarios_.initial_noise(static_cast<int>(r % m), std::span<double>(p0 + r * d0, d0));
    });
    theta_rows_ = py::none();  // the policy's theta rows are rebuilt when the live rows change
    Array states = as_matrix(initial_state_(read_only(noise0)), "model.initial_state result",
                             static_cast<py::ssize_t>(n), -1);
    const py::ssize_t ds = states.shape(1);
    if (ds < 1) throw py::value_error("model.initial_state result: expected at least one state column");
    require_finite(states, "model.initial_state result");
    // Each array a user's method gets is a read-only view, made once per array (a state's serves terminal,
    // observe, step and reward).
    py::object states_view = read_only(states);

    double weight = 1.0;
    const double gamma = discounting_.gamma;
    for (int t = 0; t < discounting_.horizon; ++t) {
      if (!terminal_.is_none()) {  // absorbing states take no more steps and earn nothing (rollout.hpp)
        const Array done =
            as_vector(terminal_(states_view), "model.terminal result", static_cast<py::ssize_t>(rows.size()));
        std::vector<std::size_t> keep;
        for (std::size_t j = 0; j < rows.size(); ++j) {
          const double d = done.data()[j];
          if (d != 0.0 && d != 1.0)  // 0.5 or NaN would silently count as absorbed
            throw py::value_error(
                fmt::format("model.terminal result: expected booleans (or 0 and 1), got {} at row {}", d, j));
          if (d == 0.0) keep.push_back(j);
        }
        if (keep.size() != rows.size()) {
          Array live = matrix(static_cast<py::ssize_t>(keep.size()), ds);
          for (std::size_t j = 0; j < keep.size(); ++j) {
            std::copy_n(states.data() + keep[j] * static_cast<std::size_t>(ds), ds,
                        live.mutable_data() + j * static_cast<std::size_t>(ds));
            rows[j] = rows[keep[j]];
          }
          rows.resize(keep.size());
          states = std::move(live);
          states_view = read_only(states);
          theta_rows_ = py::none();
        }
        if (rows.empty()) break;
      }
      const auto na = static_cast<py::ssize_t>(rows.size());
      Array observations = states;
      py::object observations_view = states_view;
      if (!observe_.is_none()) {
        observations = as_matrix(observe_(states_view), "model.observe result", na, -1);
        require_finite(observations, "model.observe result");
        observations_view = read_only(observations);
      }
      const Array actions = act(thetas, rows, m, observations, observations_view);
      const py::object actions_view = read_only(actions);
      Array noise = matrix(na, static_cast<py::ssize_t>(dp));
      double* pt = noise.mutable_data();
      pool_->parallel_for(rows.size(), [&](std::size_t j) {
        scenarios_.step_noise(static_cast<int>(rows[j] % m), t, std::span<double>(pt + j * dp, dp));
      });
      Array next = as_matrix(step_(states_view, actions_view, read_only(noise)), "model.step result", na, ds);
      require_finite(next, "model.step result");
      py::object next_view = read_only(next);
      const Array r = as_vector(reward_(states_view, actions_view, next_view), "model.reward result", na);
      require_finite(r, "model.reward result");
      const double* rp = r.data();
      if (!event_fraction_.is_none()) {  // continuous-time discounting (footnote 9 of §4.4)
        const Array tau = as_vector(event_fraction_(states_view, actions_view, next_view),
                                    "model.event_fraction result", na);
        for (std::size_t j = 0; j < rows.size(); ++j) {
          const double f = tau.data()[j];
          if (!(f >= 0.0 && f <= 1.0))
            throw py::value_error(fmt::format(
                "model.event_fraction result: expected numbers in [0, 1], got {} at row {}", f, j));
          returns[rows[j]] += f > 0.0 ? rp[j] * weight * std::pow(gamma, f) : rp[j] * weight;
        }
      } else {
        for (std::size_t j = 0; j < rows.size(); ++j) returns[rows[j]] += rp[j] * weight;
      }
      weight *= gamma;
      states = std::move(next);
      states_view = std::move(next_view);
    }
    return returns;
  }

 private:
  // `observations_view` is the read-only view of `observations` a Python policy gets.
  Array act(std::span<const Theta> thetas, const std::vector<std::size_t>& rows, std::size_t m,
            const Array& observations, const py::object& observations_view) {
    const auto na = static_cast<py::ssize_t>(rows.size());
    const std::size_t np = spec_.size();
    if (box_) {
      if (observations.shape(1) != box_->observation_dim())
        throw py::value_error(fmt::format("model.observe result: expected {} columns for the policy, got {}",
                                          box_->observation_dim(), observations.shape(1)));
      Array out = matrix(na, box_->action_dim());
      const auto no = static_cast<std::size_t>(box_->observation_dim()),
                 nu = static_cast<std::size_t>(box_->action_dim());
      const double* o = observations.data();
      double* u = out.mutable_data();
      pool_->parallel_for_chunks(rows.size(), 0, [&](std::size_t begin, std::size_t end) {
        box_->act([&](std::size_t j) { return thetas[rows[begin + j] / m].data(); }, o + begin * no,
                  end - begin, u + begin * nu);
      });
      return out;
    }
    if (theta_rows_.is_none()) {  // the same rows as the last step: the same (read-only) array again
      Array theta_rows = matrix(na, static_cast<py::ssize_t>(np));
      double* w = theta_rows.mutable_data();
      pool_->parallel_for(rows.size(),
                          [&](std::size_t j) { std::copy_n(thetas[rows[j] / m].data(), np, w + j * np); });
      theta_rows.attr("setflags")(py::arg("write") = false);
      theta_rows_ = std::move(theta_rows);
    }
    Array a = as_array(act_(theta_rows_, observations_view), "policy.act result");
    if (a.ndim() == 1) a = as_matrix(a.reshape({a.shape(0), py::ssize_t{1}}), "policy.act result", na, 1);
    a = as_matrix(a, "policy.act result", na, -1);
    require_finite(a, "policy.act result");
    return a;
  }

  std::shared_ptr<ThreadPool> pool_;
  py::object model_, policy_;
  ScenarioSet scenarios_;
  Discounting discounting_;
  ParameterSpec spec_;
  const BoxPolicy* box_ = nullptr;
  py::object initial_state_, step_, reward_, terminal_, observe_, event_fraction_, act_;
  py::object theta_rows_ =
      py::none();      // the theta of each live row, as handed to policy.act (None: to be rebuilt)
  bool busy_ = false;  // an evaluation is running (the Python calls may let another thread in)
};

}  // namespace

void bind_vectorized(py::module_& m) {
  py::class_<BoxPolicy>(m, "BoxPolicy", R"doc(
Built-in policy class over a batch: a = squash(W o), W the parameters "w.a<k>.x<f>" (action k, observation f),
squash a clip to [low, high] (LinearPolicy) or low + (high - low) sigmoid (SigmoidPolicy, the bicycle's form,
thesis §4.6). Computed in C++: no Python call per step.)doc")
      .def_property_readonly("parameters", &BoxPolicy::parameters, py::return_value_policy::copy,
                             "The ParameterSpec of W: action_dim * observation_dim weights \"w.a<k>.x<f>\", "
                             "row by row.")
      .def_property_readonly("observation_dim", &BoxPolicy::observation_dim,
                             "Numbers per observation row (the columns of W).")
      .def_property_readonly("action_dim", &BoxPolicy::action_dim,
                             "Numbers per action row, len(low) (the rows of W).")
      .def("act", &BoxPolicy::act_py, py::arg("thetas"), py::arg("observations"),
           "Actions [n, da] of the rows of observations [n, do] under thetas [n, n_params] (or one theta).");
  m.def(
      "LinearPolicy",
      [](std::int64_t observation_dim, const std::vector<double>& low, const std::vector<double>& high,
         double scale) { return BoxPolicy(observation_dim, low, high, false, scale); },
      py::arg("observation_dim"), py::arg("low"), py::arg("high"), py::arg("scale") = 1.0,
      "a = clip(W o, low, high): a BoxPolicy.");
  m.def(
      "SigmoidPolicy",
      [](std::int64_t observation_dim, const std::vector<double>& low, const std::vector<double>& high,
         double scale) { return BoxPolicy(observation_dim, low, high, true, scale); },
      py::arg("observation_dim"), py::arg("low"), py::arg("high"), py::arg("scale") = 1.0,
      "a = low + (high - low) sigmoid(W o): a BoxPolicy.");

  py::class_<VectorizedProblem, Objective>(m, "VectorizedProblem", R"doc(
PEGASUS U-hat (thesis Eq 4.22) of a simulator written in Python, vectorised over rollouts.

model: an object with
  noise_dim, initial_noise_dim            ints: uniforms per step and for the initial state
  initial_state(noise[n, d0]) -> states[n, ds]
  step(states[n, ds], actions[n, da], noise[n, dp]) -> next_states[n, ds]   (a new array; deterministic)
  reward(states, actions, next_states) -> [n]          R(s, a, s') of each row
  terminal(states) -> [n] bools                        optional: absorbing states take no more steps
  observe(states) -> observations[n, do]               optional: the policy sees the state itself
  event_fraction(states, actions, next_states) -> [n]  optional: tau in [0, 1], the transition's reward is
                                                       discounted by gamma^(t + tau) (§4.4 footnote 9)
policy: a BoxPolicy (LinearPolicy, SigmoidPolicy) or an object with `parameters` (a ParameterSpec) and
  act(thetas[n, n_params], observations[n, do]) -> actions[n, da] (or [n]).
Each method is called once per time step for all live (theta, scenario) pairs of an evaluation; the noise
is the scenario set's (seed, scenarios, horizon, variant), the same numbers as the C++ evaluators'.
threads: as --threads, and the result is bit-identical for any number. The model's and a Python policy's
methods are Python calls and run one after another under the GIL (numpy itself may use several cores); the
threads share what C++ does per step over the rows: the scenario noise, a built-in policy's actions
(BoxPolicy) and the theta rows handed to policy.act. Every row is computed alone and the returns are
accumulated per row in time order and summed in scenario order, so no result depends on the thread count.
policy.act receives the same read-only thetas array on consecutive steps while the live rows do not change.)doc")
      .def(py::init<UserObjectArg, UserObjectArg, SeedArg, std::int64_t, std::int64_t, double,
                    const std::string&, std::int64_t>(),
           py::arg("model"), py::arg("policy"), py::kw_only(), py::arg("seed"), py::arg("scenarios"),
           py::arg("horizon"), py::arg("gamma") = 1.0, py::arg("variant") = "plain", py::arg("threads") = 1,
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>())
      .def_property_readonly("threads", &VectorizedProblem::threads,
                             "Worker threads, as --threads (the result never depends on them).")
      .def_property_readonly("scenarios", &VectorizedProblem::scenarios,
                             "The ScenarioSet whose numbers every evaluation uses.")
      .def_property_readonly(
          "gamma", [](const VectorizedProblem& p) { return p.discounting().gamma; },
          "Discount per step, in [0, 1].")
      .def_property_readonly(
          "horizon", [](const VectorizedProblem& p) { return p.discounting().horizon; },
          "Rollout length H, steps.")
      .def(
          "returns",
          [](VectorizedProblem& p, ArrayLikeArg thetas) {
            const std::vector<Theta> ts = as_thetas(thetas, "thetas", p.parameters());
            const std::vector<double> r = p.rollouts(ts);
            Array out = matrix(static_cast<py::ssize_t>(ts.size()), p.scenarios().size());
            std::copy(r.begin(), r.end(), out.mutable_data());
            return out;
          },
          py::arg("thetas"), "Per-scenario returns [K, m] of each theta (U-hat is each row's mean).");
}

}  // namespace pegasus::python
