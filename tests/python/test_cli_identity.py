"""The same seed and options give the same bits from Python as from the command line, for any threads."""
import json
import subprocess

import numpy as np
import pytest

import numpy_bicycle
import pegasus

SMALL = ["--scenarios", "8", "--horizon", "150", "--optimizer.gradient.max-iterations", "3", "--rides", "0", "--seed", "3"]


def small_training(threads=1):
    o = pegasus.BicycleTrainingOptions()
    o.scenarios, o.horizon, o.seed, o.threads = 8, 150, 3, threads
    o.optimizer.gradient.max_iterations = 3
    o.optimizer.hill_climbing.max_iterations = 3
    return o


def run_cli(cli, out, *extra):
    result = subprocess.run([cli, "bicycle", "train", *SMALL, *extra, "--quiet", "--out", str(out)],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return json.loads((out / "summary.json").read_text()), json.loads((out / "policy.json").read_text())


def test_bicycle_training_gives_the_cli_figures_bit_for_bit(cli, tmp_path):
    summary_json, policy_json = run_cli(cli, tmp_path / "cli", "--threads", "2")
    theta, summary = pegasus.train_bicycle(small_training(threads=1))
    assert summary.initial_value == summary_json["initial_uhat"]
    assert summary.best_value == summary_json["final_uhat"]
    assert summary.iterations == summary_json["iterations"] == 3
    assert summary.evaluations == summary_json["evaluations"]
    assert summary.termination_type == summary_json["termination"]
    assert summary.message == summary_json["message"]
    names = pegasus.bicycle_policy_parameters().names
    assert [policy_json["parameters"][n] for n in names] == list(theta)
    assert summary.best_value > summary.initial_value
    # The policy file as a controller: the controls of a batch of states.
    read = pegasus.read_bicycle_policy(str(tmp_path / "cli" / "policy.json"))
    assert np.array_equal(read, theta)
    observations = np.random.default_rng(2).normal(scale=0.1, size=(20, 5))
    controls = pegasus.bicycle_controls(read, observations)
    assert controls == pytest.approx(numpy_bicycle.NumpyBicyclePolicy().act(np.tile(read, (20, 1)), observations),
                                     rel=1e-13, abs=1e-15)


def test_a_file_that_is_not_a_policy_is_refused_naming_it(tmp_path):
    bad = tmp_path / "policy.json"
    bad.write_text('{"policy": "bicycle-sigmoid-15", "parameters": {"w.T.omega": "fast"}}')
    with pytest.raises(ValueError, match="policy.json"):
        pegasus.read_bicycle_policy(str(bad))
    with pytest.raises(ValueError, match=r"observations: expected a 2-D array of shape \(any, 5\)"):
        pegasus.bicycle_controls(pegasus.bicycle_balancing_theta(), np.zeros((3, 4)))


def test_threads_never_change_the_result():
    _, one = pegasus.train_bicycle(small_training(threads=1))
    theta3, three = pegasus.train_bicycle(small_training(threads=3))
    same, difference = one.same_outcome(three)
    assert same, difference
    problem = pegasus.BicycleProblem(seed=3, scenarios=8, horizon=150, gamma=0.998, threads=1)
    problem4 = pegasus.BicycleProblem(seed=3, scenarios=8, horizon=150, gamma=0.998, threads=4)
    thetas = theta3 + np.linspace(-0.1, 0.1, 5)[:, None]
    assert np.array_equal(problem.uhat_batch(thetas), problem4.uhat_batch(thetas))


def test_a_resumed_training_ends_as_the_uninterrupted_one():
    options = small_training()
    checkpoints = []
    _, full = pegasus.train_bicycle(options, checkpoint_every=1, on_checkpoint=checkpoints.append)
    assert len(checkpoints) >= 2 and isinstance(checkpoints[0], dict)
    _, resumed = pegasus.train_bicycle(options, checkpoint_every=1, on_checkpoint=lambda c: None,
                                       resume_from=checkpoints[0])
    assert resumed.resumed
    same, difference = full.same_outcome(resumed)
    assert same, difference


@pytest.mark.parametrize("method", ["cmaes", "ars"])
def test_cmaes_and_ars_give_the_cli_figures_bit_for_bit(cli, tmp_path, method):
    flags = ["--optimizer.method", method, f"--optimizer.{method}.max-iterations", "2"]
    if method == "cmaes":
        flags += ["--optimizer.cmaes.population-size", "6"]
    else:
        flags += ["--optimizer.ars.directions", "3", "--optimizer.ars.top-directions", "2"]
    summary_json, policy_json = run_cli(cli, tmp_path / "cli", "--threads", "2", *flags)
    options = small_training(threads=1)
    options.optimizer.method = method
    if method == "cmaes":
        options.optimizer.cmaes.max_iterations, options.optimizer.cmaes.population_size = 2, 6
    else:
        ars = options.optimizer.ars
        ars.max_iterations, ars.directions, ars.top_directions = 2, 3, 2
    checkpoints = []
    theta, summary = pegasus.train_bicycle(options, checkpoint_every=1, on_checkpoint=checkpoints.append)
    assert summary.method == method and summary.iterations == summary_json["iterations"] == 2
    assert summary.best_value == summary_json["final_uhat"] and summary.evaluations == summary_json["evaluations"]
    names = pegasus.bicycle_policy_parameters().names
    assert [policy_json["parameters"][n] for n in names] == list(theta)
    _, resumed = pegasus.train_bicycle(options, resume_from=checkpoints[0])
    assert resumed.same_outcome(summary) == (True, "")
