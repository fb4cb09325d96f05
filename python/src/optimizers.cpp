// Parameter specs, objectives and every optimizer of optimizers/optimizer.hpp: Options and Summary objects
// with the C++ field names, Solve with the GIL released, checkpoints as Python dicts.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "common.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/optimizers/training.hpp"

namespace pegasus::python {

namespace {

// checkpoint_every, on_checkpoint and resume_from of one method's options.
template <class Options>
void bind_checkpointing(py::class_<Options>& c) {
  c.def_readwrite("checkpoint_every", &Options::checkpoint_every,
                  "Iterations between checkpoints (0: none); each is passed to on_checkpoint as a dict.")
      .def_property(
          "on_checkpoint", [](const Options& o) { return static_cast<bool>(o.on_checkpoint); },
          [](Options& o, CheckpointCallbackArg f) { o.on_checkpoint = checkpoint_callback(std::move(f)); },
          "Set: a callable receiving each checkpoint (a dict); get: whether one is set.")
      .def_property(
          "resume_from",
          [](const Options& o) -> py::object {
            return o.resume_from ? to_python(*o.resume_from) : py::none();
          },
          [](Options& o, OptionalCheckpointArg state) {
            if (state.is_none())
              o.resume_from.reset();
            else
              o.resume_from = from_python(state, "resume_from");
          },
          "A checkpoint (dict) to continue from, or None.")
      .def("is_valid", is_valid_method<Options>(), kIsValidDoc);
}

// Binds one VisitFields field per call, with its help as the docstring, and keeps the names for _fields.
template <class Options>
struct FieldBinder {
  py::class_<Options>& c;
  std::vector<std::string>& names;

