#!/usr/bin/python3
"""The helicopter from Python (thesis ch. 5): the ground-truth aircraft as a batch model, a two-stage training plan
(gradient ascent, then CMA-ES from its result) of the hover controller on it, and the result saved as a policy
file that serves controls for a batch of states, as `pegasus heli control` does.

Usage: PYTHONPATH=build/python /usr/bin/python3 examples/python/helicopter.py [OUT_DIR]"""
import pathlib
import sys
import tempfile

import numpy as np

import pegasus

aircraft = pegasus.Aircraft()
trim = aircraft.hover_trim
init = pegasus.HoverPolicyInit()
init.trim, init.trim_roll, init.trim_pitch = trim["controls"], trim["roll"], trim["pitch"]

# U-hat of the hover policy class (34 weights) on 8 scenarios of 3 s with gusts, from perturbed starts.
params = pegasus.AircraftParams()
params.start_pos_sigma, params.start_vel_sigma = 1.0, 0.3
problem = pegasus.HoverProblem(pegasus.Aircraft(params), init=init, seed=1, scenarios=8, horizon=150, threads=2)

gradient = pegasus.OptimizerOptions("gradient")
gradient.gradient.max_iterations, gradient.gradient.relative_step, gradient.gradient.initial_step = 3, 0.05, 1.0
cmaes = pegasus.OptimizerOptions("cmaes")
cmaes.cmaes.max_iterations, cmaes.cmaes.population_size = 4, 8
plan = pegasus.TrainingPlan(seed=1, stages=[pegasus.TrainingStage("gradient", gradient),
                                            pegasus.TrainingStage("refine", cmaes, seeds=pegasus.REFINE_SEED_DOMAINS)])
theta, summary = pegasus.train(plan, problem)
print(summary.brief_report())
assert summary.best_value > summary.initial_value

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp())
policy = pegasus.HeliPolicy.hover(theta, pegasus.SetPoint(0, 0, -10, 0), init.trim, init)
policy.save(str(out / "policy.json"))
controller = pegasus.HeliPolicy.load(str(out / "policy.json"))

# Twenty flights of 10 s on the ground truth under the saved controller: none crashes.
scenarios = pegasus.ScenarioSet(7, 20, 500, aircraft.noise_dim, aircraft.initial_noise_dim)
flights = pegasus.Aircraft(params).simulate(scenarios.initial_noise(), scenarios.step_noise(), policy=controller,
                                            threads=2)
error = flights["observations"][:, :, :3] - np.array([0.0, 0.0, -10.0])
rms = float(np.sqrt(np.mean(np.sum(error[:, 100:] ** 2, axis=2))))
print(f"policy.json in {out}; 20 flights of 10 s: {np.count_nonzero(flights['crash_step'] >= 0)} crashes, "
      f"RMS position error after 2 s {rms:.3f} m")
assert np.all(flights["crash_step"] == -1) and rms < 2.0
# The controls of a batch of states, as `pegasus heli control --policy policy.json` answers them line by line.
print(controller.controls(flights["observations"][:3, -1]))
