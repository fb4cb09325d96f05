"""The training layer from Python (optimizers/training.hpp): plans of optimizer stages with one seed, one
checkpoint schema and iteration callbacks; Options and Summary of every optimizer (cmaes and ars included) as
dataclass-like objects with the C++ field names; a resumed plan ends with the bits of an uninterrupted one, and
no result depends on threads."""
import copy

import numpy as np
import pytest

import pegasus

# The C++ structs' fields (include/pegasus/optimizers/*.hpp), callbacks aside (passed to solve and train).
CHECKPOINTING = ["checkpoint_every", "on_checkpoint", "resume_from"]
CPP_FIELDS = {
    pegasus.GradientAscentOptions: ["max_iterations", "max_evaluations", "relative_step", "initial_step", "max_step",
                                    "min_step", "step_growth", "max_backtracks", "function_tolerance"],
    pegasus.HillClimbingOptions: ["seed", "stream", "max_iterations", "max_evaluations", "proposals_per_iteration",
                                  "initial_step", "max_step", "min_step", "step_growth", "step_shrink"],
    pegasus.ExhaustiveSearchOptions: ["max_policies", "block_size", "keep_all_values"],
    pegasus.NloptOptions: ["algorithm", "max_evaluations", "initial_step", "x_tolerance", "function_tolerance",
                           "population", "seed"],
    pegasus.CmaesOptions: ["seed", "stream", "max_iterations", "max_evaluations", "population_size", "initial_step",
                           "x_tolerance", "function_tolerance", "max_condition", "stall_generations",
                           "stall_tolerance", "restarts"],
    pegasus.AugmentedRandomSearchOptions: ["seed", "stream", "max_iterations", "max_evaluations", "directions",
                                           "top_directions", "step_size", "exploration_noise"],
}


def pendulum(threads=1, scenarios=6):
    return pegasus.PendulumProblem(seed=4, scenarios=scenarios, horizon=120, gamma=0.99, threads=threads)


def two_stage_plan(**fields):
    gradient = pegasus.OptimizerOptions("gradient")
    gradient.gradient.max_iterations = 3
    cmaes = pegasus.OptimizerOptions("cmaes")
    cmaes.cmaes.max_iterations, cmaes.cmaes.population_size = 4, 6
    return pegasus.TrainingPlan(stages=[pegasus.TrainingStage("gradient", gradient),
                                        pegasus.TrainingStage("refine", cmaes, seeds=pegasus.REFINE_SEED_DOMAINS)],
                                **{"seed": 11, **fields})


def test_options_and_summaries_have_the_cpp_fields_and_defaults():
    for cls, fields in CPP_FIELDS.items():
        assert list(cls._fields) == fields + CHECKPOINTING, cls.__name__
    assert list(pegasus.OptimizerOptions._fields) == ["method", "exhaustive", "gradient", "hill_climbing", "nlopt",
                                                      "cmaes", "ars"]
    assert set(pegasus.optimizer_methods()) >= {"cmaes", "ars"}
    c, a = pegasus.CmaesOptions(), pegasus.AugmentedRandomSearchOptions()
    assert (c.stream, c.max_iterations, c.population_size, c.initial_step, c.max_condition) == (
        0x434D4145, 1000, 0, 0.3, 1e14)
    assert (a.stream, a.max_iterations, a.directions, a.top_directions, a.step_size, a.exploration_noise) == (
        0x41525321, 100, 8, 8, 0.02, 0.03)
    o = pegasus.OptimizerOptions("ars")
    twin = copy.deepcopy(o)
    assert twin == o and "ars=AugmentedRandomSearchOptions(seed=0" in repr(o)
    twin.ars.directions = 4
    assert twin != o and o.ars.directions == 8  # a copy, not a view
    assert pegasus.OptimizerOptions("cmaes").iteration_limit() == 1000
    assert list(pegasus.SeedDomains._fields) == ["hill_climbing", "nlopt", "cmaes", "ars"]
    assert pegasus.REFINE_SEED_DOMAINS.cmaes == 0x52434D41 and pegasus.SeedDomains().cmaes == 0x434D4145
    mine = pegasus.SeedDomains(cmaes=7)
    assert mine.cmaes == 7 and mine.ars == pegasus.SeedDomains().ars
    with pytest.raises(ValueError, match=r"draws random numbers \(hill_climbing, nlopt, cmaes, ars\), got 'gradient'"):
        pegasus.SeedDomains(gradient=1)
    with pytest.raises(ValueError, match=r"cmaes: expected an integer in \[0, 2\*\*32\), got 4294967296"):
        pegasus.SeedDomains(cmaes=2**32)
    with pytest.raises(ValueError, match=r"nlopt: expected an integer in \[0, 2\*\*32\), got -1"):
        mine.nlopt = -1
    # One class per method, from the C++ list of methods, its docstring saying which methods read it.
    assert type(o.nlopt).__name__ == "NloptOptions" and "Options of bobyqa, sbplx, crs2, esch." in (
        pegasus.OptimizerOptions.nlopt.__doc__)
    assert [f for f in pegasus.TrainingPlan.__dataclass_fields__] == [
        "stages", "seed", "checkpoint_every", "on_checkpoint", "resume_from", "callbacks"]
    assert [f for f in pegasus.TrainingStage.__dataclass_fields__] == ["name", "optimizer", "seeds", "objective"]


