"""scripts/judged_cost_bound.py: its per-axis minimum is a true lower bound and the exact optimum where one is known."""
import importlib.util
import pathlib

import numpy as np
import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "judged_cost_bound.py"
spec = importlib.util.spec_from_file_location("judged_cost_bound", SCRIPT)
bound = importlib.util.module_from_spec(spec)
spec.loader.exec_module(bound)

DT, STEPS = 0.1, 60


def simulate(e0, v0, gains, accel, w_pos, w_vel):
    """The cost, summed as the bound sums it, of a saturated PD on the double integrator the bound models."""
    e, v, cost = e0, v0, 0.0
    for _ in range(STEPS):
        cost += w_pos * e * e + w_vel * v * v
        a = float(np.clip(-gains[0] * e - gains[1] * v, -accel, accel))
        e, v = e + v * DT + a * DT * DT / 2, v + a * DT
    return cost + w_pos * e * e + w_vel * v * v


def test_no_controller_scores_below_the_bound():
    position, velocity = bound.axis_matrices(DT, STEPS)
    rng = np.random.default_rng(3)
    for e0, v0 in rng.normal(0, [1.0, 0.3], size=(5, 2)):
        least = bound.axis_cost(e0, v0, 3.0, 1.0, 0.5, DT, position, velocity)
        for gains in [(1, 1), (3, 2), (10, 5), (30, 10)]:
            assert simulate(e0, v0, gains, 3.0, 1.0, 0.5) >= least - 1e-9


def test_unbounded_it_is_the_discrete_lqr_cost():
    # Without the acceleration bound, the minimum of the quadratic cost is the Riccati recursion's x0' P0 x0.
    a = np.array([[1, DT], [0, 1]])
    b = np.array([[DT * DT / 2], [DT]])
    q = np.diag([1.0, 0.5])
    p = q.copy()
    for _ in range(STEPS):
        k = np.linalg.solve(b.T @ p @ b + 1e-12, b.T @ p @ a)
        p = q + a.T @ p @ (a - b @ k)
    x0 = np.array([0.8, -0.2])
    position, velocity = bound.axis_matrices(DT, STEPS)
    least = bound.axis_cost(x0[0], x0[1], 1e6, 1.0, 0.5, DT, position, velocity)
    assert least == pytest.approx(float(x0 @ p @ x0), rel=1e-5)


def test_a_start_on_the_set_point_costs_nothing():
    position, velocity = bound.axis_matrices(DT, STEPS)
    assert bound.axis_cost(0.0, 0.0, 3.0, 1.0, 0.5, DT, position, velocity) == pytest.approx(0.0, abs=1e-12)
