#include "heli_policy.hpp"

#include <fmt/format.h>

#include <cmath>

#include "builtin_problem.hpp"
#include "heli_batch.hpp"
#include "pegasus/heli/hover_policy.hpp"

namespace pegasus::python {

HeliPolicyObject::HeliPolicyObject(heli::PolicyFile f, std::string from)
    : file(std::move(f)), source(std::move(from)) {
  controller = heli::make_controller(file, source);
}

Array HeliPolicyObject::controls(ArrayLikeArg states, TimeArg time, std::int64_t threads,
                                 bool one_flight) const {
  const Array s = as_matrix(states, "states", -1, kLogged);
  require_finite(s, "states");
  const py::ssize_t n = s.shape(0);
  Array t = as_array(time, "time");
  if (!(t.ndim() == 0 || (t.ndim() == 1 && t.shape(0) == n)))
    throw py::value_error(fmt::format("time: expected a number or a 1-D array of length {}", n));
  require_finite(t, "time");
  const bool one = t.ndim() == 0;
  const auto pool = make_pool(threads);
  Array out = matrix(n, 4);
  const double *sp = s.data(), *tp = t.data();
  double* o = out.mutable_data();
  const auto row = [&](std::size_t r, heli::ControllerMemory& memory) {
    heli::LoggedState x;
    std::copy(sp + r * kLogged, sp + (r + 1) * kLogged, x.begin());
    const heli::Controls u = controller->act(x, one ? tp[0] : tp[r], memory);
    std::copy(u.begin(), u.end(), o + r * 4);
  };
  {
    ReleaseGilInterruptibly release;
    if (one_flight) {  // one control period after another: the controller's memory runs through the rows
      heli::ControllerMemory memory;
      for (std::size_t r = 0; r < static_cast<std::size_t>(n); ++r) row(r, memory);
    } else {
      pool->parallel_for(static_cast<std::size_t>(n), [&](std::size_t r) {
        heli::ControllerMemory fresh;
        row(r, fresh);
      });
    }
  }
  return out;
}

void bind_heli_policy_files(py::module_& m) {
  py::class_<HeliPolicyObject>(m, "HeliPolicy", R"doc(
A helicopter policy file (heli/policy_file.hpp: "hover", "maneuver" or another registered class) with its
controller bound: controls(states, time) gives the controls of a batch of logged states, as `pegasus heli
control` and `pegasus heli fly` compute them, bit for bit. HeliPolicy.load(path), HeliPolicy.from_json(dict) or
HeliPolicy.hover(theta, target, trim).)doc")
      .def_static(
          "load",
          [](const std::string& path) { return HeliPolicyObject(heli::read_policy_file(path), path); },
          py::arg("path"), "Reads and checks a policy file; ValueError 'FILE: FIELD: expected ...'.")
      .def_static(
          "from_json",
          [](JsonObject j, const std::string& source) {
            return HeliPolicyObject(heli::parse_policy_file(from_python(j, "policy"), source), source);
          },
          py::arg("policy"), py::arg("source") = "policy", "A policy from the file's JSON object (a dict).")
      .def_static(
          "hover",
          [](ArrayLikeArg theta, const heli::SetPoint& target, ArrayLikeArg trim,
             const heli::HoverPolicyInit& init, double integral_dt) {
            const heli::HoverPolicy policy(init);
            const Theta w = as_theta(theta, "theta", policy.parameters());
            const Array t = as_vector(trim, "trim", 4);
            require_finite(t, "trim");
            for (py::ssize_t c = 0; c < 4; ++c)
              if (std::abs(t.data()[c]) > 1.0)
                throw py::value_error(
                    fmt::format("trim: expected controls in [-1, 1], got {} at {}", t.data()[c], c));
            if (policy.has_integral() && !(integral_dt > 0))
              throw py::value_error(
                  "integral_dt: expected the control period > 0, s (init has the integral term)");
            return HeliPolicyObject(
                heli::hover_policy_file(policy, w, target,
                                        {t.data()[0], t.data()[1], t.data()[2], t.data()[3]},
                                        {.dt = policy.has_integral() ? integral_dt : 0.0}),
                "hover");
          },
          py::arg("theta"), py::arg_v("target", heli::SetPoint{}, "SetPoint()"),
          py::arg("trim") = std::vector<double>{0, 0, 0, 0},
          py::arg_v("init", heli::HoverPolicyInit{}, "HoverPolicyInit()"), py::arg("integral_dt") = 0.02,
          "A hover policy file from trained weights (with init.integral_seconds > 0: 38 weights, the "
          "integral "
          "term's integrator stepping integral_dt s per call, the default limits).")
      .def_property_readonly(
          "class_name", [](const HeliPolicyObject& p) { return p.file.class_name; },
          "The file's policy class: \"hover\", \"maneuver\" or another registered one.")
      .def_property_readonly(
          "names", [](const HeliPolicyObject& p) { return p.file.names; },
          "The parameter names, in the class's order.")
      .def_property_readonly(
          "values", [](const HeliPolicyObject& p) { return vector_array(p.file.values); },
          "The parameter values, in the order of names.")
      .def_property_readonly(
          "target", [](const HeliPolicyObject& p) { return p.file.target; },
          "The file's SetPoint (world NED, m and rad): the hover's set point, or where another class's "
          "path is anchored.")
      .def_property_readonly(
          "trim", [](const HeliPolicyObject& p) { return vector_array(p.file.trim); },
          "The hover trim estimate of the pilot's logs, a1..a4 in [-1, 1]: the class's starting point and "
          "the safe output of `heli control`.")
      .def_property_readonly(
          "options", [](const HeliPolicyObject& p) { return JsonObject(to_python(p.file.options)); },
          "Class-specific settings, a dict (hover: \"integral\", the integral term's integrator; maneuver: "
          "which trajectory).")
      .def_property_readonly(
          "provenance", [](const HeliPolicyObject& p) { return JsonObject(to_python(p.file.provenance)); },
          "How the policy was made (command, U-hat, ...), a dict; flying ignores it.")
      .def(
          "to_json",
          [](const HeliPolicyObject& p) { return JsonObject(to_python(heli::policy_file_json(p.file))); },
          "The policy file's contents as a dict (what save writes).")
      .def(
          "save",
          [](const HeliPolicyObject& p, const std::string& path) { heli::write_policy_file(path, p.file); },
          py::arg("path"), "Writes the policy file atomically (doubles reading back to the same bits).")
      .def("controls", &HeliPolicyObject::controls, py::arg("states"), py::arg("time") = 0.0, py::kw_only(),
           py::arg("threads") = 1, py::arg("one_flight") = false, R"doc(
The controls [n, 4] (a1..a4 in [-1, 1]) for logged states [n, 12] (x, y, z, roll, pitch, yaw, xdot, ydot, zdot,
roll_rate, pitch_rate, yaw_rate; world NED, m, rad) at `time` seconds after the flight or manoeuvre began (one
number, or one per row). Each row is a flight's first call, unless one_flight: then the rows are one flight's
control periods in order, and a controller with memory (a hover policy with the integral term, options
"integral") carries it from row to row as `pegasus heli fly` and `heli control` do. The GIL is released; rows
run on `threads` threads (one_flight: one), the result never depends on them.)doc")
      .def(
          "target_at", [](const HeliPolicyObject& p, double time) { return p.controller->target(time); },
          py::arg("time"), "The set point the controller steers to at `time`.")
      .def("__repr__", [](const HeliPolicyObject& p) {
        return fmt::format("HeliPolicy(class_name='{}', parameters={}, source='{}')", p.file.class_name,
                           p.file.values.size(), p.source);
      });
  m.def("heli_policy_classes", &heli::policy_class_names, "The registered policy-file class names.");
}

}  // namespace pegasus::python