def test_derived_seeds_are_those_train_gives_each_stage():
    o = pegasus.OptimizerOptions("cmaes")
    pegasus.derive_optimizer_seeds(11, pegasus.REFINE_SEED_DOMAINS, o)
    first = pegasus.OptimizerOptions("cmaes")
    pegasus.derive_optimizer_seeds(11, pegasus.SeedDomains(), first)
    assert o.cmaes.seed != first.cmaes.seed and o.ars.seed != o.cmaes.seed
    # The refine stage of a plan is solve() with those seeds from the gradient stage's best theta.
    objective = pendulum()
    theta, summary = pegasus.train(two_stage_plan(), objective)
    stage = two_stage_plan().stages[1].optimizer
    pegasus.derive_optimizer_seeds(11, pegasus.REFINE_SEED_DOMAINS, stage)
    alone, alone_summary = pegasus.solve(objective, stage, theta=summary.stages[0].best_theta)
    assert np.array_equal(alone, theta) and alone_summary.same_outcome(summary.stages[1]) == (True, "")


def test_a_plan_runs_its_stages_in_order_and_merges_their_history():
    theta, summary = pegasus.train(two_stage_plan(), pendulum())
    assert summary.stage_names == ["gradient", "refine"]
    assert [s.method for s in summary.stages] == ["gradient", "cmaes"]
    assert summary.best_value == summary.stages[1].best_value >= summary.stages[0].best_value
    assert np.array_equal(theta, summary.best_theta) and summary.initial_value == summary.stages[0].initial_value
    history = summary.history
    assert len(history) == summary.stages[0].iterations + summary.stages[1].iterations
    assert [r.iteration for r in history] == list(range(1, len(history) + 1))
    assert all(b.value >= a.value and b.evaluations > a.evaluations for a, b in zip(history, history[1:]))
    assert not summary.stopped_by_callback and "refine: cmaes" in summary.brief_report()


@pytest.mark.parametrize("stage", [0, 1])
def test_a_resumed_plan_ends_with_the_bits_of_the_uninterrupted_one_on_any_threads(stage):
    checkpoints = []
    theta, full = pegasus.train(two_stage_plan(checkpoint_every=1, on_checkpoint=checkpoints.append), pendulum(1))
    assert {c["format"] for c in checkpoints} == {"pegasus.training.checkpoint"}
    at_stage = [c for c in checkpoints if c["stage"] == stage]
    assert len(at_stage) >= 2
    checkpoint = at_stage[1]
    assert pegasus.training_checkpoint_iterations(checkpoint) >= 1
    resumed_theta, resumed = pegasus.train(two_stage_plan(resume_from=checkpoint), pendulum(3))
    assert np.array_equal(resumed_theta, theta)
    assert resumed.same_outcome(full) == (True, "")
    assert resumed.best_value == full.best_value and resumed.history[-1].value == full.history[-1].value


def test_threads_never_change_a_plan():
    one = pegasus.train(two_stage_plan(), pendulum(1))
    four = pegasus.train(two_stage_plan(), pendulum(4))
    assert np.array_equal(one[0], four[0]) and one[1].same_outcome(four[1]) == (True, "")


def test_callbacks_see_every_iteration_and_may_stop_the_plan():
    seen = []

    def watch(report):
        seen.append((report.method, report.record.iteration, report.record.value, report.best_theta.copy()))

    plain = pegasus.train(two_stage_plan(), pendulum())
    watched = pegasus.train(two_stage_plan(callbacks=[watch]), pendulum())
    assert np.array_equal(plain[0], watched[0]) and plain[1].same_outcome(watched[1]) == (True, "")
    assert len(seen) == len(plain[1].history) and {m for m, *_ in seen} == {"gradient", "cmaes"}

    def stop_at_two(report):
        return report.record.iteration >= 2 or None

    theta, stopped = pegasus.train(two_stage_plan(callbacks=[stop_at_two]), pendulum())
    assert stopped.stopped_by_callback and stopped.stage_names == ["gradient"]
    assert stopped.stages[0].termination_type == "USER_REQUESTED" and stopped.stages[0].iterations == 2
    _, solved = pegasus.solve(pendulum(), pegasus.OptimizerOptions("ars"),
                              callbacks=[lambda r: pegasus.CallbackReturnType.TERMINATE])
    assert solved.termination_type == "USER_REQUESTED" and solved.iterations == 1


def test_a_stage_may_have_its_own_objective():
    plan = two_stage_plan()
    bigger = pendulum(scenarios=12)
    plan.stages[1].objective = bigger
    theta, summary = pegasus.train(plan, pendulum())
    assert summary.stages[1].best_value == bigger.uhat(theta)