  template <class T>
  void bind(const char* name, T Options::*member, const char* help) {
    c.def_readwrite(name, member, help);
    names.emplace_back(name);
  }
  template <class Int>
  void integer(const char* name, Int Options::*member, const char* help, double, double = 0) {
    bind(name, member, help);
  }
  void real(const char* name, double Options::*member, const char* help, double, double, bool = false) {
    bind(name, member, help);
  }
  template <class T>
  void internal(const char* name, T Options::*member, const char* help) {
    bind(name, member, help);
  }
};

// A method's Options class: its fields (VisitFields), checkpointing and is_valid.
template <class Options>
void bind_method_options(py::module_& m) {
  const OptimizerMethodInfo& info = Options::kMethod;
  // type_name is a string literal (kMethod is constexpr): null-terminated, and alive as long as the module.
  auto c = py::class_<Options>(m, info.type_name.data(), std::string(info.description).c_str());
  c.def(py::init<>());
  std::vector<std::string> names;
  if constexpr (std::is_same_v<Options, NloptOptions>) {
    c.def_property(
        "algorithm", [](const NloptOptions& o) { return std::string(NloptAlgorithmName(o.algorithm)); },
        [](NloptOptions& o, const std::string& name) {
          const auto a = NloptAlgorithmFromName(name);
          if (!a)
            throw py::value_error("algorithm: expected bobyqa, sbplx, crs2 or esch, got '" + name + "'");
          o.algorithm = *a;
        },
        "bobyqa, sbplx, crs2 or esch; solve() sets it from OptimizerOptions.method.");
    names.emplace_back("algorithm");
  }
  FieldBinder<Options> binder{c, names};
  Options::VisitFields(binder);
  bind_checkpointing(c);
  for (const char* name : {"checkpoint_every", "on_checkpoint", "resume_from"}) names.emplace_back(name);
  set_fields(c, names);
}

py::array_t<double> theta_array(const Theta& theta) { return vector_array(theta); }

}  // namespace

void bind_optimizers(py::module_& m) {
  py::class_<Parameter>(m, "Parameter",
                        "One tunable parameter of a policy class (thesis §4.1). Read-only once made (a spec "
                        "checks its parameters when they are added): make a new one to change it.")
      .def(py::init(
               [](std::string name, double initial, double lower, double upper, double scale, bool integer) {
                 return Parameter{std::move(name), initial, lower, upper, scale, integer};
               }),
           py::arg("name"), py::arg("initial") = 0.0, py::arg("lower") = -INFINITY,
           py::arg("upper") = INFINITY, py::arg("scale") = 1.0, py::arg("integer") = false)
      .def_readonly("name", &Parameter::name, "Unique within its spec.")
      .def_readonly("initial", &Parameter::initial, "Where optimizers start (finite, within the bounds).")
      .def_readonly("lower", &Parameter::lower, "Lower bound (-inf: none).")
      .def_readonly("upper", &Parameter::upper, "Upper bound (inf: none).")
      .def_readonly("scale", &Parameter::scale, "Typical size of a useful change (§5.3).")
      .def_readonly(
          "integer", &Parameter::integer,
          "Whole numbers within the bounds only (a table's action); only exhaustive search takes it.")
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
      .def(
          "add", &ParameterSpec::add, py::arg("parameter"), py::return_value_policy::reference_internal,
          "Appends a parameter (a unique name, lower <= initial <= upper, a finite initial value, scale > 0) "
          "and returns the spec.")
      .def("__len__", &ParameterSpec::size)
      .def(
          "__getitem__",
          [](const ParameterSpec& s, std::int64_t i) {
            if (i < 0) i += static_cast<std::int64_t>(s.size());
            if (i < 0 || i >= static_cast<std::int64_t>(s.size())) throw py::index_error("parameter index");
            return s[static_cast<std::size_t>(i)];
          },
          py::arg("i"), "The parameter at position i (negative: from the end), read-only.")
      .def_property_readonly(
          "names",
          [](const ParameterSpec& s) {
            std::vector<std::string> names;
            for (const auto& p : s.all()) names.push_back(p.name);
            return names;
          },
          "Every parameter's name, in theta's order.")
      .def_property_readonly(
          "initial", [](const ParameterSpec& s) { return theta_array(s.initial()); },
          "Every parameter's initial value, in theta's order: where optimizers start.")
      .def_property_readonly(
          "lower", [](const ParameterSpec& s) { return theta_array(s.lower()); },
          "Every parameter's lower bound, in theta's order (-inf: none).")
      .def_property_readonly(
          "upper", [](const ParameterSpec& s) { return theta_array(s.upper()); },
          "Every parameter's upper bound, in theta's order (inf: none).")
      .def_property_readonly(
          "scales", [](const ParameterSpec& s) { return theta_array(s.scales()); },
          "Every parameter's scale, in theta's order: the typical size of a useful change (§5.3).")
      .def(
          "index_of",
          [](const ParameterSpec& s, const std::string& name) {
            const std::size_t i = s.index_of(name);
            if (i == s.size()) throw py::key_error(fmt::format("no parameter named '{}'", name));
            return i;
          },
          py::arg("name"), "The position of the parameter named `name` (KeyError when there is none).");

  py::class_<Objective>(m, "Objective", R"doc(
A deterministic objective theta -> U-hat(theta) that the optimizers maximise. Built by VectorizedProblem,
BicycleProblem, FunctionObjective, ...)doc")
      .def_property_readonly("parameters", &Objective::parameters, py::return_value_policy::copy,
                             "The ParameterSpec of theta: names, initial values, bounds and scales.")
      .def(
          "uhat",
          [](Objective& o, ArrayLikeArg theta) {
            const Theta t = as_theta(theta, "theta", o.parameters());
            ReleaseGilInterruptibly release;
            return o.evaluate(t);
          },
          py::arg("theta"), "U-hat of one theta (the same bits every call).")
      .def(
          "uhat_batch",
          [](Objective& o, ArrayLikeArg thetas) {
            const std::vector<Theta> ts = as_thetas(thetas, "thetas", o.parameters());
            std::vector<double> values(ts.size());
            {
              ReleaseGilInterruptibly release;
              o.evaluate_batch(ts, values);
            }
            return vector_array(values);
          },
          py::arg("thetas"), "U-hat of each row of thetas [K, n], evaluated together (parallel work).");

  class PythonFunctionObjective final : public Objective {
   public:
    PythonFunctionObjective(ParameterSpec spec, ObjectiveFunctionArg f)
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
      .def(py::init([](ParameterSpec spec, ObjectiveFunctionArg f) {
             if (!PyCallable_Check(f.ptr())) throw py::value_error("f: expected a callable");
             if (spec.size() == 0) throw py::value_error("parameters: expected at least one parameter");
             return std::make_unique<PythonFunctionObjective>(std::move(spec), std::move(f));
           }),
           py::arg("parameters"), py::arg("f"));

  // Every method's Options class, from its kMethod and VisitFields (optimizer_method.hpp).
  ForEachOptimizerMethod(
      [&](auto member) { bind_method_options<OptimizerMethodOptions<decltype(member)>>(m); });

  auto optimizer_options =
      py::class_<OptimizerOptions>(m, "OptimizerOptions", R"doc(
Which optimizer runs (method: one of optimizer_methods(); "cmaes" by default, the method of the optimizer suite's
table in the manual's "Choosing an optimizer") and the options of each method, one attribute per options section;
only the selected method's are used and validated.)doc")
          .def(py::init<>())
          .def(py::init([](const std::string& method) {
                 const auto names = OptimizerMethodNames();
                 if (std::find(names.begin(), names.end(), method) == names.end())
                   throw py::value_error(
                       fmt::format("method: expected one of {}, got '{}'", fmt::join(names, ", "), method));
                 OptimizerOptions o;
                 o.method = method;
                 return o;
               }),
               py::arg("method"))
          .def_readwrite("method", &OptimizerOptions::method,
                         "The optimizer that runs: one of optimizer_methods().");
  std::vector<std::string> optimizer_fields = {"method"};
  ForEachOptimizerMethod([&](auto member) {
    const OptimizerMethodInfo& info = OptimizerMethodOptions<decltype(member)>::kMethod;
    std::vector<std::string_view> names;
    for (std::string_view name : info.method_names)
      if (!name.empty()) names.push_back(name);
    optimizer_options.def_readwrite(std::string(info.section).c_str(), member,
                                    fmt::format("Options of {}.", fmt::join(names, ", ")).c_str());
    optimizer_fields.emplace_back(info.section);
  });
  optimizer_options
      .def("iteration_limit", &OptimizerOptions::IterationLimit,
           "The selected method's iteration limit (what a progress bar counts to).")
      .def(
          "set_checkpointing",
          [](OptimizerOptions& o, std::int64_t every, CheckpointCallbackArg on_checkpoint,
             OptionalCheckpointArg resume_from) {
            std::optional<nlohmann::json> resume;
            if (!resume_from.is_none()) resume = from_python(resume_from, "resume_from");
            o.SetCheckpointing(every, checkpoint_callback(std::move(on_checkpoint)), std::move(resume));
          },
          py::arg("checkpoint_every"), py::arg("on_checkpoint") = py::none(),
          py::arg("resume_from") = py::none(),
          "Checkpointing of every method at once: each checkpoint (a dict) goes to on_checkpoint; "
          "resume_from "
          "continues one.")
      .def("is_valid", is_valid_method<OptimizerOptions>(), kIsValidDoc);
  set_fields(optimizer_options, optimizer_fields);
  m.def(
      "optimizer_methods",
      [] {
        std::vector<std::string> names;
        for (auto n : OptimizerMethodNames()) names.emplace_back(n);
        return names;
      },
      "The names OptimizerOptions.method takes (exhaustive needs a finite class; crs2 and esch finite "
      "bounds).");

  auto record = py::class_<IterationRecord>(m, "IterationRecord", "One row of an optimizer's history.");
  record.def_readonly("iteration", &IterationRecord::iteration, "1-based count of completed iterations.")
      .def_readonly("evaluations", &IterationRecord::evaluations,
                    "Objective evaluations so far, this iteration's included.")
      .def_readonly("value", &IterationRecord::value, "Best U-hat found so far.")
      .def_readonly("seconds", &IterationRecord::seconds,
                    "Wall time since the run began (time before a resume included).");
  set_fields(record, {"iteration", "evaluations", "value", "seconds"});

  auto summary = py::class_<OptimizerSummary>(m, "OptimizerSummary",
                                              "What an optimizer run reports (Ceres' Summary shape).");
  summary.def(py::init<>())
      .def_readonly("method", &OptimizerSummary::method, "The method as OptimizerOptions.method spells it.")
      .def_readonly("parameter_names", &OptimizerSummary::parameter_names,
                    "The policy class's parameter names, in theta's order.")
      .def_property_readonly(
          "termination_type",
          [](const OptimizerSummary& s) { return std::string(TerminationTypeName(s.termination_type)); },
          "CONVERGENCE, MAX_ITERATIONS, MAX_EVALUATIONS, SEARCH_COMPLETE, FAILURE or USER_REQUESTED.")
      .def_readonly("message", &OptimizerSummary::message,
                    "Why the run stopped, with the numbers that triggered it.")
      .def_readonly("iterations", &OptimizerSummary::iterations,
                    "Completed iterations (a gradient step, a batch of proposals, a block of policies, an "
                    "NLopt evaluation or a CMA-ES generation).")
      .def_readonly("evaluations", &OptimizerSummary::evaluations,
                    "Objective evaluations from the start of the run, those before a resume included.")
      .def_readonly("replayed_evaluations", &OptimizerSummary::replayed_evaluations,
                    "NLopt resume only: evaluations answered from the checkpoint's log.")
      .def_readonly("resumed", &OptimizerSummary::resumed, "Whether the run continued from a checkpoint.")
      .def_readonly("initial_value", &OptimizerSummary::initial_value,
                    "U-hat at the (clamped) starting theta; NaN where the method never evaluates it.")
      .def_readonly("best_value", &OptimizerSummary::best_value, "The best U-hat found.")
      .def_property_readonly(
          "best_theta", [](const OptimizerSummary& s) { return theta_array(s.best_theta); },
          "The best theta found, in parameter_names' order.")
      .def_readonly("final_step", &OptimizerSummary::final_step,
                    "Gradient ascent and hill climbing: the step length at the stop (scaled units); CMA-ES: "
                    "sigma; else NaN.")
      .def_readonly("wall_seconds", &OptimizerSummary::wall_seconds,
                    "Wall time of the whole run, time before a resume included.")
      .def_readonly("history", &OptimizerSummary::history, "One IterationRecord per iteration.")
      .def_property_readonly(
          "all_values", [](const OptimizerSummary& s) { return vector_array(s.all_values); },
          "Exhaustive search with keep_all_values: every policy's U-hat, in enumeration order.")
      .def("brief_report", &OptimizerSummary::BriefReport,
           "One line: method, termination, iterations, evaluations, best value, time.")
      .def("full_report", &OptimizerSummary::FullReport,
           "Several lines: the brief report plus the message and the best theta by parameter name.")
      .def(
          "same_outcome",
          [](const OptimizerSummary& a, const OptimizerSummary& b) {
            std::string difference;
            const bool same = SameOutcome(a, b, &difference);
            return py::make_tuple(same, difference);
          },
          py::arg("other"),
          "(same, difference): whether two runs ended identically (every number bit for bit; wall time, "
          "resumed "
          "and replayed evaluations ignored, so a resumed run compares with an uninterrupted one), and the "
          "first difference when not.")
      .def("__repr__", &OptimizerSummary::BriefReport);
  set_fields(summary, {"method", "parameter_names", "termination_type", "message", "iterations",
                       "evaluations", "replayed_evaluations", "resumed", "initial_value", "best_value",
                       "best_theta", "final_step", "wall_seconds", "history", "all_values"});

  m.def(
      "solve",
      [](Objective& objective, const OptimizerOptions& options, ArrayLikeArg theta,
         IterationCallbacksArg callbacks) {
        Theta t;
        if (!theta.is_none()) t = as_theta(theta, "theta", objective.parameters());
        std::string error;
        if (!options.IsValid(&error)) throw py::value_error("options." + error);
        const IterationCallbackList list(callbacks);
        OptimizerOptions o = options;
        o.SetCallbacks(list.pointers());
        OptimizerSummary result;
        {
          ReleaseGilInterruptibly release;
          Solve(o, objective, &t, &result);
        }
        return py::make_tuple(theta_array(t), result);
      },
      py::arg("objective"), py::arg_v("options", OptimizerOptions{}, "OptimizerOptions()"),
      py::arg("theta") = py::none(), py::kw_only(), py::arg("callbacks") = py::none(),
      R"doc(Maximises the objective with options.method, starting from theta (default: the spec's initial
values). Returns (theta, OptimizerSummary). The GIL is released while the C++ optimizer works.
callbacks: callables f(IterationReport) told after every iteration (the C++ Options' `callbacks`); one that
returns True or CallbackReturnType.TERMINATE stops the run (termination USER_REQUESTED). A run whose callbacks
always continue is bit-identical to one without.)doc");
}

}  // namespace pegasus::python
