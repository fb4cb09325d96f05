"""Your own simulator in numpy, trained by PEGASUS (thesis §4.4): a puck on a line pushed towards the origin.

The model is vectorised over rollouts: every method takes one row per (theta, scenario) pair, and PEGASUS
calls each once per time step for the whole batch. Run: PYTHONPATH=build/python /usr/bin/python3 <this file>
"""
import numpy as np

import pegasus


class Puck:
    """x'' = u + wind, dt = 0.1 s; the wind is uniform in [-0.5, 0.5] m/s^2 each step; reward -x^2 - 0.1 u^2."""

    noise_dim = 1          # uniforms per step (the wind)
    initial_noise_dim = 2  # uniforms for the initial position and velocity

    def initial_state(self, noise):
        return np.column_stack([4.0 * noise[:, 0] - 2.0, noise[:, 1] - 0.5])

    def step(self, states, actions, noise):
        x, v = states[:, 0], states[:, 1]
        v = v + 0.1 * (actions[:, 0] + (noise[:, 0] - 0.5))
        return np.column_stack([x + 0.1 * v, v])

    def reward(self, states, actions, next_states):
        return -next_states[:, 0] ** 2 - 0.1 * actions[:, 0] ** 2


def main():
    policy = pegasus.LinearPolicy(observation_dim=2, low=[-3.0], high=[3.0])  # u = clip(w . [x, v])
    problem = pegasus.VectorizedProblem(Puck(), policy, seed=1, scenarios=20, horizon=100, gamma=0.99)
    options = pegasus.OptimizerOptions("gradient")
    options.gradient.max_iterations = 40
    theta, summary = pegasus.solve(problem, options)
    print(summary.brief_report())
    print("policy:", dict(zip(policy.parameters.names, np.round(theta, 3))))
    assert summary.best_value > 0.5 * summary.initial_value  # rewards are negative: at least halved
    assert theta[0] < 0 and theta[1] < 0                     # push back towards 0, damp the velocity


if __name__ == "__main__":
    main()