def test_bad_plans_raise_value_error_naming_the_field():
    with pytest.raises(ValueError, match="plan.stages: expected at least one stage"):
        pegasus.train(pegasus.TrainingPlan(), pendulum())
    plan = two_stage_plan()
    plan.stages[1].optimizer.cmaes.initial_step = -1.0
    with pytest.raises(ValueError, match=r"plan.stages\[1\].optimizer.cmaes.initial_step"):
        pegasus.train(plan, pendulum())
    with pytest.raises(ValueError, match="on_checkpoint"):
        pegasus.train(two_stage_plan(checkpoint_every=2), pendulum())
    with pytest.raises(ValueError, match="plan.on_checkpoint"):
        pegasus.train(two_stage_plan(checkpoint_every=2, on_checkpoint=3), pendulum())
    with pytest.raises(ValueError, match=r"callbacks\[1\]"):
        pegasus.train(two_stage_plan(callbacks=[print, "x"]), pendulum())
    with pytest.raises(ValueError, match="callbacks: expected a callback to return"):
        pegasus.train(two_stage_plan(callbacks=[lambda r: "stop"]), pendulum())
    with pytest.raises(ValueError, match="checkpoint"):
        pegasus.train(two_stage_plan(resume_from={"format": "something else"}), pendulum())
    with pytest.raises(ValueError, match="checkpoint: expected format"):
        pegasus.train(two_stage_plan(resume_from={"format": 1}), pendulum())
    with pytest.raises(ValueError, match="plan.seed"):
        pegasus.train(two_stage_plan(seed=-1), pendulum())
    with pytest.raises(ValueError, match=r"stages\[0\].objective"):
        pegasus.train(pegasus.TrainingPlan(stages=[pegasus.TrainingStage("x", objective="pendulum")]), pendulum())
    with pytest.raises(ValueError, match="theta"):
        pegasus.train(two_stage_plan(), pendulum(), theta=np.zeros(2))
    with pytest.raises(ValueError, match="plan: expected a TrainingPlan"):
        pegasus.train({"stages": []}, pendulum())
    with pytest.raises(ValueError, match="checkpoint"):
        pegasus.training_checkpoint_iterations({"format": 1})


def test_every_compiled_name_has_a_stub_and_every_new_class_a_docstring(source_dir):
    import ast
    tree = ast.parse((source_dir / "python" / "pegasus" / "_pegasus.pyi").read_text())
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            stubbed.add(node.target.id)
        elif isinstance(node, ast.Assign):
            stubbed.update(t.id for t in node.targets)
    public = {name for name in dir(pegasus._pegasus) if not name.startswith("__")}
    assert public <= stubbed, sorted(public - stubbed)
    # Every compiled class and function says what it is (a function's doc is its signature, then the text), and
    # a signature names Python classes, never a C++ type.
    for name in sorted(public):
        obj = getattr(pegasus._pegasus, name)
        doc = (obj.__doc__ or "").strip()
        if isinstance(obj, type):
            assert len(doc) > 20, name
        elif callable(obj):
            signature, _, text = doc.partition("\n")
            assert len(text.strip()) > 20, name
            assert "::" not in signature, (name, signature)
    # So does every method of a compiled class (fields aside).
    undocumented = []
    for name in sorted(public):
        cls = getattr(pegasus._pegasus, name)
        if not isinstance(cls, type):
            continue
        for member, value in vars(cls).items():
            if member.startswith("_") or isinstance(value, property) or not callable(value):
                continue
            signature, _, text = (value.__doc__ or "").strip().partition("\n")
            if len(text.strip()) < 15:
                undocumented.append(f"{name}.{member}")
    assert undocumented == []
    for name in ["CmaesOptions", "AugmentedRandomSearchOptions", "TrainingSummary", "SeedDomains", "IterationReport",
                 "Aircraft", "AircraftParams", "LearnedHeliModel", "LearnedModelOptions", "HoverProblem",
                 "HoverTrainingOptions", "HoverReward", "HoverPolicy", "HeliPolicy", "SetPoint"]:
        assert len(getattr(pegasus, name).__doc__ or "") > 40, name
    for name in ["train", "TrainingPlan", "TrainingStage", "train_hover", "bicycle_training_problem"]:
        assert len(getattr(pegasus, name).__doc__ or "") > 40, name


def test_every_property_of_every_class_says_what_it_is():
    # Fields, getters and class constants alike: help() shows a property's docstring, so a bare field name is all
    # a user would see. pybind11's own enum properties (__doc__, __members__, name, value) are pybind11's to word.
    import inspect
    enum_internals = {"__doc__", "__members__", "name", "value"}
    undocumented = []
    for name in dir(pegasus):
        cls = getattr(pegasus, name)
        if not inspect.isclass(cls):
            continue
        is_enum = "__members__" in vars(cls)
        for member, value in vars(cls).items():
            if not isinstance(value, property) or (is_enum and member in enum_internals):
                continue
            if type(value).__name__ == "pybind11_static_property":
                # pybind11 keeps no docstring on a static property: the class's docstring must explain it.
                if member not in (cls.__doc__ or ""):
                    undocumented.append(f"{name}.{member}")
            elif len((value.__doc__ or "").strip()) < 10:
                undocumented.append(f"{name}.{member}")
    assert undocumented == []
