"""A Gymnasium-style environment (reset(seed=) / step(action)) trained by PEGASUS (thesis §4.3): each scenario
seeds its own episode, so U-hat is a deterministic function of the policy's parameters.

The condition: all the environment's randomness comes from the generator reset(seed=...) seeds. GymModel
replays one seeded episode at construction and refuses an environment whose replay differs. With gymnasium
installed, `GymModel(lambda: gymnasium.make("Pendulum-v1"), check_actions=[[0.0]] * 10)` works the same way.
Run: PYTHONPATH=build/python /usr/bin/python3 <this file>
"""
import numpy as np

import pegasus
from pegasus.gym import GymModel


class WindyCart:
    """A cart on a line with random wind: x' = x + 0.1 v, v' = v + 0.1 (u + wind); reward -x^2; 100 steps."""

    def reset(self, seed=None):
        self.rng = np.random.default_rng(seed)
        self.x, self.v, self.t = self.rng.uniform(-1, 1), 0.0, 0
        return np.array([self.x, self.v]), {}

    def step(self, action):
        u = float(np.clip(action, -2.0, 2.0))
        self.v += 0.1 * (u + self.rng.normal(0.0, 0.5))
        self.x += 0.1 * self.v
        self.t += 1
        return np.array([self.x, self.v]), -self.x ** 2, False, self.t >= 100, {}


def main():
    model = GymModel(WindyCart, check_actions=[0.5] * 20)
    policy = pegasus.LinearPolicy(observation_dim=2, low=[-2.0], high=[2.0])
    problem = pegasus.VectorizedProblem(model, policy, seed=4, scenarios=8, horizon=100)
    options = pegasus.OptimizerOptions("bobyqa")
    options.nlopt.max_evaluations = 30
    theta, summary = pegasus.solve(problem, options)
    print(summary.brief_report())
    assert problem.uhat(theta) == summary.best_value  # the same scenarios, the same episodes
    assert summary.best_value > 0.5 * summary.initial_value


if __name__ == "__main__":
    main()
