// Parameter specs, objectives and every optimizer of optimizers/optimizer.hpp: Options and Summary objects
// with the C++ field names, Solve with the GIL released, checkpoints as Python dicts.
#include <fmt/format.h>

#include <memory>

#include "common.hpp"
#include "pegasus/optimizers/optimizer.hpp"

namespace pegasus::python {

namespace {

// A Python object kept alive by C++ copies that may be made and dropped without the GIL: the reference is
// released under the GIL.
std::shared_ptr<py::object> hold(py::object object) {
  return std::shared_ptr<py::object>(new py::object(std::move(object)), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
}

CheckpointCallback checkpoint_callback(py::object callback) {
  if (callback.is_none()) return {};
  if (!PyCallable_Check(callback.ptr())) throw py::value_error("on_checkpoint: expected a callable or None");
  auto held = hold(std::move(callback));
  return [held](const nlohmann::json& state) {
    py::gil_scoped_acquire gil;
    (*held)(to_python(state));
  };
}

// checkpoint_every, on_checkpoint and resume_from of one method's options.
template <class Options>
void bind_checkpointing(py::class_<Options>& c) {
  c.def_readwrite("checkpoint_every", &Options::checkpoint_every,
                  "Iterations between checkpoints (0: none); each is passed to on_checkpoint as a dict.")
      .def_property(
          "on_checkpoint", [](const Options& o) { return static_cast<bool>(o.on_checkpoint); },
          [](Options& o, py::object f) { o.on_checkpoint = checkpoint_callback(std::move(f)); },
          "Set: a callable receiving each checkpoint (a dict); get: whether one is set.")
      .def_property(
          "resume_from",
          [](const Options& o) -> py::object {
            return o.resume_from ? to_python(*o.resume_from) : py::none();
          },
          [](Options& o, py::object state) {
            if (state.is_none())
              o.resume_from.reset();
            else
              o.resume_from = from_python(state, "resume_from");
          },
          "A checkpoint (dict) to continue from, or None.")
      .def("is_valid", [](const Options& o) {
        std::string error;
        const bool ok = o.IsValid(&error);
        return py::make_tuple(ok, error);
      });
}

py::array_t<double> theta_array(const Theta& theta) { return vector_array(theta); }

}  // namespace

void bind_optimizers(py::module_& m) {
  py::class_<Parameter>(m, "Parameter", "One tunable parameter of a policy class (thesis §4.1).")
      .def(py::init(
               [](std::string name, double initial, double lower, double upper, double scale, bool integer) {
                 return Parameter{std::move(name), initial, lower, upper, scale, integer};
               }),
           py::arg("name"), py::arg("initial") = 0.0, py::arg("lower") = -INFINITY,
           py::arg("upper") = INFINITY, py::arg("scale") = 1.0, py::arg("integer") = false)
      .def_readwrite("name", &Parameter::name)
      .def_readwrite("initial", &Parameter::initial)
      .def_readwrite("lower", &Parameter::lower)
      .def_readwrite("upper", &Parameter::upper)
      .def_readwrite("scale", &Parameter::scale, "Typical size of a useful change (§5.3).")
      .def_readwrite("integer", &Parameter::integer)
      .def("__repr__", [](const Parameter& p) {
        return fmt::format("Parameter('{}', initial={}, lower={}, upper={}, scale={}, integer={})", p.name,
                           p.initial, p.lower, p.upper, p.scale, p.integer ? "True" : "False");
      });

  py::class_<ParameterSpec>(m, "ParameterSpec", R"doc(
The parameters of a policy class: names, initial values, bounds, scales. ParameterSpec([Parameter, ...]) or
ParameterSpec.from_names(names, initial=0, scale=1).)doc")
      .def(py::init<>())
      .def(py::init([](std::vector<Parameter> parameters) { return ParameterSpec(std::move(parameters)); }),
           py::arg("parameters"))
      .def_static(
          "from_names",
          [](const std::vector<std::string>& names, double initial, double scale) {
            ParameterSpec spec;
            for (const auto& name : names) spec.add({.name = name, .initial = initial, .scale = scale});
            return spec;
          },
          py::arg("names"), py::arg("initial") = 0.0, py::arg("scale") = 1.0)
      .def("add", &ParameterSpec::add, py::arg("parameter"), py::return_value_policy::reference_internal)
      .def("__len__", &ParameterSpec::size)
      .def("__getitem__",
           [](const ParameterSpec& s, std::int64_t i) {
             if (i < 0) i += static_cast<std::int64_t>(s.size());
             if (i < 0 || i >= static_cast<std::int64_t>(s.size())) throw py::index_error("parameter index");
             return s[static_cast<std::size_t>(i)];
           })
      .def_property_readonly("names",
                             [](const ParameterSpec& s) {
                               std::vector<std::string> names;
                               for (const auto& p : s.all()) names.push_back(p.name);
                               return names;
                             })
      .def_property_readonly("initial", [](const ParameterSpec& s) { return theta_array(s.initial()); })
      .def_property_readonly("lower", [](const ParameterSpec& s) { return theta_array(s.lower()); })
      .def_property_readonly("upper", [](const ParameterSpec& s) { return theta_array(s.upper()); })
      .def_property_readonly("scales", [](const ParameterSpec& s) { return theta_array(s.scales()); })
      .def("index_of", &ParameterSpec::index_of);

  py::class_<Objective>(m, "Objective", R"doc(
A deterministic objective theta -> U-hat(theta) that the optimizers maximise. Built by VectorizedProblem,
BicycleProblem, FunctionObjective, ...)doc")
      .def_property_readonly("parameters", &Objective::parameters,
                             py::return_value_policy::reference_internal)
      .def(
          "uhat",
          [](Objective& o, py::object theta) {
            const Theta t = as_theta(theta, "theta", o.parameters());
            py::gil_scoped_release release;
            return o.evaluate(t);
          },
          py::arg("theta"), "U-hat of one theta (the same bits every call).")
      .def(
          "uhat_batch",
          [](Objective& o, py::object thetas) {
            const std::vector<Theta> ts = as_thetas(thetas, "thetas", o.parameters());
            std::vector<double> values(ts.size());
            {
              py::gil_scoped_release release;
              o.evaluate_batch(ts, values);
            }
            return vector_array(values);
          },
          py::arg("thetas"), "U-hat of each row of thetas [K, n], evaluated together (parallel work).");

  class PythonFunctionObjective final : public Objective {
   public:
    PythonFunctionObjective(ParameterSpec spec, py::object f)
        : spec_(std::move(spec)), f_(hold(std::move(f))) {}
    const ParameterSpec& parameters() const override { return spec_; }
    double evaluate(std::span<const double> theta) override {
      py::gil_scoped_acquire gil;
      const py::object value = (*f_)(vector_array(theta));
      double v;
      try {
        v = value.cast<double>();
      } catch (const py::cast_error&) {
        throw py::value_error("objective: expected the function to return a float");
      }
      return v;
    }

   private:
    ParameterSpec spec_;
    std::shared_ptr<py::object> f_;
  };
  py::class_<PythonFunctionObjective, Objective>(m, "FunctionObjective",
                                                 "An Objective from a Python function f(theta) -> float.")
      .def(py::init([](ParameterSpec spec, py::object f) {
             if (!PyCallable_Check(f.ptr())) throw py::value_error("f: expected a callable");
             if (spec.size() == 0) throw py::value_error("parameters: expected at least one parameter");
             return std::make_unique<PythonFunctionObjective>(std::move(spec), std::move(f));
           }),
           py::arg("parameters"), py::arg("f"));

  auto gradient = py::class_<GradientAscentOptions>(
      m, "GradientAscentOptions", "Bounded-step gradient ascent (thesis §4.6 footnote 14).");
  gradient.def(py::init<>())
      .def_readwrite("max_iterations", &GradientAscentOptions::max_iterations)
      .def_readwrite("max_evaluations", &GradientAscentOptions::max_evaluations)
      .def_readwrite("relative_step", &GradientAscentOptions::relative_step)
      .def_readwrite("initial_step", &GradientAscentOptions::initial_step)
      .def_readwrite("max_step", &GradientAscentOptions::max_step)
      .def_readwrite("min_step", &GradientAscentOptions::min_step)
      .def_readwrite("step_growth", &GradientAscentOptions::step_growth)
      .def_readwrite("max_backtracks", &GradientAscentOptions::max_backtracks)
      .def_readwrite("function_tolerance", &GradientAscentOptions::function_tolerance);
  bind_checkpointing(gradient);

  auto hill = py::class_<HillClimbingOptions>(m, "HillClimbingOptions", "Random-walk hill climbing.");
  hill.def(py::init<>())
      .def_readwrite("seed", &HillClimbingOptions::seed)
      .def_readwrite("stream", &HillClimbingOptions::stream)
      .def_readwrite("max_iterations", &HillClimbingOptions::max_iterations)
      .def_readwrite("max_evaluations", &HillClimbingOptions::max_evaluations)
      .def_readwrite("proposals_per_iteration", &HillClimbingOptions::proposals_per_iteration)
      .def_readwrite("initial_step", &HillClimbingOptions::initial_step)
      .def_readwrite("max_step", &HillClimbingOptions::max_step)
      .def_readwrite("min_step", &HillClimbingOptions::min_step)
      .def_readwrite("step_growth", &HillClimbingOptions::step_growth)
      .def_readwrite("step_shrink", &HillClimbingOptions::step_shrink);
  bind_checkpointing(hill);

  auto exhaustive = py::class_<ExhaustiveSearchOptions>(m, "ExhaustiveSearchOptions",
                                                        "Enumerates every policy of integer parameters.");
  exhaustive.def(py::init<>())
      .def_readwrite("max_policies", &ExhaustiveSearchOptions::max_policies)
      .def_readwrite("block_size", &ExhaustiveSearchOptions::block_size)
      .def_readwrite("keep_all_values", &ExhaustiveSearchOptions::keep_all_values);
  bind_checkpointing(exhaustive);

  auto nlopt = py::class_<NloptOptions>(m, "NloptOptions", "NLopt: bobyqa, sbplx, crs2, esch.");
  nlopt.def(py::init<>())
      .def_property(
          "algorithm", [](const NloptOptions& o) { return std::string(NloptAlgorithmName(o.algorithm)); },
          [](NloptOptions& o, const std::string& name) {
            const auto a = NloptAlgorithmFromName(name);
            if (!a)
              throw py::value_error("algorithm: expected bobyqa, sbplx, crs2 or esch, got '" + name + "'");
            o.algorithm = *a;
          })
      .def_readwrite("max_evaluations", &NloptOptions::max_evaluations)
      .def_readwrite("initial_step", &NloptOptions::initial_step)
      .def_readwrite("x_tolerance", &NloptOptions::x_tolerance)
      .def_readwrite("function_tolerance", &NloptOptions::function_tolerance)
      .def_readwrite("population", &NloptOptions::population)
      .def_readwrite("seed", &NloptOptions::seed);
  bind_checkpointing(nlopt);

  py::class_<OptimizerOptions>(m, "OptimizerOptions", R"doc(
Which optimizer runs (method: "exhaustive", "gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch") and the
options of each; only the selected method's are used and validated.)doc")
      .def(py::init<>())
      .def(py::init([](const std::string& method) {
             OptimizerOptions o;
             o.method = method;
             return o;
           }),
           py::arg("method"))
      .def_readwrite("method", &OptimizerOptions::method)
      .def_readwrite("exhaustive", &OptimizerOptions::exhaustive)
      .def_readwrite("gradient", &OptimizerOptions::gradient)
      .def_readwrite("hill_climbing", &OptimizerOptions::hill_climbing)
      .def_readwrite("nlopt", &OptimizerOptions::nlopt)
      .def(
          "set_checkpointing",
          [](OptimizerOptions& o, std::int64_t every, py::object on_checkpoint, py::object resume_from) {
            std::optional<nlohmann::json> resume;
            if (!resume_from.is_none()) resume = from_python(resume_from, "resume_from");
            o.SetCheckpointing(every, checkpoint_callback(std::move(on_checkpoint)), std::move(resume));
          },
          py::arg("checkpoint_every"), py::arg("on_checkpoint") = py::none(),
          py::arg("resume_from") = py::none(),
          "Checkpointing of every method at once: each checkpoint (a dict) goes to on_checkpoint; "
          "resume_from "
          "continues one.")
      .def("is_valid", [](const OptimizerOptions& o) {
        std::string error;
        const bool ok = o.IsValid(&error);
        return py::make_tuple(ok, error);
      });
  m.def("optimizer_methods", [] {
    std::vector<std::string> names;
    for (auto n : OptimizerMethodNames()) names.emplace_back(n);
    return names;
  });

  py::class_<IterationRecord>(m, "IterationRecord")
      .def_readonly("iteration", &IterationRecord::iteration)
      .def_readonly("evaluations", &IterationRecord::evaluations)
      .def_readonly("value", &IterationRecord::value)
      .def_readonly("seconds", &IterationRecord::seconds);

  py::class_<OptimizerSummary>(m, "OptimizerSummary", "What an optimizer run reports (Ceres' Summary shape).")
      .def(py::init<>())
      .def_readonly("method", &OptimizerSummary::method)
      .def_readonly("parameter_names", &OptimizerSummary::parameter_names)
      .def_property_readonly(
          "termination_type",
          [](const OptimizerSummary& s) { return std::string(TerminationTypeName(s.termination_type)); })
      .def_readonly("message", &OptimizerSummary::message)
      .def_readonly("iterations", &OptimizerSummary::iterations)
      .def_readonly("evaluations", &OptimizerSummary::evaluations)
      .def_readonly("replayed_evaluations", &OptimizerSummary::replayed_evaluations)
      .def_readonly("resumed", &OptimizerSummary::resumed)
      .def_readonly("initial_value", &OptimizerSummary::initial_value)
      .def_readonly("best_value", &OptimizerSummary::best_value)
      .def_property_readonly("best_theta",
                             [](const OptimizerSummary& s) { return theta_array(s.best_theta); })
      .def_readonly("final_step", &OptimizerSummary::final_step)
      .def_readonly("wall_seconds", &OptimizerSummary::wall_seconds)
      .def_readonly("history", &OptimizerSummary::history)
      .def_property_readonly("all_values",
                             [](const OptimizerSummary& s) { return vector_array(s.all_values); })
      .def("brief_report", &OptimizerSummary::BriefReport)
      .def("full_report", &OptimizerSummary::FullReport)
      .def("same_outcome",
           [](const OptimizerSummary& a, const OptimizerSummary& b) {
             std::string difference;
             const bool same = SameOutcome(a, b, &difference);
             return py::make_tuple(same, difference);
           })
      .def("__repr__", &OptimizerSummary::BriefReport);

  m.def(
      "solve",
      [](Objective& objective, const OptimizerOptions& options, py::object theta) {
        Theta t;
        if (!theta.is_none()) t = as_theta(theta, "theta", objective.parameters());
        std::string error;
        if (!options.IsValid(&error)) throw py::value_error("options." + error);
        OptimizerSummary summary;
        {
          py::gil_scoped_release release;
          Solve(options, objective, &t, &summary);
        }
        return py::make_tuple(theta_array(t), summary);
      },
      py::arg("objective"), py::arg("options") = OptimizerOptions{}, py::arg("theta") = py::none(),
      R"doc(Maximises the objective with options.method, starting from theta (default: the spec's initial
values). Returns (theta, OptimizerSummary). The GIL is released while the C++ optimizer works.)doc");
}

}  // namespace pegasus::python
