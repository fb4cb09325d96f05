"""Simulators and policies written in numpy, evaluated by PEGASUS one Python call per time step for the whole
batch of (theta, scenario) pairs (thesis Eq 4.22)."""
import numpy as np
import pytest

import pegasus

import numpy_bicycle


class Walker:
    """x' = x + a + (p - 0.5); reward -|x'| (a 1-D walk pulled towards 0); absorbing beyond |x| > 3. Counts
    its calls."""

    noise_dim = 1
    initial_noise_dim = 1

    def __init__(self):
        self.calls = {"initial_state": 0, "step": 0, "reward": 0, "terminal": 0}
        self.seen_noise = []

    def initial_state(self, p0):
        self.calls["initial_state"] += 1
        return 4.0 * p0 - 2.0

    def step(self, s, a, p):
        self.calls["step"] += 1
        self.seen_noise.append(p.copy())
        return s + a + (p - 0.5)

    def reward(self, s, a, nxt):
        self.calls["reward"] += 1
        return -np.abs(nxt[:, 0])

    def terminal(self, s):
        self.calls["terminal"] += 1
        return np.abs(s[:, 0]) > 3.0


class Gain:
    """a = -k x, one parameter."""

    parameters = pegasus.ParameterSpec([pegasus.Parameter("k", initial=0.5, lower=0.0, upper=2.0)])

    def act(self, thetas, observations):
        return -thetas[:, :1] * observations


def reference_return(theta, scenarios, i, horizon, gamma):
    """One rollout in plain Python: the loop of evaluators/rollout.hpp."""
    init, noise = scenarios.initial_noise()[i], scenarios.step_noise()[i]
    x, ret, weight = 4.0 * init[0] - 2.0, 0.0, 1.0
    for t in range(horizon):
        if abs(x) > 3.0:
            break
        nxt = x - theta[0] * x + (noise[t, 0] - 0.5)
        ret += weight * -abs(nxt)
        weight *= gamma
        x = nxt
    return ret


def test_uhat_is_the_scenario_mean_of_the_plain_rollouts():
    problem = pegasus.VectorizedProblem(Walker(), Gain(), seed=4, scenarios=12, horizon=25, gamma=0.9)
    for k in [0.0, 0.3, 1.0, 1.9]:
        expected = [reference_return([k], problem.scenarios, i, 25, 0.9) for i in range(12)]
        assert problem.returns(np.array([k]))[0] == pytest.approx(expected, rel=1e-14, abs=1e-14)
        assert problem.uhat(np.array([k])) == sum(expected) / 12 or \
            problem.uhat(np.array([k])) == pytest.approx(np.mean(expected), rel=1e-14)


def test_one_python_call_per_time_step_for_a_whole_batch():
    model = Walker()
    problem = pegasus.VectorizedProblem(model, Gain(), seed=4, scenarios=30, horizon=40)
    thetas = np.linspace(0.8, 1.2, 31)[:, None]  # never absorbing: |x| stays small
    values = problem.uhat_batch(thetas)
    assert len(values) == 31
    assert model.calls == {"initial_state": 1, "step": 40, "reward": 40, "terminal": 40}
    assert model.seen_noise[0].shape == (31 * 30, 1)


def test_a_batch_gives_the_bits_of_single_evaluations():
    problem = pegasus.VectorizedProblem(Walker(), Gain(), seed=9, scenarios=7, horizon=30, gamma=0.95)
    thetas = np.array([[0.1], [0.7], [1.3], [0.0]])
    batch = problem.uhat_batch(thetas)
    for k in range(4):
        assert batch[k] == problem.uhat(thetas[k])


def test_the_model_sees_the_scenario_sets_numbers():
    model = Walker()
    problem = pegasus.VectorizedProblem(model, Gain(), seed=11, scenarios=5, horizon=6, variant="antithetic")
    problem.uhat(np.array([1.0]))  # x' = a + p - 0.5 stays within reach: no absorption
    expected = problem.scenarios.step_noise()
    for t, seen in enumerate(model.seen_noise):
        assert np.array_equal(seen[:, 0], expected[:, t, 0])


