#pragma once
// The batch interface of the aircraft models in Python (heli.cpp: the X-Cell ground truth and the identified
// model; quadrotor.cpp: the Crazyflie ground truth): numpy state rows in, rows out, each model's row layout
// given by its StateRows specialisation.
#include <fmt/format.h>

#include <span>
#include <string>
#include <vector>

#include "builtin_problem.hpp"
#include "common.hpp"
#include "heli_policy.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "pegasus/vehicle/state.hpp"

namespace pegasus::python {

inline constexpr py::ssize_t kLogged = heli::kLoggedStates;

// A model's state as a row of numbers: kColumns, write(state, row), read(row, index, argument name) (a
// ValueError naming the argument, row and column for a row that is no state).
template <class M>
struct StateRows;

// A Vec3 field of a parameters struct as a numpy property of 3 finite numbers; get(t) is the field of t (a
// generic lambda: it reads a const T and writes a T).
template <class T, class Get>
void def_vec3(py::class_<T>& c, const char* name, Get get, const char* doc) {
  c.def_property(
      name, [get](const T& t) { return vector_array(std::span<const double>(get(t).data(), 3)); },
      [get, name](T& t, ArrayLikeArg v) {
        const Array a = as_vector(v, name, 3);
        require_finite(a, name);
        get(t) = heli::Vec3(a.data()[0], a.data()[1], a.data()[2]);
      },
      doc);
}

// A std::array<double, N> field as a numpy property of N finite numbers.
template <class T, std::size_t N>
void def_array(py::class_<T>& c, const char* name, std::array<double, N> T::*field, const char* doc) {
  c.def_property(
      name, [field](const T& t) { return vector_array(t.*field); },
      [field, name](T& t, ArrayLikeArg v) {
        const Array a = as_vector(v, name, static_cast<py::ssize_t>(N));
        require_finite(a, name);
        std::copy(a.data(), a.data() + N, (t.*field).begin());
      },
      doc);
}

// The fields every built-in ground truth's params share (ground_truth.hpp: disturbances, crash limits,
// integration, start) and is_valid, bound by their C++ names after the aircraft's own fields
// (`own_fields`, already bound); sets `_fields` to all of them.
template <class P>
void bind_ground_truth_params(py::class_<P>& params, std::vector<const char*> own_fields) {
// The flight conditions (heli::FlightConditions, the params' member `conditions`) by their own names.
#define PEGASUS_CONDITION(field, doc)                                                                        \
  params.def_property(                                                                                       \
      #field, [](const P& p) { return p.conditions.field; }, [](P& p, double v) { p.conditions.field = v; }, \
      doc)
#define PEGASUS_SHARED(field, doc) params.def_readwrite(#field, &P::field, doc)
  PEGASUS_CONDITION(gust_sigma, "Turbulence standard deviation per axis, m/s.");
  PEGASUS_CONDITION(gust_tau, "Turbulence correlation time, s.");
  PEGASUS_CONDITION(est_sigma_pos, "State-estimate error in position (standard deviation), m.");
  PEGASUS_CONDITION(est_sigma_vel, "State-estimate error in velocity, m/s.");
  PEGASUS_CONDITION(est_sigma_angle, "State-estimate error in attitude, rad.");
  PEGASUS_CONDITION(est_sigma_rate, "State-estimate error in the rates, rad/s.");
  PEGASUS_CONDITION(est_tau, "Correlation time of the estimate's error, s.");
  PEGASUS_SHARED(max_tilt_rad, "|roll| or |pitch| beyond this crashes, rad.");
  PEGASUS_SHARED(max_rate_rad_s, "|p|, |q| or |r| beyond this crashes, rad/s.");
  PEGASUS_SHARED(dt, "One control step, s.");
  PEGASUS_SHARED(substeps, "Integration substeps per control step, in [1, 10000].");
  PEGASUS_CONDITION(start_yaw, "Start yaw, rad.");
  PEGASUS_CONDITION(start_pos_sigma, "Start position perturbation per axis, m.");
  PEGASUS_CONDITION(start_vel_sigma, "Start velocity perturbation per axis, m/s.");
#undef PEGASUS_SHARED
#undef PEGASUS_CONDITION
  def_vec3(
      params, "mean_wind_W", [](auto& p) -> auto& { return p.conditions.mean_wind_W; },
      "Mean wind in the world frame, m/s.");
  def_vec3(
      params, "start_p_W", [](auto& p) -> auto& { return p.conditions.start_p_W; },
      "Start position in the world frame (NED), m.");
  params.def("is_valid", is_valid_method<P>(), kIsValidDoc);
  for (const char* name : {"mean_wind_W", "gust_sigma", "gust_tau", "est_sigma_pos", "est_sigma_vel",
                           "est_sigma_angle", "est_sigma_rate", "est_tau", "max_tilt_rad", "max_rate_rad_s",
                           "dt", "substeps", "start_p_W", "start_yaw", "start_pos_sigma", "start_vel_sigma"})
    own_fields.push_back(name);
  set_fields(params, own_fields);
}

// Uniforms in [0, 1] (the models map them through the normal quantile).
inline void require_uniform(const Array& a, const std::string& name) {
  const double* x = a.data();
  for (py::ssize_t k = 0; k < a.size(); ++k)
    if (!(x[k] >= 0.0 && x[k] <= 1.0))
      throw py::value_error(
          fmt::format("{}: expected uniforms in [0, 1], got {} at flat index {}", name, x[k], k));
}

inline heli::Controls controls_row(const double* a) { return {a[0], a[1], a[2], a[3]}; }

// ---- Batch models -----------------------------------------------------------------------------------------

// The batch interface shared by the aircraft models (the helicopter, the quadrotor, the identified model):
// rows in, rows out; the GIL is released while a batch steps, on `threads` threads (each row is independent:
// results never depend on them).
template <class M>
struct HeliBatch {
  static constexpr py::ssize_t columns() { return StateRows<M>::kColumns; }
  static typename M::State row(const double* x, py::ssize_t r, const char* name) {
    return StateRows<M>::read(x, r, name);
  }
  static std::vector<typename M::State> states(const Array& s, const char* name) {
    std::vector<typename M::State> out;
    out.reserve(static_cast<std::size_t>(s.shape(0)));
    for (py::ssize_t r = 0; r < s.shape(0); ++r) out.push_back(row(s.data() + r * columns(), r, name));
    return out;
  }

