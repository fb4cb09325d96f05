// The training layer of optimizers/training.hpp: a plan of optimizer stages with one seed, one checkpoint
// schema and iteration callbacks. The plan itself is a Python dataclass (python/pegasus/training.py, the
// C++ field names); this file binds what it is made of and runs it with the GIL released.
#include "pegasus/optimizers/training.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "common.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus::python {

namespace {

// One stage of a plan as the Python dataclass gives it: (name, optimizer, seeds, objective or None).
TrainingStage stage_from_python(py::handle stage, std::size_t k, std::vector<py::object>* keep) {
  const std::string where = fmt::format("plan.stages[{}]", k);
  for (const char* field : {"name", "optimizer", "seeds", "objective"})
    if (!py::hasattr(stage, field))
      throw py::value_error(fmt::format("{}: expected a TrainingStage (no field {})", where, field));
  TrainingStage s;
  try {
    s.name = stage.attr("name").cast<std::string>();
  } catch (const py::cast_error&) {
    throw py::value_error(where + ".name: expected a string");
  }
  try {
    s.optimizer = stage.attr("optimizer").cast<OptimizerOptions>();
  } catch (const py::cast_error&) {
    throw py::value_error(where + ".optimizer: expected a pegasus.OptimizerOptions");
  }
  try {
    s.seeds = stage.attr("seeds").cast<SeedDomains>();
  } catch (const py::cast_error&) {
    throw py::value_error(where + ".seeds: expected a pegasus.SeedDomains");
  }
  py::object objective = stage.attr("objective");
  if (!objective.is_none()) {
    try {
      s.objective = objective.cast<Objective*>();
    } catch (const py::cast_error&) {
      throw py::value_error(where + ".objective: expected a pegasus.Objective or None");
    }
    keep->push_back(std::move(objective));
  }
  return s;
}

}  // namespace