def test_absorbed_rollouts_take_no_more_steps():
    model = Walker()
    problem = pegasus.VectorizedProblem(model, Gain(), seed=2, scenarios=20, horizon=50)
    # k = 0 with noise drifts: some rollouts leave |x| <= 3 and must stop there.
    returns = problem.returns(np.array([0.0]))[0]
    expected = [reference_return([0.0], problem.scenarios, i, 50, 1.0) for i in range(20)]
    assert returns == pytest.approx(expected, rel=1e-14, abs=1e-14)


def test_builtin_sigmoid_policy_matches_the_numpy_policy():
    rng = np.random.default_rng(1)
    obs = rng.normal(size=(40, 5))
    thetas = rng.normal(size=(40, 30))
    builtin = numpy_bicycle.feature_policy().act(thetas, numpy_bicycle.features(obs))
    numpy_version = numpy_bicycle.NumpyBicyclePolicy().act(thetas, obs)
    assert builtin == pytest.approx(numpy_version, rel=1e-13, abs=1e-15)


def test_numpy_bicycle_steps_as_the_cpp_bicycle():
    rng = np.random.default_rng(3)
    model = numpy_bicycle.NumpyBicycle(goal=(1000.0, 0.0, 10.0))
    cpp = pegasus.Bicycle()
    p0 = rng.uniform(size=(64, 5))
    s = model.initial_state(p0)
    assert s[:, :9] == pytest.approx(cpp.initial_state(p0), rel=1e-12, abs=1e-12)
    for t in range(200):
        a = np.column_stack([rng.uniform(-2, 2, 64), rng.uniform(-0.02, 0.02, 64)])
        p = rng.uniform(size=(64, 1))
        expected = cpp.step(s[:, :9], a, p)
        s = model.step(s, a, p)
        assert s[:, :9] == pytest.approx(expected, rel=1e-9, abs=1e-9)
        s[:, :9] = expected  # keep both on the same trajectory


def test_numpy_bicycle_uhat_agrees_with_the_cpp_bicycle_on_the_same_scenarios():
    steering = pegasus.bicycle_balancing_theta()
    steering[12] = 0.4  # steer a little towards the goal
    model = numpy_bicycle.NumpyBicycle(goal=(1000.0, 0.0, 10.0))
    ours = pegasus.VectorizedProblem(model, numpy_bicycle.NumpyBicyclePolicy(), seed=5, scenarios=16, horizon=300,
                                     gamma=0.998)
    cpp = pegasus.BicycleProblem(pegasus.BicycleOptions(), seed=5, scenarios=16, horizon=300, gamma=0.998)
    unsteered = np.zeros(30)  # falls within a second or two: the fall penalty at gamma^(t + tau)
    for theta, falls in [(steering, 0), (unsteered, 16), (0.5 * steering, None)]:
        r_ours, r_cpp = ours.returns(theta)[0], cpp.returns(theta)
        if falls is not None:
            assert np.count_nonzero(r_cpp) == falls
        assert r_ours == pytest.approx(r_cpp, rel=1e-9, abs=1e-12)


class Cart:
    """A noisy cart on a rail (x, v), absorbed beyond |x| = 2: only +, *, / and comparisons, whose results numpy
    computes exactly rounded whatever its SIMD path (numpy 1.24's sin, arctan, exp, ... may differ in the last bit
    with the memory layout of their arrays, so a model using them is not bit-reproducible from call to call,
    threads or not)."""
    noise_dim, initial_noise_dim = 1, 2

    def initial_state(self, p0):
        return 2.0 * p0 - 1.0

    def step(self, s, a, p):
        v = s[:, 1] + 0.05 * (a[:, 0] + (p[:, 0] - 0.5))
        return np.stack([s[:, 0] + 0.05 * v, v], axis=1)

    def reward(self, s, a, nxt):
        return -(nxt[:, 0] * nxt[:, 0] + 0.1 * a[:, 0] * a[:, 0]) - 10.0 * (np.abs(nxt[:, 0]) > 2.0)

    def terminal(self, s):
        return np.abs(s[:, 0]) > 2.0