  static Array initial_state(const M& model, ArrayLikeArg noise, std::int64_t threads) {
    const Array p = as_matrix(noise, "noise", -1, model.initial_noise_dim());
    require_uniform(p, "noise");
    const auto pool = make_pool(threads);
    Array out = matrix(p.shape(0), columns());
    const auto d = static_cast<std::size_t>(model.initial_noise_dim());
    const double* pp = p.data();
    double* o = out.mutable_data();
    {
      ReleaseGilInterruptibly release;
      pool->parallel_for(static_cast<std::size_t>(p.shape(0)), [&](std::size_t r) {
        StateRows<M>::write(model.initial_state(std::span<const double>(pp + r * d, d)), o + r * columns());
      });
    }
    return out;
  }

  static Array step(const M& model, ArrayLikeArg states, ArrayLikeArg actions, ArrayLikeArg noise,
                    std::int64_t threads) {
    const Array s = as_matrix(states, "states", -1, columns());
    const Array a = as_matrix(actions, "actions", s.shape(0), 4);
    const Array p = as_matrix(noise, "noise", s.shape(0), model.noise_dim());
    require_finite(a, "actions");
    require_uniform(p, "noise");
    const std::vector<typename M::State> in = HeliBatch::states(s, "states");
    const auto pool = make_pool(threads);
    Array out = matrix(s.shape(0), columns());
    const auto d = static_cast<std::size_t>(model.noise_dim());
    const double *ap = a.data(), *pp = p.data();
    double* o = out.mutable_data();
    {
      ReleaseGilInterruptibly release;
      pool->parallel_for(in.size(), [&](std::size_t r) {
        StateRows<M>::write(
            model.step(in[r], controls_row(ap + 4 * r), std::span<const double>(pp + r * d, d)),
            o + r * columns());
      });
    }
    return out;
  }

  static Array observe(const M& model, ArrayLikeArg states) {
    const Array s = as_matrix(states, "states", -1, columns());
    Array out = matrix(s.shape(0), kLogged);
    for (py::ssize_t r = 0; r < s.shape(0); ++r) {
      const auto o = model.observe(row(s.data() + r * columns(), r, "states"));
      std::copy(o.begin(), o.end(), out.mutable_data() + r * kLogged);
    }
    return out;
  }

  static py::array_t<bool> terminal(const M& model, ArrayLikeArg states) {
    const Array s = as_matrix(states, "states", -1, columns());
    py::array_t<bool> out(s.shape(0));
    for (py::ssize_t r = 0; r < s.shape(0); ++r)
      out.mutable_data()[r] = model.terminal(row(s.data() + r * columns(), r, "states"));
    return out;
  }

