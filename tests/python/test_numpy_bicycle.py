"""A bicycle written in numpy (the equations of src/envs/bicycle.cpp), trained by PEGASUS through
pegasus.VectorizedProblem, rides to the goal (thesis §4.6)."""
import numpy as np
import pytest

import pegasus

from numpy_bicycle import NumpyBicycle, NumpyBicyclePolicy

GAMMA = 0.998


def training_options(iterations):
    # The bicycle experiment's bounded-step gradient ascent (BicycleTrainingOptions::default_optimizer).
    o = pegasus.OptimizerOptions("gradient")
    g = o.gradient
    g.max_iterations, g.relative_step, g.initial_step, g.max_step, g.min_step = iterations, 0.05, 0.2, 0.5, 1e-3
    g.function_tolerance = 0.0
    return o


def reached_fraction(theta, goal, rides=24, steps=2000):
    """Rides from the initial-state distribution on fresh scenarios: the return is 1 on entering the goal."""
    model = NumpyBicycle(goal=goal, goal_reward=1.0, fall_reward=0.0)
    problem = pegasus.VectorizedProblem(model, NumpyBicyclePolicy(), seed=2024, scenarios=rides, horizon=steps)
    return problem.uhat(theta)


def test_numpy_bicycle_trained_by_pegasus_rides_to_the_goal():
    # Training as §4.6: the goal infinitely far east, potential shaping for progress towards it (Eq 3.1).
    model = NumpyBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=GAMMA)
    problem = pegasus.VectorizedProblem(model, NumpyBicyclePolicy(), seed=1, scenarios=12, horizon=300, gamma=GAMMA)
    start = pegasus.bicycle_balancing_theta()
    theta, summary = pegasus.solve(problem, training_options(12), theta=start)
    assert summary.best_value > summary.initial_value + 1.0
    # numpy 1.24's sin, arctan, ... may round the last bit differently with the memory layout of their arrays
    # (a SIMD or a scalar loop), so a numpy model reproduces U-hat to the last bits, not always bit for bit.
    assert problem.uhat(theta) == pytest.approx(summary.best_value, rel=1e-12)

    goal = (30.0, 0.0, 5.0)  # a circle 30 m east of the start, 5 m radius
    before, after = reached_fraction(start, goal), reached_fraction(theta, goal)
    assert after >= 0.75, (before, after)
    assert before <= 0.25, (before, after)