class NumpyLinear:
    parameters = pegasus.ParameterSpec.from_names(["kx", "kv"])

    def act(self, thetas, observations):
        return np.clip(np.einsum("ij,ij->i", thetas, observations), -3.0, 3.0)


@pytest.mark.parametrize("builtin", [False, True])
def test_threads_give_the_same_bits_as_one_thread(builtin):
    # A numpy policy (theta rows on the pool) or the built-in LinearPolicy (its actions on the pool), rollouts
    # absorbed at different steps, on 1, 2 and 5 threads: the same returns and U-hat, bit for bit.
    policy = pegasus.LinearPolicy(2, [-3.0], [3.0]) if builtin else NumpyLinear()
    thetas = np.array([[-1.0, -1.5], [0.5, 0.0], [-3.0, -0.2], [0.0, 0.0], [-0.5, -2.0]])
    results = []
    for threads in (1, 2, 5):
        problem = pegasus.VectorizedProblem(Cart(), policy, seed=9, scenarios=40, horizon=300, gamma=0.99,
                                            threads=threads)
        assert problem.threads == threads
        results.append((problem.returns(thetas), problem.uhat_batch(thetas)))
    absorbed = results[0][0] < -10.0
    assert 0 < np.count_nonzero(absorbed) < absorbed.size  # some rollouts ended early, others ran on
    for returns, values in results[1:]:
        assert np.array_equal(returns, results[0][0])
        assert np.array_equal(values, results[0][1])


def test_the_numpy_bicycle_agrees_on_any_threads_to_numpys_last_bit():
    model = numpy_bicycle.NumpyBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=0.998)
    thetas = np.tile(pegasus.bicycle_balancing_theta(), (5, 1))
    thetas[1:, :15] += np.random.default_rng(2).normal(scale=0.5, size=(4, 15))
    returns = [pegasus.VectorizedProblem(model, numpy_bicycle.NumpyBicyclePolicy(), seed=9, scenarios=7, horizon=200,
                                         gamma=0.998, threads=threads).returns(thetas) for threads in (1, 3)]
    assert np.count_nonzero(returns[0] < -50) > 0  # some rollouts fell
    assert returns[1] == pytest.approx(returns[0], rel=1e-12, abs=1e-12)


def test_the_policy_sees_the_same_read_only_theta_rows_while_the_live_rows_stay():
    seen = []

    class Recording:
        parameters = pegasus.ParameterSpec.from_names(["k"])

        def act(self, thetas, observations):
            seen.append(thetas)
            assert not thetas.flags.writeable
            return thetas[:, :1] * observations[:, :1]

    class Falls:  # row r of scenario i is absorbed after i steps
        noise_dim, initial_noise_dim = 0, 1

        def initial_state(self, p0):
            return np.zeros((p0.shape[0], 1))

        def step(self, s, a, p):
            return s + 1.0

        def reward(self, s, a, nxt):
            return np.ones(s.shape[0])

        def terminal(self, s):
            return s[:, 0] >= 3.0

    problem = pegasus.VectorizedProblem(Falls(), Recording(), seed=1, scenarios=2, horizon=6, threads=2)
    assert list(problem.returns(np.array([[1.0], [2.0]]))[:, 0]) == [3.0, 3.0]
    assert len(seen) == 3 and seen[0] is seen[1] is seen[2]
    with pytest.raises(ValueError, match="threads"):
        pegasus.VectorizedProblem(Falls(), Recording(), seed=1, scenarios=2, horizon=6, threads=0)
