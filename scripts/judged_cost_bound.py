#!/usr/bin/python3
"""A lower bound on the judged cost of ANY controller flown by `pegasus fly` from its random starts.

Each world axis is a double integrator whose acceleration is bounded by what the aircraft can reach (given
generously: no attitude or rotor lag, no estimate error, the attitude and rate terms of accelerating left
out). Per start drawn as `fly` draws them (position N(0, start_pos_sigma), velocity N(0, start_vel_sigma) per
axis), the accelerations that minimise the vehicle file's position and velocity terms, summed over the
control steps as `fly` sums them (from the start's own step), are found by a box-constrained convex
minimisation; the mean over the starts is the bound (`--flights`: exactly the starts of a `fly` run's
flights.csv, as `fly --compare-baseline` flew both controllers from them). No controller of the aircraft can score below it, so a
bar "k times better than a baseline" is out of reach when the baseline's judged cost / k is below it.

Usage: judged_cost_bound.py --vehicle V.toml [--accel A] [--accel-vertical A] [--start-pos-sigma S]
                            [--start-vel-sigma S] [--samples N] [--seconds T] [--seed K]
                            [--flights RUN/flights.csv]
"""
import argparse
import sys
import tomllib

import numpy as np
from scipy.optimize import minimize


def axis_matrices(dt, steps):
    """e = e0 + v0 t + P a and v = v0 + V a for accelerations a held over each step."""
    k = np.arange(steps + 1)[:, None]
    j = np.arange(steps)[None, :]
    before = j < k
    position = np.where(before, dt * dt / 2 + (k - 1 - j) * dt * dt, 0.0)
    velocity = np.where(before, dt, 0.0)
    return position, velocity


def axis_cost(e0, v0, accel, w_pos, w_vel, dt, position, velocity):
    t = np.arange(position.shape[0]) * dt
    free_e, free_v = e0 + v0 * t, np.full_like(t, v0)

    def cost(a):
        e, v = free_e + position @ a, free_v + velocity @ a
        return w_pos * (e @ e) + w_vel * (v @ v)

    def gradient(a):
        e, v = free_e + position @ a, free_v + velocity @ a
        return 2 * w_pos * (position.T @ e) + 2 * w_vel * (velocity.T @ v)

    steps = position.shape[1]
    result = minimize(cost, np.zeros(steps), jac=gradient, bounds=[(-accel, accel)] * steps, method="L-BFGS-B",
                      options={"maxiter": 5000, "ftol": 1e-13, "gtol": 1e-10})
    return result.fun


def read_starts(path):
    """Per axis, the errors from the set point and the velocities at t = 0 of each flight of flights.csv."""
    rows = np.genfromtxt(path, delimiter=",", names=True)
    first = rows[rows["t"] == 0]
    return [(first[p] - first["target_" + p], first[v]) for p, v in (("x", "xdot"), ("y", "ydot"), ("z", "zdot"))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vehicle", required=True, help="vehicle file with a [cost] section")
    parser.add_argument("--accel", type=float, default=9.81, help="horizontal acceleration bound, m/s^2")
    parser.add_argument("--accel-vertical", type=float, default=19.62, help="vertical acceleration bound, m/s^2")
    parser.add_argument("--start-pos-sigma", type=float, default=1.0, help="fly's --start-pos-sigma, m")
    parser.add_argument("--start-vel-sigma", type=float, default=0.3, help="fly's --start-vel-sigma, m/s")
    parser.add_argument("--samples", type=int, default=400, help="starts drawn per axis")
    parser.add_argument("--seconds", type=float, default=8.0,
                        help="steps optimised (the rest of the flight adds its cost >= 0 to the bound)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--flights", help="a fly run's flights.csv: its flights' own starts instead of draws")
    args = parser.parse_args()
    try:
        with open(args.vehicle, "rb") as f:
            vehicle = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError) as e:
        print(f"{args.vehicle}: {e}", file=sys.stderr)
        return 2
    cost = vehicle.get("cost")
    rate = vehicle.get("control", {}).get("rate_hz")
    if cost is None or rate is None:
        print(f"{args.vehicle}: expected a [cost] section and [control] rate_hz", file=sys.stderr)
        return 2
    dt = 1.0 / rate
    steps = int(round(args.seconds / dt))
    position, velocity = axis_matrices(dt, steps)
    w_pos = cost.get("position", [0, 0, 0])
    w_vel = cost.get("velocity", [0, 0, 0])
    starts = read_starts(args.flights) if args.flights else None
    rng = np.random.default_rng(args.seed)
    total = 0.0
    for axis in range(3):
        accel = args.accel if axis < 2 else args.accel_vertical
        if starts is not None:
            e0, v0 = starts[axis]
        else:
            e0 = rng.normal(0, args.start_pos_sigma, args.samples)
            v0 = rng.normal(0, args.start_vel_sigma, args.samples)
        costs = [axis_cost(e, v, accel, w_pos[axis], w_vel[axis], dt, position, velocity) for e, v in zip(e0, v0)]
        mean = float(np.mean(costs))
        spread = "" if starts is not None else f" (standard error {np.std(costs) / np.sqrt(len(costs)):.2f})"
        print(f"axis {axis + 1}: {mean:.2f}{spread} over {len(costs)} starts, |acceleration| <= {accel:g} m/s^2")
        total += mean
    print(f"position and velocity terms per flight, any controller: >= {total:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
