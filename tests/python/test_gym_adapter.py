"""Gymnasium-style environments as deterministic models: one seed per scenario, checked by replay."""
import numpy as np
import pytest

import pegasus
from pegasus.gym import GymModel


class NoisyWalk:
    """A Gymnasium-style environment (reset(seed=) / step(action)) whose randomness all comes from the
    generator reset seeds: x' = x + a + N(0, 0.1), reward -x'^2, truncated after 30 steps."""

    def reset(self, seed=None):
        self.rng = np.random.default_rng(seed)
        self.x, self.t = self.rng.uniform(-1.0, 1.0), 0
        return np.array([self.x]), {}

    def step(self, action):
        self.x = self.x + float(np.clip(action, -1.0, 1.0)) + self.rng.normal(0.0, 0.1)
        self.t += 1
        return np.array([self.x]), -self.x ** 2, abs(self.x) > 5.0, self.t >= 30, {}


class Unseeded(NoisyWalk):
    """Draws from a generator that reset does not seed."""
    shared = np.random.default_rng(0)

    def step(self, action):
        obs, r, term, trunc, info = super().step(action)
        return obs + self.shared.normal(0.0, 0.01), r, term, trunc, info


class Feedback:
    parameters = pegasus.ParameterSpec([pegasus.Parameter("k", initial=0.2, lower=0.0, upper=1.5)])

    def act(self, thetas, observations):
        return -thetas[:, :1] * observations


def test_a_scenario_replays_exactly():
    model = GymModel(NoisyWalk, check_actions=[0.1] * 10)
    problem = pegasus.VectorizedProblem(model, Feedback(), seed=3, scenarios=6, horizon=40)
    returns = problem.returns(np.array([[0.5], [0.9]]))
    assert np.array_equal(returns, problem.returns(np.array([[0.5], [0.9]])))
    # Scenario 2 by hand: the environment seeded from the scenario's initial uniform.
    u = problem.scenarios.initial_noise()[2, 0]
    env = NoisyWalk()
    obs, _ = env.reset(seed=GymModel.scenario_seed(u))
    total = 0.0
    for _ in range(40):
        obs, r, term, trunc, _ = env.step(-0.9 * obs[0])
        total += r
        if term or trunc:
            break
    assert returns[1, 2] == total


def test_pegasus_improves_the_gain_on_the_seeded_scenarios():
    model = GymModel(NoisyWalk, check_actions=[0.0] * 5)
    problem = pegasus.VectorizedProblem(model, Feedback(), seed=1, scenarios=8, horizon=30)
    theta, summary = pegasus.solve(problem, pegasus.OptimizerOptions("bobyqa"))
    assert summary.best_value > summary.initial_value
    assert theta[0] > 0.5


def test_a_non_deterministic_environment_is_refused():
    with pytest.raises(ValueError, match="not deterministic given its seed"):
        GymModel(Unseeded, check_actions=[0.0] * 5)
    with pytest.raises(ValueError, match="make_env"):
        GymModel(None, check_actions=[])
