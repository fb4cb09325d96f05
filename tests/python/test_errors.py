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
    with pytest.raises(ValueError, match=field):
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
        if self.what == "step nan":
            return nxt * np.nan
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
        if self.what == "terminal half":
            return np.full(len(done), 0.5)
        return done[:1] if self.what == "terminal shape" else done


@pytest.mark.parametrize("what,message", [
    ("step shape", r"model.step result: expected a 2-D array of shape \(4, 1\), got shape \(4, 0\)"),
    ("step dtype", r"model.step result: expected an array of real numbers, got dtype <U1"),
    ("reward nan", r"model.reward result: expected finite numbers, got nan"),
    # A NaN state is named where it is made, even when the reward never reads it.
    ("step nan", r"model.step result: expected finite numbers, got nan"),
    ("reward shape", r"model.reward result: expected a 1-D array of length 4"),
    ("terminal shape", r"model.terminal result: expected a 1-D array of length 4"),
    ("terminal half", r"model.terminal result: expected booleans \(or 0 and 1\), got 0.5 at row 0"),
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


def test_the_arrays_a_model_or_policy_gets_are_read_only():
    class Doubling(Gain):
        def act(self, thetas, observations):
            observations *= 2.0  # would change the state the model steps from
            return super().act(thetas, observations)
    with pytest.raises(ValueError, match="read-only"):
        problem(policy=Doubling()).uhat(np.array([1.0]))
    class SteppingInPlace(Walker):
        def step(self, s, a, p):
            s += a  # would change the state the reward is computed from
            return s
    with pytest.raises(ValueError, match="read-only"):
        problem(SteppingInPlace()).uhat(np.array([1.0]))


def test_a_nan_action_is_named_as_the_policys():
    class NanPolicy(Gain):
        def act(self, thetas, observations):
            return super().act(thetas, observations) * np.nan
    with pytest.raises(ValueError, match=r"policy.act result: expected finite numbers, got nan"):
        problem(policy=NanPolicy()).uhat(np.array([1.0]))


@pytest.mark.parametrize("make", [
    lambda: pegasus.GridworldProblem(4, seed=1, scenarios=1, horizon=5),
    lambda: pegasus.PomdpGridworldProblem(seed=1, scenarios=1, horizon=5),
])
def test_table_entries_outside_their_actions_are_refused_not_read_past_the_table(make):
    p = make()
    n = len(p.parameters)
    for bad in (4.0, -1.0, 1e6, -1e9, 1.5):  # 1e6 read past the table and crashed the interpreter
        with pytest.raises(ValueError, match=r"theta: action\[0\]: expected an integer in \[0, 3\]"):
            p.uhat(np.full(n, bad))
    with pytest.raises(ValueError, match=r"thetas\[1\]: action\[0\]: expected an integer"):
        p.uhat_batch(np.stack([np.zeros(n), np.full(n, 9.0)]))
    assert p.uhat(np.full(n, 3.0)) == p.uhat(np.full(n, 3.0))


def test_only_exhaustive_search_takes_integer_parameters():
    p = pegasus.GridworldProblem(3, seed=1, scenarios=3, horizon=20)
    for method in ("gradient", "hill-climb", "crs2", "esch", "cmaes"):
        with pytest.raises(ValueError, match=f"optimizer method {method}: searches real numbers, but parameter "
                                             r"'action\[0\]' is an integer"):
            pegasus.solve(p, pegasus.OptimizerOptions(method))
    theta, summary = pegasus.solve(p, pegasus.OptimizerOptions("exhaustive"))
    assert summary.termination_type == "SEARCH_COMPLETE" and np.all(theta == np.round(theta))


def test_parameters_are_read_only_and_checked():
    spec = pegasus.ParameterSpec.from_names(["a", "b"])
    with pytest.raises(AttributeError):
        spec[0].initial = 99.0  # a copy would have taken it silently
    with pytest.raises(KeyError, match="no parameter named 'zz'"):
        spec.index_of("zz")
    assert spec.index_of(name="b") == 1
    with pytest.raises(ValueError, match="parameter a: expected a finite initial value, got inf"):
        pegasus.ParameterSpec([pegasus.Parameter("a", initial=float("inf"))])
    with pytest.raises(ValueError, match="parameter t: expected a whole initial value"):
        pegasus.ParameterSpec([pegasus.Parameter("t", initial=0.5, lower=0, upper=3, integer=True)])


def test_an_aircraft_with_endless_substeps_is_refused():
    for params, make in ((pegasus.AircraftParams(), pegasus.Aircraft), (pegasus.QuadrotorParams(), pegasus.Quadrotor)):
        params.substeps = 10**9  # one step ran for minutes
        with pytest.raises(ValueError, match=r"substeps in \[1, 10000\]"):
            make(params)


def test_reward_weights_beyond_the_bound_are_refused():
    options = pegasus.BicycleTrainingOptions()
    options.bicycle.fall_reward = -1e308  # U-hat overflowed to -inf and training ended as if it had worked
    with pytest.raises(ValueError, match=r"fall_reward: expected a number in \[-1000000000000, 1000000000000\]"):
        pegasus.train_bicycle(options)


def test_ctrl_c_stops_a_long_cpp_run_within_an_iteration():
    import os
    import signal
    import threading
    import time
    options = pegasus.BicycleTrainingOptions()
    options.optimizer.method = "hill-climb"
    options.optimizer.hill_climbing.max_iterations = 100000  # minutes of C++ without a Python callback
    options.threads = 1
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        pegasus.train_bicycle(options)
    assert time.monotonic() - start < 10


def test_a_file_the_machine_refuses_is_an_os_error(tmp_path):
    policy = pegasus.HeliPolicy.hover(pegasus.HoverPolicy().parameters.initial)
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OSError, match="cannot"):
        policy.save(str(blocker / "policy.json"))  # a directory that is a file


def test_ctrl_c_stops_a_long_uhat_call_within_seconds_and_the_next_call_runs():
    """Issue 51: one large uhat call ignored Ctrl-C for over 60 s. Uninterrupted, this call runs for minutes."""
    import os
    import signal
    import threading
    import time

    problem = pegasus.BicycleProblem(seed=1, scenarios=200000, horizon=5000, gamma=0.998, threads=2)
    theta = pegasus.bicycle_balancing_theta()
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        problem.uhat(theta)
    elapsed = time.monotonic() - start
    timer.join()
    assert 0.9 < elapsed < 4.0
    # The interrupt is spent: the same problem evaluates again, to the same bits as a fresh one.
    small = pegasus.BicycleProblem(seed=1, scenarios=4, horizon=50, gamma=0.998, threads=2)
    assert small.uhat(theta) == pegasus.BicycleProblem(seed=1, scenarios=4, horizon=50, gamma=0.998,
                                                       threads=1).uhat(theta)
