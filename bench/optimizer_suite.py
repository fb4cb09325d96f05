#!/usr/bin/python3
"""The optimizer suite (issue 48 item 6): every method at its defaults on small problems a user would bring,
through the Python path (numpy models in pegasus.VectorizedProblem), with the same evaluation budget each.

Problems (numpy, vectorised over rollouts; each a PEGASUS problem of fixed scenarios):
  cartpole     balance a cart-pole (Barto et al. 1983 dynamics, dt 0.02 s, force in [-10, 10] N plus a uniform
               disturbance of +-2 N per step), 1 per step until the pole passes 12 degrees or the cart 2.4 m,
               500 steps (10 s); linear policy on (x, x', theta, theta').
  integrator   a double integrator (dt 0.1 s) in a steady wind drawn per scenario (+-1 m/s^2) with gusts
               (+-0.5 m/s^2 per step), reward -x^2 - 0.01 u^2 over 200 steps; linear policy on (x, x', the
               integral of x): the integral term must hold position against the steady wind.
  mountaincar  mountain car with continuous force (Moore 1990, the Gymnasium constants), the velocity
               disturbed by +-0.0005 per step, reward -0.1 u^2 per step and 100 at the goal (x >= 0.45,
               terminal), 400 steps; linear policy on (x + 0.5, 100 x'), u in [-1, 1].

Methods: every name of pegasus.optimizer_methods() that a box of continuous parameters takes (not exhaustive),
each with its default options except the budget: max_evaluations = --budget (max_iterations unbounded), and
for the NLopt methods their evaluation limit. Seeds 1..--seeds are the problems' scenario seeds, so each seed is
another sample of the problem.

Prints a Markdown table: mean over the seeds of the best U-hat found, and each method's worst shortfall from the
best method on a seed, relative to the best's magnitude ("gap"); and which methods are within 2% everywhere.
Usage: PYTHONPATH=build/python /usr/bin/python3 bench/optimizer_suite.py [--budget 3000] [--seeds 3] [--out F]
"""
import argparse
import json
import time

import numpy as np

import pegasus


class CartPole:
    noise_dim = 1
    initial_noise_dim = 4
    gravity, cart_mass, pole_mass, half_length, dt = 9.8, 1.0, 0.1, 0.5, 0.02

    def initial_state(self, noise):
        return 0.1 * (noise - 0.5)  # each of x, x', theta, theta' uniform in [-0.05, 0.05]

    def step(self, s, a, noise):
        x, v, th, w = s[:, 0], s[:, 1], s[:, 2], s[:, 3]
        force = np.clip(a[:, 0], -10.0, 10.0) + 4.0 * (noise[:, 0] - 0.5)
        total = self.cart_mass + self.pole_mass
        cos, sin = np.cos(th), np.sin(th)
        temp = (force + self.pole_mass * self.half_length * w * w * sin) / total
        alpha = (self.gravity * sin - cos * temp) / (
            self.half_length * (4.0 / 3.0 - self.pole_mass * cos * cos / total))
        acc = temp - self.pole_mass * self.half_length * alpha * cos / total
        return np.column_stack([x + self.dt * v, v + self.dt * acc, th + self.dt * w, w + self.dt * alpha])

    def terminal(self, s):
        return (np.abs(s[:, 0]) > 2.4) | (np.abs(s[:, 2]) > 12.0 * np.pi / 180.0)

    def reward(self, s, a, s_next):
        return np.where(self.terminal(s_next), 0.0, 1.0)


class WindyIntegrator:
    noise_dim = 1
    initial_noise_dim = 3  # position, velocity, steady wind
    dt = 0.1

    def initial_state(self, noise):
        return np.column_stack([2.0 * noise[:, 0] - 1.0, noise[:, 1] - 0.5, np.zeros(len(noise)),
                                2.0 * noise[:, 2] - 1.0])

    def step(self, s, a, noise):
        x, v, integral, wind = s[:, 0], s[:, 1], s[:, 2], s[:, 3]
        v = v + self.dt * (np.clip(a[:, 0], -5.0, 5.0) + wind + (noise[:, 0] - 0.5))
        x = x + self.dt * v
        return np.column_stack([x, v, integral + self.dt * x, wind])

    def observe(self, s):
        return s[:, :3]  # the wind is not measured

    def reward(self, s, a, s_next):
        return -s_next[:, 0] ** 2 - 0.01 * a[:, 0] ** 2


