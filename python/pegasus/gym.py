"""Gymnasium-style environments as deterministic simulative models (thesis §4.2.1).

An environment with reset(seed=...) -> (observation, info) and step(action) -> (observation, reward,
terminated, truncated, info) becomes a model for pegasus.VectorizedProblem by giving each scenario its own
seed, drawn from the scenario's initial uniform (the project's counter RNG): scenario i is then the same
episode every time it is rolled out, which is what PEGASUS needs (§4.3).

The condition: all of the environment's randomness comes from the generator reset(seed=...) seeds. GymModel
checks it when it is made, by playing one seeded episode twice with the same actions and refusing (ValueError)
an environment whose replay differs."""
import numpy as np


def _flat(observation):
    return np.asarray(observation, dtype=float).reshape(-1)


class GymModel:
    """A vectorised model over Gymnasium-style environments made by make_env(); one environment per live
    rollout, stepped in a Python loop (the environment itself is not vectorised). A state row is
    [slot, terminated, reward, observation...]; `check_actions` are played to verify determinism."""

    noise_dim = 0
    initial_noise_dim = 1

    def __init__(self, make_env, check_actions, check_seed=12345):
        if not callable(make_env):
            raise ValueError("make_env: expected a callable returning an environment")
        check_actions = list(check_actions)
        if not check_actions:
            raise ValueError("check_actions: expected at least one action to play (the environment's "
                             "determinism given its seed is checked by replaying them)")
        self.make_env = make_env
        self._envs = []
        first = self._episode(check_seed, check_actions)
        second = self._episode(check_seed, check_actions)
        for t, (x, y) in enumerate(zip(first, second)):
            if not (np.array_equal(x[0], y[0]) and x[1:] == y[1:]):
                raise ValueError(f"make_env: the environment is not deterministic given its seed: the replay of "
                                 f"seed {check_seed} differs at step {t}")
        self.observation_dim = first[0][0].size

    def _episode(self, seed, actions):
        env = self.make_env()
        observation, _ = env.reset(seed=seed)
        out = [(_flat(observation), 0.0, False)]
        for action in actions:
            observation, reward, terminated, truncated, _ = env.step(action)
            out.append((_flat(observation), float(reward), bool(terminated or truncated)))
            if terminated or truncated:
                break
        return out

    @staticmethod
    def scenario_seed(uniform):
        """The environment seed of a scenario: 53 bits of its initial uniform."""
        return int(uniform * 2.0 ** 53)

    def initial_state(self, noise):
        n = noise.shape[0]
        while len(self._envs) < n:
            self._envs.append(self.make_env())
        states = np.zeros((n, 3 + self.observation_dim))
        for i in range(n):
            observation, _ = self._envs[i].reset(seed=self.scenario_seed(noise[i, 0]))
            states[i, 0] = i
            states[i, 3:] = _flat(observation)
        return states

    def step(self, states, actions, noise):
        out = np.empty_like(states)
        for j in range(states.shape[0]):
            slot = int(states[j, 0])
            action = actions[j] if actions.shape[1] > 1 else actions[j, 0]
            observation, reward, terminated, truncated, _ = self._envs[slot].step(action)
            out[j, 0], out[j, 1], out[j, 2] = slot, float(terminated or truncated), reward
            out[j, 3:] = _flat(observation)
        return out

    def reward(self, states, actions, next_states):
        return next_states[:, 2]

    def terminal(self, states):
        return states[:, 1] != 0.0

    def observe(self, states):
        return states[:, 3:]
