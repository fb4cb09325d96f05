"""Built-in environments as objects: batch models, PEGASUS problems on any number of threads."""
import numpy as np
import pytest

import pegasus


def test_pendulum_steps_as_gymnasium_writes_it():
    rng = np.random.default_rng(0)
    pendulum = pegasus.Pendulum()
    s = pendulum.initial_state(rng.uniform(size=(50, 2)))
    assert np.all(np.abs(s[:, 0]) <= np.pi) and np.all(np.abs(s[:, 1]) <= 1.0)
    u = rng.uniform(-3.0, 3.0, size=(50, 1))
    g, m, l, dt = 10.0, 1.0, 1.0, 0.05
    torque = np.clip(u[:, 0], -2.0, 2.0)
    speed = np.clip(s[:, 1] + (3 * g / (2 * l) * np.sin(s[:, 0]) + 3.0 / (m * l ** 2) * torque) * dt, -8.0, 8.0)
    assert pendulum.step(s, u) == pytest.approx(np.column_stack([s[:, 0] + speed * dt, speed]), rel=1e-14)
    angle = np.mod(s[:, 0] + np.pi, 2 * np.pi) - np.pi
    assert pendulum.reward(s, u) == pytest.approx(-(angle ** 2 + 0.1 * s[:, 1] ** 2 + 0.001 * torque ** 2),
                                                  rel=1e-12)


@pytest.mark.parametrize("make", [
    lambda threads: pegasus.PendulumProblem(seed=2, scenarios=12, horizon=100, gamma=0.99, threads=threads),
    lambda threads: pegasus.BicycleProblem(seed=2, scenarios=12, horizon=200, gamma=0.998, threads=threads),
])
def test_builtin_uhat_is_the_mean_of_the_returns_on_any_threads(make):
    one, three = make(1), make(3)
    spec = one.parameters
    thetas = np.stack([spec.initial + 0.01 * k for k in range(5)]) if len(spec) != 30 else \
        np.stack([pegasus.bicycle_balancing_theta() + 0.02 * k for k in range(5)])
    batch = one.uhat_batch(thetas)
    assert np.array_equal(batch, three.uhat_batch(thetas))
    for k in range(5):
        assert batch[k] == one.uhat(thetas[k])
        assert batch[k] == pytest.approx(np.mean(one.returns(thetas[k])), rel=1e-15)


def test_pegasus_improves_the_pendulum_swing_up():
    problem = pegasus.PendulumProblem(seed=5, scenarios=8, horizon=200, gamma=0.99, refinements=False)
    options = pegasus.OptimizerOptions("bobyqa")
    options.nlopt.max_evaluations = 60
    theta, summary = pegasus.solve(problem, options)
    assert summary.best_value > summary.initial_value
    assert problem.uhat(theta) == summary.best_value


def test_pegasus_estimates_the_exact_value_of_the_optimal_gridworld_policy():
    n = 5
    mdp = pegasus.corner_gridworld_mdp(n, intended=0.8, gamma=1.0)
    solved = mdp.policy_iteration()
    problem = pegasus.GridworldProblem(n, 0.8, seed=7, scenarios=2000, horizon=200, threads=2)
    returns = problem.returns(solved.policy.astype(float))
    exact = solved.value[0]  # the start cell (0, 0)
    assert abs(returns.mean() - exact) < 4.0 * returns.std() / np.sqrt(len(returns))
    assert problem.uhat(solved.policy.astype(float)) == returns.mean() or \
        problem.uhat(solved.policy.astype(float)) == pytest.approx(returns.mean(), rel=1e-15)
    phi = pegasus.corner_gridworld_potential(n, 0.8)
    assert phi[-1] == 0.0 and phi[0] == pytest.approx(-2 * (n - 1) / 0.8)


def test_exhaustive_search_solves_the_pomdp_gridworld_table_policy():
    problem = pegasus.PomdpGridworldProblem(5, 5, seed=3, scenarios=30, horizon=40, threads=2)
    assert len(problem.parameters) >= 2 and all(p.integer for p in problem.parameters)
    theta, summary = pegasus.solve(problem, pegasus.OptimizerOptions("exhaustive"))
    assert summary.termination_type == "SEARCH_COMPLETE"
    assert summary.evaluations == 4 ** len(problem.parameters)
    assert summary.best_value > -40.0  # reaches the goal on every scenario before the horizon
    with pytest.raises(ValueError, match="width, height"):
        pegasus.PomdpGridworldProblem(1, 5, seed=3, scenarios=3, horizon=4)
    with pytest.raises(ValueError, match="intended"):
        pegasus.GridworldProblem(5, 0.0, seed=3, scenarios=3, horizon=4)