class NoisyMountainCar:
    noise_dim = 1
    initial_noise_dim = 1

    def initial_state(self, noise):
        return np.column_stack([-0.6 + 0.2 * noise[:, 0], np.zeros(len(noise))])

    def step(self, s, a, noise):
        x, v = s[:, 0], s[:, 1]
        u = np.clip(a[:, 0], -1.0, 1.0)
        v = np.clip(v + 0.0015 * u - 0.0025 * np.cos(3.0 * x) + 0.001 * (noise[:, 0] - 0.5), -0.07, 0.07)
        x = np.clip(x + v, -1.2, 0.6)
        v = np.where((x <= -1.2) & (v < 0), 0.0, v)
        return np.column_stack([x, v])

    def observe(self, s):
        return np.column_stack([s[:, 0] + 0.5, 100.0 * s[:, 1]])

    def terminal(self, s):
        return s[:, 0] >= 0.45

    def reward(self, s, a, s_next):
        return -0.1 * np.clip(a[:, 0], -1.0, 1.0) ** 2 + np.where(self.terminal(s_next), 100.0, 0.0)


PROBLEMS = {
    # name: (model, observation_dim, action box, scenarios, horizon, gamma)
    "cartpole": (CartPole, 4, ([-10.0], [10.0]), 20, 500, 1.0),
    "integrator": (WindyIntegrator, 3, ([-5.0], [5.0]), 20, 200, 1.0),
    "mountaincar": (NoisyMountainCar, 2, ([-1.0], [1.0]), 20, 400, 1.0),
}
NLOPT = ("bobyqa", "sbplx", "crs2", "esch")


SECTIONS = {"gradient": "gradient", "hill-climb": "hill_climbing", "cmaes": "cmaes", "ars": "ars"}


def options_for(method, budget):
    """The method's default options, allowed `budget` evaluations."""
    options = pegasus.OptimizerOptions(method)
    if method in NLOPT:
        options.nlopt.max_evaluations = budget
    else:
        section = getattr(options, SECTIONS[method])
        section.max_evaluations = budget
        section.max_iterations = 10**9
    return options


def run(problem_name, method, budget, seed):
    model, obs_dim, (low, high), scenarios, horizon, gamma = PROBLEMS[problem_name]
    policy = pegasus.LinearPolicy(observation_dim=obs_dim, low=low, high=high)
    problem = pegasus.VectorizedProblem(model(), policy, seed=seed, scenarios=scenarios, horizon=horizon,
                                        gamma=gamma)
    start = time.perf_counter()
    try:
        _, summary = pegasus.solve(problem, options_for(method, budget))
    except ValueError as e:  # crs2 and esch need finite bounds on every parameter
        print(f"{problem_name} {method}: {e}")
        return None
    return {"problem": problem_name, "method": method, "seed": seed, "best": summary.best_value,
            "evaluations": summary.evaluations, "seconds": time.perf_counter() - start}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--budget", type=int, default=3000)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--problems", default=",".join(PROBLEMS))
    parser.add_argument("--methods", default="")
    parser.add_argument("--out", default="")
    args = parser.parse_args()
    methods = args.methods.split(",") if args.methods else [
        m for m in pegasus.optimizer_methods() if m != "exhaustive"]
    problems = args.problems.split(",")
    results = [run(p, m, args.budget, s) for p in problems for m in methods for s in range(1, args.seeds + 1)]
    results = [r for r in results if r is not None]
    methods = [m for m in methods if any(r["method"] == m for r in results)]
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)
    default_method = pegasus.OptimizerOptions().method
    print(f"budget {args.budget} evaluations, seeds 1..{args.seeds}; OptimizerOptions() runs '{default_method}'\n")
    print("| problem | " + " | ".join(methods) + " |")
    print("|---|" + "---:|" * len(methods))
    worst_gap = {m: 0.0 for m in methods}
    for p in problems:
        cells = []
        for m in methods:
            gaps = []
            for s in range(1, args.seeds + 1):
                best = max(r["best"] for r in results if r["problem"] == p and r["seed"] == s)
                mine = next((r["best"] for r in results if r["problem"] == p and r["seed"] == s and r["method"] == m),
                            -np.inf)
                gaps.append((best - mine) / max(abs(best), 1e-12))
            worst_gap[m] = max(worst_gap[m], max(gaps))
            mean = np.mean([r["best"] for r in results if r["problem"] == p and r["method"] == m])
            cells.append(f"{mean:.4g} (gap {100 * max(gaps):.1f}%)")
        print(f"| {p} | " + " | ".join(cells) + " |")
    within = [m for m in methods if worst_gap[m] <= 0.02]
    print(f"\nwithin 2% of the best on every problem and seed: {', '.join(within) or 'none'}")


if __name__ == "__main__":
    main()