  // Open loop (actions [n, T, 4]) or closed loop under a policy file's controller; see the docstring.
  static py::dict simulate(const M& model, ArrayLikeArg initial_noise, ArrayLikeArg noise,
                           ArrayLikeArg actions, const heli::HeliController* controller,
                           std::int64_t threads) {
    const Array p0 = as_matrix(initial_noise, "initial_noise", -1, model.initial_noise_dim());
    require_uniform(p0, "initial_noise");
    const py::ssize_t n = p0.shape(0);
    Array p = as_array(noise, "noise");
    if (p.ndim() != 3 || p.shape(0) != n || p.shape(2) != model.noise_dim())
      throw py::value_error(
          fmt::format("noise: expected a 3-D array of shape ({}, steps, {})", n, model.noise_dim()));
    require_uniform(p, "noise");
    const py::ssize_t steps = p.shape(1);
    Array a;
    if ((controller == nullptr) == actions.is_none())
      throw py::value_error("actions, controller: expected exactly one of them");
    if (controller == nullptr) {
      a = as_array(actions, "actions");
      if (a.ndim() != 3 || a.shape(0) != n || a.shape(1) != steps || a.shape(2) != 4)
        throw py::value_error(fmt::format("actions: expected a 3-D array of shape ({}, {}, 4)", n, steps));
      require_finite(a, "actions");
    }
    const auto pool = make_pool(threads);
    Array observed({n, steps + 1, kLogged}), applied({n, steps, py::ssize_t{4}});
    Array rewards = matrix(n, steps);
    py::array_t<std::int64_t> crash_step(n);
    const auto d0 = static_cast<std::size_t>(model.initial_noise_dim());
    const auto dp = static_cast<std::size_t>(model.noise_dim());
    const auto T = static_cast<std::size_t>(steps);
    const double *p0p = p0.data(), *pp = p.data(), *app = controller ? nullptr : a.data();
    double *obs = observed.mutable_data(), *act = applied.mutable_data(), *rew = rewards.mutable_data();
    std::int64_t* crashed = crash_step.mutable_data();
    const double dt = 0.02;
    {
      ReleaseGilInterruptibly release;
      pool->parallel_for(static_cast<std::size_t>(n), [&](std::size_t i) {
        typename M::State s = model.initial_state(std::span<const double>(p0p + i * d0, d0));
        crashed[i] = -1;
        auto o = model.observe(s);
        std::copy(o.begin(), o.end(), obs + (i * (T + 1)) * kLogged);
        heli::ControllerMemory memory;  // the flight's
        for (std::size_t t = 0; t < T; ++t) {
          heli::Controls u{};
          if (controller != nullptr)
            u = controller->act(o, static_cast<double>(t) * dt, memory);
          else
            u = controls_row(app + (i * T + t) * 4);
          typename M::State next = model.step(s, u, std::span<const double>(pp + (i * T + t) * dp, dp));
          rew[i * T + t] = model.reward(s, u, next);
          if (crashed[i] < 0 && model.terminal(next)) crashed[i] = static_cast<std::int64_t>(t);
          s = next;
          o = model.observe(s);
          std::copy(u.begin(), u.end(), act + (i * T + t) * 4);
          std::copy(o.begin(), o.end(), obs + (i * (T + 1) + t + 1) * kLogged);
        }
      });
    }
    py::dict out;
    out["observations"] = observed;
    out["actions"] = applied;
    out["rewards"] = rewards;
    out["crash_step"] = crash_step;
    return out;
  }

  template <class Class>
  static void bind(Class& c) {
    c.def_property_readonly("noise_dim", &M::noise_dim, kNoiseDimDoc)
        .def_property_readonly("initial_noise_dim", &M::initial_noise_dim, kInitialNoiseDimDoc)
        .def("initial_state", &HeliBatch::initial_state, py::arg("noise"), py::kw_only(),
             py::arg("threads") = 1, "State rows [n, columns] from uniforms [n, initial_noise_dim].")
        .def("step", &HeliBatch::step, py::arg("states"), py::arg("actions"), py::arg("noise"), py::kw_only(),
             py::arg("threads") = 1,
             "One 50 Hz step of every row: states [n, columns], actions [n, 4] (a1..a4, clipped to [-1, 1]), "
             "noise [n, noise_dim] uniforms; a new array. Deterministic; threads never change the result.")
        .def("observe", &HeliBatch::observe, py::arg("states"),
             "What a controller sees, [n, 12] (x, y, z, roll, pitch, yaw, xdot, ydot, zdot, roll_rate, "
             "pitch_rate, yaw_rate; world frame NED).")
        .def("terminal", &HeliBatch::terminal, py::arg("states"), "Whether each row has crashed (absorbing).")
        .def(
            "simulate",
            [](const M& model, ArrayLikeArg initial_noise, ArrayLikeArg noise, ArrayLikeArg actions,
               HeliPolicyArg policy, std::int64_t threads) {
              const heli::HeliController* controller = nullptr;
              if (!policy.is_none()) {
                if (!py::isinstance<HeliPolicyObject>(policy))
                  throw py::value_error("policy: expected a pegasus.HeliPolicy or None");
                controller = policy.cast<const HeliPolicyObject*>()->controller.get();
              }
              return simulate(model, initial_noise, noise, actions, controller, threads);
            },
            py::arg("initial_noise"), py::arg("noise"), py::kw_only(), py::arg("actions") = py::none(),
            py::arg("policy") = py::none(), py::arg("threads") = 1,
            R"doc(Flies n flights of `steps` 50 Hz steps from initial_noise [n, initial_noise_dim] with noise
[n, steps, noise_dim] (a ScenarioSet's initial_noise() and step_noise() fit), either open loop (actions
[n, steps, 4]) or closed loop under a policy file (policy=HeliPolicy, controller time t * 0.02 s). Returns a
dict: observations [n, steps + 1, 12] (what a controller sees), actions [n, steps, 4] (applied), rewards
[n, steps] (the model's own: the learned model's crash penalty), crash_step [n] (the step whose transition
crashed, -1 for none). The GIL is released; rows run on `threads` threads, the result never depends on them.)doc");
  }
};

}  // namespace pegasus::python
