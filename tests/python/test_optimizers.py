"""Every optimizer from Python: Options and Summary with the C++ field names, checkpoints and resumes."""
import numpy as np
import pytest

import pegasus


def quadratic(theta):
    return -float(np.sum((theta - np.array([0.3, -0.2])) ** 2))


def spec():
    return pegasus.ParameterSpec([pegasus.Parameter("a", 0.0, -1.0, 1.0, 0.1),
                                  pegasus.Parameter("b", 0.0, -1.0, 1.0, 0.1)])


@pytest.mark.parametrize("method", ["gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch", "cmaes", "ars"])
def test_every_continuous_method_finds_the_maximum(method):
    options = pegasus.OptimizerOptions(method)
    options.ars.max_iterations, options.ars.step_size = 400, 0.1
    options.hill_climbing.max_iterations = 3000
    options.hill_climbing.proposals_per_iteration = 4
    options.nlopt.max_evaluations = 4000
    theta, summary = pegasus.solve(pegasus.FunctionObjective(spec(), quadratic), options)
    assert summary.method == method
    assert summary.parameter_names == ["a", "b"]
    assert summary.best_value == quadratic(summary.best_theta)
    tolerance = {"esch": 0.1, "crs2": 2e-2, "hill-climb": 2e-2, "ars": 2e-3}.get(method, 1e-4)  # global, stochastic searches
    assert theta == pytest.approx([0.3, -0.2], abs=tolerance)
    assert summary.best_value > summary.initial_value
    assert summary.evaluations >= summary.iterations > 0
    assert summary.termination_type in ("CONVERGENCE", "MAX_ITERATIONS", "MAX_EVALUATIONS")


def test_exhaustive_search_enumerates_integer_parameters():
    s = pegasus.ParameterSpec([pegasus.Parameter("i", 0, 0, 4, 1, True), pegasus.Parameter("j", 0, 0, 3, 1, True)])
    options = pegasus.OptimizerOptions("exhaustive")
    options.exhaustive.keep_all_values = True
    theta, summary = pegasus.solve(pegasus.FunctionObjective(s, lambda t: -abs(t[0] - 3) - abs(t[1] - 1)), options)
    assert list(theta) == [3.0, 1.0]
    assert summary.termination_type == "SEARCH_COMPLETE"
    assert len(summary.all_values) == 20 and max(summary.all_values) == 0.0


@pytest.mark.parametrize("method", ["gradient", "hill-climb", "bobyqa", "cmaes", "ars"])
def test_resuming_from_a_checkpoint_ends_as_the_uninterrupted_run(method):
    def options():
        o = pegasus.OptimizerOptions(method)
        o.cmaes.max_iterations = 6
        o.ars.max_iterations = 6
        o.gradient.max_iterations = 6
        o.hill_climbing.max_iterations = 6
        o.nlopt.max_evaluations = 12
        return o
    objective = pegasus.FunctionObjective(spec(), quadratic)
    checkpoints = []
    full_options = options()
    full_options.set_checkpointing(2, checkpoints.append)
    _, full = pegasus.solve(objective, full_options)
    assert checkpoints
    resumed_options = options()
    resumed_options.set_checkpointing(2, lambda c: None, resume_from=checkpoints[0])
    _, resumed = pegasus.solve(objective, resumed_options)
    assert resumed.resumed
    same, difference = full.same_outcome(resumed)
    assert same, difference


def test_invalid_options_raise_value_error_naming_the_field():
    options = pegasus.OptimizerOptions("gradient")
    options.gradient.max_step = -1.0
    assert options.is_valid()[0] is False and "gradient.max_step" in options.is_valid()[1]
    with pytest.raises(ValueError, match="gradient.max_step"):
        pegasus.solve(pegasus.FunctionObjective(spec(), quadratic), options)
    with pytest.raises(ValueError, match="method: expected one of exhaustive, gradient, .*got 'newton'"):
        pegasus.OptimizerOptions("newton")
    renamed = pegasus.OptimizerOptions("gradient")
    renamed.method = "newton"
    with pytest.raises(ValueError, match="method"):
        pegasus.solve(pegasus.FunctionObjective(spec(), quadratic), renamed)
    with pytest.raises(ValueError, match="algorithm"):
        pegasus.NloptOptions().algorithm = "lbfgs"


def test_an_exception_in_the_objective_reaches_the_caller():
    def broken(theta):
        raise ZeroDivisionError("inside the objective")
    with pytest.raises(ZeroDivisionError, match="inside the objective"):
        pegasus.solve(pegasus.FunctionObjective(spec(), broken), pegasus.OptimizerOptions("gradient"))


def test_every_optimizer_and_training_option_and_result_says_what_it_is():
    for cls in (pegasus.OptimizerOptions, pegasus.GradientAscentOptions, pegasus.HillClimbingOptions,
                pegasus.ExhaustiveSearchOptions, pegasus.NloptOptions, pegasus.CmaesOptions,
                pegasus.AugmentedRandomSearchOptions, pegasus.HoverTrainingOptions,
                pegasus.BicycleTrainingOptions, pegasus.OptimizerSummary, pegasus.IterationRecord,
                pegasus.TrainingSummary, pegasus.HoverTrainingResult):
        undocumented = [name for name, value in vars(cls).items()
                        if isinstance(value, property) and len((value.__doc__ or "").strip()) < 10]
        assert undocumented == [], cls.__name__