void bind_training(py::module_& m) {
  py::enum_<CallbackReturnType>(m, "CallbackReturnType",
                                "What an iteration callback answers: CONTINUE, or TERMINATE (stop after this "
                                "iteration; USER_REQUESTED, the best so far is the result).")
      .value("CONTINUE", CallbackReturnType::kContinue)
      .value("TERMINATE", CallbackReturnType::kTerminate);

  auto report = py::class_<IterationReportCopy>(m, "IterationReport", R"doc(
What an iteration callback is told after every iteration of every optimizer (run_progress.hpp): the method, the
iteration's record (iteration, evaluations so far, best U-hat so far, seconds) and the best theta so far.)doc");
  report
      .def_readonly("method", &IterationReportCopy::method,
                    "The method as OptimizerOptions.method spells it (\"gradient\", \"hill-climb\", ...).")
      .def_readonly("record", &IterationReportCopy::record,
                    "This iteration's IterationRecord: iteration, evaluations so far, best U-hat so far, "
                    "seconds.")
      .def_property_readonly(
          "best_theta", [](const IterationReportCopy& r) { return vector_array(r.best_theta); },
          "The best theta so far (a copy), in the parameters' order.");
  set_fields(report, {"method", "record", "best_theta"});

  auto seeds = py::class_<SeedDomains>(m, "SeedDomains", R"doc(
The seed domains of a stage's optimizers (optimizers/training.hpp): each random method's seed is
mix_seed(plan seed, its domain), apart from the scenarios' streams and from other stages. The defaults are the
first stage's; REFINE_SEED_DOMAINS those of a refinement stage.)doc");
  // A domain is a 32-bit number; a Python int beyond it is refused by name, not wrapped.
  auto domain_of = [](py::handle value, const std::string& name) {
    return static_cast<std::uint32_t>(as_unsigned(value, name, 32));
  };
  seeds.def(py::init([domain_of](const py::kwargs& domains) {
              SeedDomains d;  // each domain left out keeps the first stage's; set() refuses a foreign one
              for (const auto& [key, value] : domains) {
                const auto section = key.cast<std::string>();
                d.set(section, domain_of(value, section));
              }
              return d;
            }),
            "SeedDomains(**domains): each keyword an options section of a random method (as in _fields) and "
            "its domain; each left out keeps the first stage's.");
  std::vector<std::string> sections;
  const SeedDomains first = SeedDomains(), refine = SeedDomains::Refine();
  for (const auto& [section, domain] : first.all()) {
    const std::string name(section);
    sections.push_back(name);
    seeds.def_property(
        name.c_str(), [name](const SeedDomains& d) { return d.of(name); },
        [name, domain_of](SeedDomains& d, py::handle value) { d.set(name, domain_of(value, name)); },
        fmt::format("The domain of OptimizerOptions.{}'s seed: mix_seed(run seed, this) (first stage: {:#x}, "
                    "refinement: {:#x}).",
                    name, domain, refine.of(name))
            .c_str());
  }
  set_fields(seeds, sections);
  m.attr("REFINE_SEED_DOMAINS") = SeedDomains::Refine();
  m.def(
      "derive_optimizer_seeds",
      [](SeedArg run_seed, const SeedDomains& domains, OptimizerOptions& options) {
        DeriveOptimizerSeeds(as_seed(run_seed, "run_seed"), domains, &options);
      },
      py::arg("run_seed"), py::arg("domains"), py::arg("options"),
      "Sets every random method's seed in options (in place) from the run's seed and the stage's domains, as "
      "train does for each stage.");

  auto summary = py::class_<TrainingSummary>(m, "TrainingSummary", R"doc(
What a training plan reports: one OptimizerSummary per stage that ran (stage_names beside them), the merged
history (iterations, evaluations and seconds counting on across stages; the value the best so far), the first
stage's initial U-hat, the last stage's best U-hat and theta, and whether a callback stopped the plan.)doc");
  summary.def(py::init<>())
      .def_readonly("stages", &TrainingSummary::stages, "One OptimizerSummary per stage that ran.")
      .def_readonly("stage_names", &TrainingSummary::stage_names, "The stages' names, beside stages.")
      .def_readonly("history", &TrainingSummary::history,
                    "The merged history: counts go on across stages; value is the best so far.")
      .def_readonly("initial_value", &TrainingSummary::initial_value, "The first stage's initial U-hat.")
      .def_readonly("best_value", &TrainingSummary::best_value, "The last stage's best U-hat.")
      .def_property_readonly(
          "best_theta", [](const TrainingSummary& s) { return vector_array(s.best_theta); },
          "The last stage's best theta.")
      .def_readonly("stopped_by_callback", &TrainingSummary::stopped_by_callback,
                    "Whether a callback stopped the plan.")
      .def("brief_report", &TrainingSummary::BriefReport, "One line per stage.")
      .def(
          "same_outcome",
          [](const TrainingSummary& a, const TrainingSummary& b) {
            if (a.stages.size() != b.stages.size() || a.stage_names != b.stage_names)
              return py::make_tuple(false, std::string("stages"));
            for (std::size_t k = 0; k < a.stages.size(); ++k) {
              std::string difference;
              if (!SameOutcome(a.stages[k], b.stages[k], &difference))
                return py::make_tuple(false, fmt::format("stages[{}].{}", k, difference));
            }
            return py::make_tuple(true, std::string());
          },
          py::arg("other"),
          "(True, '') when every stage ended identically (SameOutcome: every double bit for bit; wall "
          "seconds "
          "and resume counters ignored), else (False, the first difference).")
      .def("__repr__", &TrainingSummary::BriefReport);
  set_fields(summary, {"stages", "stage_names", "history", "initial_value", "best_value", "best_theta",
                       "stopped_by_callback"});

  m.def(
      "training_checkpoint_iterations",
      [](CheckpointArg checkpoint) {
        try {
          return TrainingCheckpointIterations(from_python(checkpoint, "checkpoint"));
        } catch (const nlohmann::json::exception& e) {
          throw py::value_error(std::string("checkpoint: ") + e.what());
        }
      },
      py::arg("checkpoint"),
      "Optimizer iterations done by the plan that wrote this training checkpoint (where a resumed progress "
      "bar "
      "starts); ValueError when it is not one.");

  m.def(
      "_train",
      [](UserObjectArg plan, Objective& objective, ArrayLikeArg theta) {
        for (const char* field :
             {"stages", "seed", "checkpoint_every", "on_checkpoint", "resume_from", "callbacks"})
          if (!py::hasattr(plan, field))
            throw py::value_error(fmt::format("plan: expected a TrainingPlan (no field {})", field));
        TrainingPlan p;
        std::vector<py::object> keep;  // the stages' objectives, alive for the run
        const py::object stages = plan.attr("stages");
        if (!py::isinstance<py::sequence>(stages)) throw py::value_error("plan.stages: expected a list");
        std::size_t k = 0;
        for (py::handle stage : stages) p.stages.push_back(stage_from_python(stage, k++, &keep));
        p.seed = as_seed(plan.attr("seed"), "plan.seed");
        try {
          p.checkpoint_every = plan.attr("checkpoint_every").cast<std::int64_t>();
        } catch (const py::cast_error&) {
          throw py::value_error("plan.checkpoint_every: expected an integer");
        }
        try {
          p.on_checkpoint = checkpoint_callback(plan.attr("on_checkpoint"));
        } catch (const py::value_error&) {
          throw py::value_error("plan.on_checkpoint: expected a callable or None");
        }
        const py::object resume = plan.attr("resume_from");
        if (!resume.is_none()) p.resume_from = from_python(resume, "plan.resume_from");
        const IterationCallbackList callbacks(plan.attr("callbacks"));
        p.callbacks = callbacks.pointers();
        std::string error;
        if (!p.IsValid(&error)) throw py::value_error("plan." + error);
        Theta t;
        if (!theta.is_none()) t = as_theta(theta, "theta", objective.parameters());
        TrainingSummary s;
        std::string json_error;  // a checkpoint field of the wrong JSON type, found deep in the library
        {
          ReleaseGilInterruptibly release;
          try {
            Train(p, objective, &t, &s);
          } catch (const nlohmann::json::exception& e) {
            json_error = e.what();
          }
        }
        if (!json_error.empty()) throw py::value_error("plan.resume_from: " + json_error);
        return py::make_tuple(vector_array(t), s);
      },
      py::arg("plan"), py::arg("objective"), py::arg("theta") = py::none(),
      "Runs a pegasus.TrainingPlan (use pegasus.train).");
}

}  // namespace pegasus::python
