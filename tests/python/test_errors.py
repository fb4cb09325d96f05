"""Bad input raises ValueError naming the argument and what was expected; nothing crashes the interpreter."""
import numpy as np
import pytest

import pegasus

import numpy_bicycle
from test_vectorized import Gain, Walker


def problem(model=None, policy=None, **kwargs):
    args = dict(seed=1, scenarios=4, horizon=5)
    args.update(kwargs)
    return pegasus.VectorizedProblem(model or Walker(), policy or Gain(), **args)


@pytest.mark.parametrize("theta,message", [
    (np.array([0.1, 0.2]), r"theta: expected a 1-D array of length 1, got shape \(2,\)"),
    (np.array([[0.1]]), r"theta: expected a 1-D array of length 1"),
    (np.array([np.nan]), r"theta: expected finite numbers, got nan"),
    (np.array([np.inf]), r"theta: expected finite numbers"),
    (np.array(["a"]), r"theta: expected an array of real numbers, got dtype <U1"),
    (np.array([1j]), r"theta: expected an array of real numbers, got dtype complex128"),
    (np.array([object()]), r"theta: expected an array of real numbers, got dtype object"),
    (None, r"theta: expected an array of real numbers, got None"),
])
def test_bad_theta(theta, message):
    with pytest.raises(ValueError, match=message):
        problem().uhat(theta)


def test_other_dtypes_and_non_contiguous_arrays_give_the_same_bits():
    p = problem()
    thetas = np.array([[1.0, 9.0], [0.0, 9.0], [2.0, 9.0]])[:, :1]  # a strided column
    assert not thetas.flags["C_CONTIGUOUS"]
    assert np.array_equal(p.uhat_batch(thetas), p.uhat_batch(np.ascontiguousarray(thetas)))
    assert p.uhat(np.array([1], dtype=np.int32)) == p.uhat(np.array([1.0]))
    assert p.uhat([1.0]) == p.uhat(np.array([1.0], dtype=np.float32))


def test_bad_batch_shapes():
    with pytest.raises(ValueError, match=r"thetas: expected a 2-D array of shape \(any, 1\), got shape \(3, 2\)"):
        problem().uhat_batch(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="thetas: expected"):
        problem().uhat_batch(np.zeros((2, 1, 1)))


@pytest.mark.parametrize("field,value", [("scenarios", 0), ("scenarios", -5), ("horizon", -1), ("gamma", 1.5),
                                         ("gamma", float("nan")), ("seed", -2), ("variant", "halton")])
def test_bad_problem_settings(field, value):
    with pytest.raises(ValueError, match=field if field != "scenarios" else "count"):
        problem(**{field: value})


class BadModel(Walker):
    def __init__(self, what):
        super().__init__()
        self.what = what

    def step(self, s, a, p):
        nxt = super().step(s, a, p)
        if self.what == "step shape":
            return nxt[:, :0]
        if self.what == "step dtype":
            return np.full(nxt.shape, "x")
        return nxt

    def reward(self, s, a, nxt):
        r = super().reward(s, a, nxt)
        if self.what == "reward nan":
            r[0] = np.nan
        if self.what == "reward shape":
            return r[:, None]
        return r

    def terminal(self, s):
        done = super().terminal(s)
        return done[:1] if self.what == "terminal shape" else done


@pytest.mark.parametrize("what,message", [
    ("step shape", r"model.step result: expected a 2-D array of shape \(4, 1\), got shape \(4, 0\)"),
    ("step dtype", r"model.step result: expected an array of real numbers, got dtype <U1"),
    ("reward nan", r"model.reward result: expected finite numbers, got nan"),
    ("reward shape", r"model.reward result: expected a 1-D array of length 4"),
    ("terminal shape", r"model.terminal result: expected a 1-D array of length 4"),
])
def test_a_model_returning_the_wrong_thing(what, message):
    with pytest.raises(ValueError, match=message):
        problem(BadModel(what)).uhat(np.array([1.0]))


def test_models_and_policies_missing_pieces():
    class NoStep:
        noise_dim = 1
        initial_noise_dim = 1
        def initial_state(self, p):
            return p
        def reward(self, s, a, n):
            return s[:, 0]
    with pytest.raises(ValueError, match="model: expected a method step"):
        problem(NoStep())
    class NoDims(Walker):
        noise_dim = -1
    with pytest.raises(ValueError, match=r"model.noise_dim: expected an integer in \[0, 100000\], got -1"):
        problem(NoDims())
    class NoSpec:
        def act(self, thetas, obs):
            return obs
    with pytest.raises(ValueError, match="policy: expected an attribute parameters"):
        problem(policy=NoSpec())
    with pytest.raises(ValueError, match="model.observe result: expected 15 columns for the policy, got 1"):
        problem(policy=numpy_bicycle.feature_policy()).uhat(pegasus.bicycle_balancing_theta())


def test_a_python_exception_in_the_model_reaches_the_caller():
    class Raising(Walker):
        def step(self, s, a, p):
            raise KeyError("from the model")
    with pytest.raises(KeyError, match="from the model"):
        problem(Raising()).uhat(np.array([1.0]))
    options = pegasus.OptimizerOptions("gradient")
    with pytest.raises(KeyError, match="from the model"):
        pegasus.solve(problem(Raising()), options)


def test_builtin_policy_and_env_arguments():
    with pytest.raises(ValueError, match="observation_dim"):
        pegasus.LinearPolicy(-1, [0.0], [1.0])
    with pytest.raises(ValueError, match="low, high"):
        pegasus.LinearPolicy(2, [0.0, 1.0], [1.0])
    with pytest.raises(ValueError, match="low, high"):
        pegasus.SigmoidPolicy(2, [2.0], [1.0])
    with pytest.raises(ValueError, match=r"observations: expected a 2-D array of shape \(any, 2\)"):
        pegasus.LinearPolicy(2, [0.0], [1.0]).act(np.zeros(2), np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"states: expected a 2-D array of shape \(any, 9\)"):
        pegasus.Bicycle().step(np.zeros((2, 8)), np.zeros((2, 2)), np.zeros((2, 1)))
    with pytest.raises(ValueError, match="threads"):
        pegasus.BicycleProblem(seed=1, scenarios=2, horizon=3, threads=0)
    options = pegasus.BicycleTrainingOptions()
    options.gamma = 2.0
    with pytest.raises(ValueError, match="gamma"):
        pegasus.train_bicycle(options)
    with pytest.raises(ValueError, match="parameter a: name already used"):
        pegasus.ParameterSpec([pegasus.Parameter("a"), pegasus.Parameter("a")])
    with pytest.raises(ValueError, match="expected lower <= initial <= upper"):
        pegasus.ParameterSpec([pegasus.Parameter("a", initial=2.0, lower=0.0, upper=1.0)])


@pytest.mark.parametrize("call", [
    lambda: pegasus.train_hover(None),
    lambda: pegasus.hover_init_from_model(None),
    lambda: pegasus.lqr_hover_init(None),
    lambda: pegasus.hover_reward_for(None),
    lambda: pegasus.HoverProblem.from_training_options(None),
])
def test_a_model_of_none_is_a_value_error_not_a_crash(call):
    # None casts to an empty model pointer in the binding; each of these once dereferenced it (a segfault).
    with pytest.raises(ValueError, match="model: expected a pegasus.IdentifiedModel or the path of a model.json"):
        call()
