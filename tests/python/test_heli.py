"""The helicopter from Python: the ground truth (Aircraft) and the identified model (LearnedHeliModel) as batch
models, U-hat of the hover policy on them (HoverProblem), `pegasus heli hover`'s training (train_hover), and policy
files (HeliPolicy) serving controls for a batch of states, bit for bit as the CLI."""
import json
import re
import subprocess

import numpy as np
import pytest

import pegasus

IDENTIFY = ["--cv-points", "60", "--scale-grid", "1,4", "--coordinate-passes", "0", "--horizon-s", "2",
            "--start-spacing-s", "5", "--variants=false", "--quiet"]


@pytest.fixture(scope="module")
def model_json(tmp_path_factory, cli):
    """A model identified by the CLI from the scripted pilot's logs (small settings)."""
    root = tmp_path_factory.mktemp("heli")
    for name, seconds, seed in [("train", "40", "3"), ("test", "20", "4")]:
        result = subprocess.run([cli, "heli", "pilot", "--hover-seconds", "4", "--quiet", "--seconds", seconds,
                                 "--seed", seed, "--out", str(root / name)], capture_output=True, text=True)
        assert result.returncode == 0, result.stdout + result.stderr
    result = subprocess.run([cli, "heli", "identify", "--train", str(root / "train" / "log.csv"), "--test",
                             str(root / "test" / "log.csv"), *IDENTIFY, "--out", str(root / "identify")],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    return root / "identify" / "model.json"


def trimmed_init(aircraft):
    init = pegasus.HoverPolicyInit()
    trim = aircraft.hover_trim
    init.trim, init.trim_roll, init.trim_pitch = trim["controls"], trim["roll"], trim["pitch"]
    return init


# ---- Ground truth -----------------------------------------------------------------------------------------------

def test_the_aircraft_hovers_at_its_trim_and_steps_deterministically_on_any_threads():
    params = pegasus.AircraftParams()
    params.gust_sigma = 0.0
    params.est_sigma_pos = params.est_sigma_vel = params.est_sigma_angle = params.est_sigma_rate = 0.0
    aircraft = pegasus.Aircraft(params)
    assert len(pegasus.Aircraft.STATE_COLUMNS) == 36 and aircraft.noise_dim == 15 and aircraft.initial_noise_dim == 21
    assert aircraft.hover_trim["residual"] < 1e-9
    s = aircraft.initial_state(np.full((3, 21), 0.5))
    assert np.array_equal(aircraft.observe(s)[:, :3], np.tile([0.0, 0.0, -10.0], (3, 1)))
    trim = np.tile(aircraft.hover_trim["controls"], (3, 1))
    for _ in range(50):  # one second at the trim, no wind: it stays where it is
        s = aircraft.step(s, trim, np.full((3, 15), 0.5))
    assert np.abs(aircraft.true_state(s)[:, :3] - [0.0, 0.0, -10.0]).max() < 1e-6
    assert not aircraft.terminal(s).any() and aircraft.crash_reason(s) == ["none"] * 3

    gusty = pegasus.Aircraft()
    scenarios = pegasus.ScenarioSet(7, 16, 40, gusty.noise_dim, gusty.initial_noise_dim)
    s0 = gusty.initial_state(scenarios.initial_noise())
    rng = np.random.default_rng(1)
    a = np.clip(trim[:1] + 0.05 * rng.normal(size=(16, 4)), -1, 1)
    one = gusty.step(s0, a, scenarios.step_noise()[:, 0], threads=1)
    assert np.array_equal(one, gusty.step(s0, a, scenarios.step_noise()[:, 0], threads=3))
    assert np.array_equal(one, gusty.step(s0.copy(), a, scenarios.step_noise()[:, 0]))
    # Open-loop simulate is the same steps, bit for bit; the estimate error stays within a few sigma.
    actions = np.repeat(a[:, None, :], 40, axis=1)
    flight = gusty.simulate(scenarios.initial_noise(), scenarios.step_noise(), actions=actions, threads=2)
    s = s0
    for t in range(40):
        s = gusty.step(s, a, scenarios.step_noise()[:, t])
        assert np.array_equal(flight["observations"][:, t + 1], gusty.observe(s))
    assert np.array_equal(flight["actions"], actions) and np.all(flight["rewards"] == 0.0)
    assert np.abs(gusty.observe(s)[:, :3] - gusty.true_state(s)[:, :3]).max() < 6 * gusty.params.est_sigma_pos


def test_hover_uhat_on_the_ground_truth_is_bit_identical_for_any_threads():
    aircraft = pegasus.Aircraft()
    init = trimmed_init(aircraft)
    theta = pegasus.HoverPolicy(init).parameters.initial
    problems = [pegasus.HoverProblem(aircraft, init=init, seed=3, scenarios=6, horizon=150, threads=t)
                for t in (1, 3)]
    values = [p.uhat(theta) for p in problems]
    assert values[0] == values[1] and np.isfinite(values[0]) and values[0] < 0.0
    returns = problems[0].returns(theta)
    assert np.array_equal(returns, problems[1].returns(theta))
    assert sum(returns) / 6 == values[0]  # U-hat is the mean of the returns, summed in scenario order
    batch = problems[1].uhat_batch(np.stack([theta, 1.1 * theta]))
    assert batch[0] == values[0] and batch[1] != values[0]
    # A hover policy file of the same weights flies the same controls as the policy class.
    flight = aircraft.simulate(pegasus.ScenarioSet(3, 6, 150, 15, 21).initial_noise(),
                               pegasus.ScenarioSet(3, 6, 150, 15, 21).step_noise(),
                               policy=pegasus.HeliPolicy.hover(theta, pegasus.SetPoint(), init.trim, init))
    assert np.all(flight["crash_step"] == -1)  # the linear starting controller holds the hover
    states = flight["observations"][:, 10]
    assert np.array_equal(flight["actions"][:, 10], pegasus.HoverPolicy(init).act(theta, states))


def calm_quadrotor(wind=(0.0, 0.0, 0.0)):
    params = pegasus.QuadrotorParams()
    params.gust_sigma = 0.0
    params.est_sigma_pos = params.est_sigma_vel = params.est_sigma_angle = params.est_sigma_rate = 0.0
    params.mean_wind_W = list(wind)
    return pegasus.Quadrotor(params)


def test_the_quadrotor_is_a_batch_model_like_the_helicopter():
    quad = calm_quadrotor()
    assert len(pegasus.Quadrotor.STATE_COLUMNS) == 33 and quad.noise_dim == 15 and quad.initial_noise_dim == 21
    assert pegasus.Quadrotor.STATE_COLUMNS[12] == "rotor_speed.1" and pegasus.Quadrotor.STATE_COLUMNS[-1] == "crash"
    s = quad.initial_state(np.full((3, 21), 0.5))
    assert np.array_equal(quad.observe(s)[:, :3], np.tile([0.0, 0.0, -2.0], (3, 1)))
    assert np.all(s[:, 12:16] == quad.hover_rotor_speed)
    trim = np.tile(quad.hover_trim["controls"], (3, 1))
    for _ in range(50):  # one second at the trim, no wind: it stays where it is
        s = quad.step(s, trim, np.full((3, 15), 0.5))
    assert np.abs(quad.true_state(s)[:, :3] - [0.0, 0.0, -2.0]).max() < 1e-9
    assert not quad.terminal(s).any() and quad.crash_reason(s) == ["none"] * 3
    # Zero thrust (a3 = -1) falls to the ground: a crash.
    down = quad.initial_state(np.full((1, 21), 0.5))
    for _ in range(150):
        down = quad.step(down, [[0.0, 0.0, -1.0, 0.0]], np.full((1, 15), 0.5))
    assert quad.terminal(down)[0] and quad.crash_reason(down) == ["ground impact"]
    bad = s.copy()
    bad[0, 32] = 0.5
    with pytest.raises(ValueError, match="states: expected a crash code in 0..[0-9]+ in column 32"):
        quad.observe(bad)

    gusty = pegasus.Quadrotor()
    scenarios = pegasus.ScenarioSet(7, 8, 30, gusty.noise_dim, gusty.initial_noise_dim)
    s0 = gusty.initial_state(scenarios.initial_noise())
    a = np.clip(trim[:1] + 0.05 * np.random.default_rng(1).normal(size=(8, 4)), -1, 1)
    one = gusty.step(s0, a, scenarios.step_noise()[:, 0], threads=1)
    assert np.array_equal(one, gusty.step(s0, a, scenarios.step_noise()[:, 0], threads=3))
    flight = gusty.simulate(scenarios.initial_noise(), scenarios.step_noise(),
                            actions=np.repeat(a[:, None, :], 30, axis=1), threads=2)
    s = s0
    for t in range(30):
        s = gusty.step(s, a, scenarios.step_noise()[:, t])
        assert np.array_equal(flight["observations"][:, t + 1], gusty.observe(s))


def test_on_the_quadrotor_the_integral_term_removes_the_steady_offset_of_a_steady_wind():
    quad = calm_quadrotor(wind=(1.0, 0.5, 0.0))
    scenarios = pegasus.ScenarioSet(1, 2, 3000, 15, 21)
    offsets = []
    for integral_seconds in (0, 5):
        init = pegasus.HoverPolicyInit()
        init.trim, init.integral_seconds = quad.hover_trim["controls"], integral_seconds
        policy = pegasus.HeliPolicy.hover(pegasus.HoverPolicy(init).parameters.initial, pegasus.SetPoint(0, 0, -2, 0),
                                          init.trim, init)
        flight = quad.simulate(scenarios.initial_noise(), scenarios.step_noise(), policy=policy, threads=2)
        assert np.all(flight["crash_step"] == -1)
        offsets.append(np.linalg.norm(flight["observations"][:, -500:, :3] - [0, 0, -2], axis=2).mean())
        # The ground truth's hover U-hat takes the quadrotor too, bit for bit on any threads.
        problems = [pegasus.HoverProblem(quad, target=pegasus.SetPoint(0, 0, -2, 0), init=init, seed=3, scenarios=2,
                                         horizon=100, threads=t) for t in (1, 2)]
        theta = pegasus.HoverPolicy(init).parameters.initial
        assert problems[0].uhat(theta) == problems[1].uhat(theta)
    assert offsets[0] > 2.0 and offsets[1] < 0.2  # 60 s in a 1.1 m/s wind, the last 10 s


# ---- Identified model -------------------------------------------------------------------------------------------

def test_the_learned_model_from_a_path_or_an_object_steps_alike(model_json):
    identified = pegasus.IdentifiedModel.load(str(model_json))
    options = pegasus.LearnedModelOptions()
    options.start_pos_sigma = 0.5
    a, b = pegasus.LearnedHeliModel(identified, options), pegasus.LearnedHeliModel(str(model_json), options)
    columns = pegasus.LearnedHeliModel.STATE_COLUMNS
    assert len(columns) == 161 and a.noise_dim == 8 and a.initial_noise_dim == 6
    assert columns[-10:-2] == ["colored." + v for v in ("roll", "pitch", "xdot_b", "ydot_b", "zdot_b", "roll_rate",
                                                        "pitch_rate", "yaw_rate")]
    scenarios = pegasus.ScenarioSet(2, 8, 100, 8, 6)
    init = pegasus.hover_init_from_model(identified)
    theta = pegasus.HoverPolicy(init).parameters.initial
    policy = pegasus.HeliPolicy.hover(theta, pegasus.SetPoint(), init.trim, init)
    fa = a.simulate(scenarios.initial_noise(), scenarios.step_noise(), policy=policy, threads=1)
    fb = b.simulate(scenarios.initial_noise(), scenarios.step_noise(), policy=policy, threads=4)
    for key in ("observations", "actions", "rewards", "crash_step"):
        assert np.array_equal(fa[key], fb[key]), key
    # Stepping row by row gives the simulated flight.
    s = a.initial_state(scenarios.initial_noise())
    assert np.array_equal(a.observe(s), fa["observations"][:, 0])
    for t in range(100):
        nxt = a.step(s, fa["actions"][:, t], scenarios.step_noise()[:, t])
        assert np.array_equal(a.reward(s, fa["actions"][:, t], nxt), fa["rewards"][:, t])
        s = nxt
    assert np.array_equal(a.observe(s), fa["observations"][:, -1])
    assert np.abs(fa["observations"][:, -1, 2] + 10.0).max() < 5.0  # still near the set point's height


def test_hover_problem_on_the_learned_model_is_the_cli_objective(model_json):
    identified = pegasus.IdentifiedModel.load(str(model_json))
    options = pegasus.HoverTrainingOptions()
    options.scenarios, options.seconds = 4, 2.0
    exact = pegasus.HoverProblem.from_training_options(str(model_json), options, threads=2)
    learned = pegasus.LearnedModelOptions()
    learned.refit_every = options.refit_steps(identified)
    assert learned.refit_every == 5  # 50 Hz steps from a 10 Hz model (§5.2.2)
    learned.start = [0, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    learned.start_pos_sigma, learned.start_vel_sigma = options.start_pos_sigma, options.start_vel_sigma
    ours = pegasus.HoverProblem(pegasus.LearnedHeliModel(identified, learned), target=options.target,
                                reward=pegasus.hover_reward_for(identified, options),
                                init=pegasus.hover_init_from_model(identified), seed=options.seed,
                                scenarios=4, horizon=options.horizon(), gamma=options.gamma, threads=1)
    theta = ours.parameters.initial
    assert exact.uhat(theta) == ours.uhat(theta)
    assert np.array_equal(exact.returns(theta), ours.returns(theta))


def test_hover_at_another_control_rate_steps_the_learned_model_at_it(model_json):
    identified = pegasus.IdentifiedModel.load(str(model_json))
    options = pegasus.HoverTrainingOptions()
    options.scenarios, options.seconds, options.control_rate_hz = 4, 2.0, 10.0
    # 10 Hz steps from a 10 Hz model refit every step, 2 s are 20 steps, and the discount per step keeps the
    # thesis's 0.9995 per 1/50 s.
    assert options.refit_steps(identified) == 1 and options.horizon() == 20
    assert options.gamma_per_step() == pytest.approx(0.9995 ** 5, rel=1e-15)
    exact = pegasus.HoverProblem.from_training_options(str(model_json), options, threads=2)
    learned = pegasus.LearnedModelOptions()
    learned.dt, learned.refit_every = 0.1, 1
    learned.start = [0, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    learned.start_pos_sigma, learned.start_vel_sigma = options.start_pos_sigma, options.start_vel_sigma
    ours = pegasus.HoverProblem(pegasus.LearnedHeliModel(identified, learned), target=options.target,
                                reward=pegasus.hover_reward_for(identified, options),
                                init=pegasus.hover_init_from_model(identified), seed=options.seed,
                                scenarios=4, horizon=20, gamma=options.gamma_per_step(), threads=1)
    theta = ours.parameters.initial
    assert exact.uhat(theta) == ours.uhat(theta)


def test_lqr_starting_gains_are_the_ones_training_starts_from(model_json):
    identified = pegasus.IdentifiedModel.load(str(model_json))
    options = pegasus.HoverTrainingOptions()
    options.scenarios, options.seconds, options.lqr_start = 4, 2.0, True
    lqr = pegasus.lqr_hover_init(identified, options)
    assert lqr["used"] and lqr["reason"] == "" and lqr["spectral_radius"] < 1.0
    assert lqr["init"].k_pos != pegasus.HoverPolicyInit().k_pos
    exact = pegasus.HoverProblem.from_training_options(str(model_json), options, threads=2)
    learned = pegasus.LearnedModelOptions()
    learned.start = [0, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    learned.start_pos_sigma, learned.start_vel_sigma = options.start_pos_sigma, options.start_vel_sigma
    ours = pegasus.HoverProblem(pegasus.LearnedHeliModel(identified, learned), target=options.target,
                                reward=pegasus.hover_reward_for(identified, options), init=lqr["init"],
                                seed=options.seed, scenarios=4, horizon=options.horizon(), gamma=options.gamma,
                                threads=1)
    assert np.array_equal(exact.parameters.initial, ours.parameters.initial)
    assert exact.uhat(ours.parameters.initial) == ours.uhat(ours.parameters.initial)


def test_train_hover_gives_the_cli_policy_and_resumes_bit_identically(model_json, cli, tmp_path):
    flags = ["--scenarios", "3", "--seconds", "1", "--optimizer.gradient.max-iterations", "2",
             "--optimizer.hill-climbing.max-iterations", "2"]
    result = subprocess.run([cli, "heli", "hover", "--model", str(model_json), *flags, "--quiet", "--threads", "2",
                             "--out", str(tmp_path / "cli")], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    options = pegasus.HoverTrainingOptions()
    options.scenarios, options.seconds = 3, 1.0
    options.optimizer.gradient.max_iterations = 2
    options.optimizer.hill_climbing.max_iterations = 2
    checkpoints = []
    result = pegasus.train_hover(str(model_json), options, checkpoint_every=1, on_checkpoint=checkpoints.append)
    policy = pegasus.HeliPolicy.load(str(tmp_path / "cli" / "policy.json"))
    assert np.array_equal(policy.values, result.theta)
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert result.final_uhat == summary["final_uhat"] and result.initial_uhat == summary["initial_uhat"]
    assert result.gradient.method == "gradient" and result.hill_climb.method == "hill-climb"
    start = summary["starting_policy"]
    assert (result.start.scenarios, result.start.crashed) == (start["scenarios"], start["crashed_scenarios"]) == (3, 0)
    assert result.start.uhat == result.initial_uhat  # the starting weights on the same scenarios
    # Resumed from a checkpoint in the second stage, on other threads: the same bits.
    later = [c for c in checkpoints if c["stage"] == 1]
    assert later, [c["stage"] for c in checkpoints]
    resumed = pegasus.train_hover(str(model_json), options, resume_from=later[0], threads=3)
    assert np.array_equal(resumed.theta, result.theta) and resumed.final_uhat == result.final_uhat
    assert resumed.hill_climb.same_outcome(result.hill_climb) == (True, "")


# ---- Policy files -----------------------------------------------------------------------------------------------

def control_lines(cli, policy_path, times, states):
    lines = "".join(",".join(repr(float(v)) for v in [t, *s]) + "\n" for t, s in zip(times, states))
    result = subprocess.run([cli, "heli", "control", "--policy", str(policy_path)], input=lines,
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return np.array([[float(v) for v in line.split(",")] for line in result.stdout.splitlines()])


def flown_states(n=40, seed=5):
    aircraft = pegasus.Aircraft()
    scenarios = pegasus.ScenarioSet(seed, n, 1, 15, 21)
    params = pegasus.AircraftParams()
    params.start_pos_sigma, params.start_vel_sigma = 2.0, 1.0
    return pegasus.Aircraft(params).observe(pegasus.Aircraft(params).initial_state(scenarios.initial_noise())), aircraft


def test_a_hover_policy_file_serves_the_cli_controls_for_a_batch_of_states(cli, tmp_path):
    states, aircraft = flown_states()
    init = trimmed_init(aircraft)
    rng = np.random.default_rng(4)
    theta = pegasus.HoverPolicy(init).parameters.initial + 0.05 * rng.normal(size=34)
    target = pegasus.SetPoint(1.0, -2.0, -12.0, 0.3)
    path = tmp_path / "policy.json"
    pegasus.HeliPolicy.hover(theta, target, init.trim, init).save(str(path))
    policy = pegasus.HeliPolicy.load(str(path))
    assert policy.class_name == "hover" and policy.names[0] == "a1.bias" and np.array_equal(policy.values, theta)
    assert policy.target == target and np.array_equal(policy.trim, init.trim)
    controls = policy.controls(states)
    assert controls.shape == (40, 4) and np.abs(controls).max() <= 1.0
    assert np.array_equal(controls, pegasus.HoverPolicy(init).act(theta, states, target))
    assert np.array_equal(controls, policy.controls(states, 0.0, threads=3))
    assert np.array_equal(controls, control_lines(cli, path, np.zeros(40), states))
    again = pegasus.HeliPolicy.from_json(policy.to_json())
    assert np.array_equal(again.controls(states), controls)


def test_command_limits_clip_in_python_in_the_file_and_in_the_cli_alike(cli, tmp_path):
    states, aircraft = flown_states()
    init = trimmed_init(aircraft)
    rng = np.random.default_rng(5)
    theta = pegasus.HoverPolicy(init).parameters.initial + 0.05 * rng.normal(size=34)
    free = pegasus.HoverPolicy(init).act(theta, states)
    # Limits just inside the free controls' range on every channel, so that each binds somewhere.
    low, high = free.min(axis=0), free.max(axis=0)
    init.command_lower = low + 0.25 * (high - low)
    init.command_upper = high - 0.25 * (high - low)
    limited = pegasus.HoverPolicy(init).act(theta, states)
    assert np.array_equal(limited, np.clip(free, init.command_lower, init.command_upper))
    assert (limited != free).any(axis=0).all()
    path = tmp_path / "policy.json"
    pegasus.HeliPolicy.hover(theta, pegasus.SetPoint(), init.trim, init).save(str(path))
    assert json.loads(path.read_text())["options"]["command_limits"]["upper"] == list(init.command_upper)
    policy = pegasus.HeliPolicy.load(str(path))
    assert np.array_equal(policy.controls(states), limited)
    assert np.array_equal(control_lines(cli, path, np.zeros(len(states)), states), limited)
    init.command_lower = [0.5, -1, -1, -1]
    init.command_upper = [0.4, 1, 1, 1]
    with pytest.raises(ValueError, match="a1: expected -1 <= lower <= upper <= 1"):
        pegasus.HoverPolicy(init)


def test_a_hover_policy_with_the_integral_term_remembers_over_one_flight_as_the_cli_does(cli, tmp_path):
    states, aircraft = flown_states()
    init = trimmed_init(aircraft)
    init.integral_seconds = 5
    theta = pegasus.HoverPolicy(init).parameters.initial
    assert theta.shape == (38,) and pegasus.HoverPolicy(init).parameters.names[34] == "a1.int"
    target = pegasus.SetPoint(1.0, -2.0, -12.0, 0.3)
    path = tmp_path / "policy.json"
    pegasus.HeliPolicy.hover(theta, target, init.trim, init).save(str(path))
    policy = pegasus.HeliPolicy.load(str(path))
    assert policy.options["integral"]["dt"] == 0.02
    times = np.arange(40) * 0.02
    flight = policy.controls(states, times, one_flight=True)
    batch = policy.controls(states, times)  # every row a flight's first call: the integral is 0
    assert np.array_equal(batch, pegasus.HoverPolicy(init).act(theta, states, target))
    assert np.array_equal(flight[0], batch[0]) and not np.array_equal(flight[1:], batch[1:])
    # `heli control` serves one flight: its answers carry the same memory, bit for bit.
    assert np.array_equal(flight, control_lines(cli, path, times, states))


def test_a_maneuver_policy_file_serves_the_cli_controls_at_each_time(cli, tmp_path):
    states, aircraft = flown_states()
    init = trimmed_init(aircraft)
    hover = pegasus.HeliPolicy.hover(pegasus.HoverPolicy(init).parameters.initial, pegasus.SetPoint(0, 0, -10, 0),
                                     init.trim, init).to_json()
    extra = [{"name": "couple.tail_to_lat", "value": 0.1}, {"name": "couple.coll_to_tail", "value": -0.2},
             {"name": "z_delay", "value": 0.5}, {"name": "feedforward", "value": 1.0}]
    file = dict(hover, **{"class": "maneuver", "parameters": hover["parameters"] + extra,
                          "options": {"name": "III.2"}})
    path = tmp_path / "maneuver.json"
    path.write_text(json.dumps(file))
    policy = pegasus.HeliPolicy.load(str(path))
    assert policy.class_name == "maneuver" and len(policy.values) == 38
    times = np.linspace(0.0, 30.0, 40)
    controls = policy.controls(states, times, threads=2)
    assert np.array_equal(controls, control_lines(cli, path, times, states))
    # One time for every row is the same as that time repeated; the set point moves along the manoeuvre.
    assert np.array_equal(policy.controls(states, 12.5), policy.controls(states, np.full(40, 12.5)))
    start, later = policy.target_at(0.0), policy.target_at(20.0)
    assert (start.x, start.y, start.z) != (later.x, later.y, later.z)


def test_a_log_read_through_a_vehicle_file_is_in_the_pipelines_layout(cli, source_dir, tmp_path):
    """The X-Cell's vehicle file reads its own logs bit for bit as read_flight_log does; an outside layout (its
    quaternion and body-frame velocity, its throttle in [0, 1] and reversed elevator) reads back to the same
    states and controls."""
    result = subprocess.run([cli, "heli", "pilot", "--seconds", "20", "--quiet", "--out", str(tmp_path / "p")],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    own = pegasus.read_flight_log(str(tmp_path / "p" / "log.csv"))
    through = pegasus.read_flight_log(str(tmp_path / "p" / "log.csv"),
                                      vehicle=str(source_dir / "experiments" / "vehicles" / "xcell60.toml"))
    assert np.array_equal(own.states, through.states) and np.array_equal(own.controls, through.controls)

    roll, pitch, yaw = own.states[:, 3], own.states[:, 4], own.states[:, 5]
    cr, sr, cp, sp, cy, sy = (np.cos(roll / 2), np.sin(roll / 2), np.cos(pitch / 2), np.sin(pitch / 2),
                              np.cos(yaw / 2), np.sin(yaw / 2))
    q = np.stack([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                  cr * cp * sy - sr * sp * cy], axis=1)
    # Body-frame velocity: R_WB^T v_W with R_WB of the Z-Y-X angles.
    c, s = np.cos, np.sin
    rows = []
    for i in range(own.rows):
        r, p, y = roll[i], pitch[i], yaw[i]
        R = np.array([[c(p) * c(y), s(r) * s(p) * c(y) - c(r) * s(y), c(r) * s(p) * c(y) + s(r) * s(y)],
                      [c(p) * s(y), s(r) * s(p) * s(y) + c(r) * c(y), c(r) * s(p) * s(y) - s(r) * c(y)],
                      [-s(p), s(r) * c(p), c(r) * c(p)]])
        rows.append(R.T @ own.states[i, 6:9])
    v_B = np.array(rows)
    a = own.controls
    columns = {"time": own.time, "n": own.states[:, 0], "e": own.states[:, 1], "d": own.states[:, 2],
               "u": v_B[:, 0], "v": v_B[:, 1], "w": v_B[:, 2], "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2],
               "qz": q[:, 3], "droll": own.states[:, 9], "dpitch": own.states[:, 10], "dyaw": own.states[:, 11],
               "throttle": (a[:, 2] + 1) / 2, "elevator": -a[:, 0], "aileron": a[:, 1], "rudder": a[:, 3]}
    with open(tmp_path / "outside.csv", "w") as f:
        f.write(",".join(columns) + "\n")
        for i in range(own.rows):
            f.write(",".join(repr(float(v[i])) for v in columns.values()) + "\n")
    # Inline tables, in the aircraft's channel order.
    (tmp_path / "outside.toml").write_text("""
[log]
rate_hz = 50
position = {fields = ["n", "e", "d"]}
velocity = {fields = ["u", "v", "w"], frame = "body"}
attitude = {fields = ["qw", "qx", "qy", "qz"], form = "quaternion"}
rates = {fields = ["droll", "dpitch", "dyaw"], form = "euler"}
controls = [{field = "throttle", axis = "thrust", range = [0, 1]}, {field = "elevator", axis = "pitch", sign = -1},
            {field = "aileron", axis = "roll"}, {field = "rudder", axis = "yaw"}]
""")
    outside = pegasus.read_flight_log(str(tmp_path / "outside.csv"), vehicle=str(tmp_path / "outside.toml"))
    yaw_error = np.angle(np.exp(1j * (outside.states[:, 5] - own.states[:, 5])))
    assert np.max(np.abs(yaw_error)) < 1e-12
    keep = [0, 1, 2, 3, 4, 6, 7, 8, 9, 10, 11]
    assert np.max(np.abs(outside.states[:, keep] - own.states[:, keep])) < 1e-12
    assert np.max(np.abs(outside.controls - own.controls)) < 1e-12
    (tmp_path / "bad.toml").write_text((tmp_path / "outside.toml").read_text().replace('axis = "roll"',
                                                                                       'axis = "pitch"'))
    with pytest.raises(ValueError, match=r"bad.toml:\d+: log.controls\[2\].axis: the pitch axis is already driven"):
        pegasus.read_flight_log(str(tmp_path / "outside.csv"), vehicle=str(tmp_path / "bad.toml"))


def test_bad_helicopter_inputs_raise_value_error_naming_the_argument(tmp_path, model_json):
    aircraft = pegasus.Aircraft()
    s = aircraft.initial_state(np.full((2, 21), 0.5))
    with pytest.raises(ValueError, match="actions"):
        aircraft.step(s, np.zeros((3, 4)), np.full((2, 15), 0.5))
    with pytest.raises(ValueError, match="noise: expected uniforms"):
        aircraft.step(s, np.zeros((2, 4)), np.full((2, 15), 1.5))
    with pytest.raises(ValueError, match="actions: expected finite"):
        aircraft.step(s, np.full((2, 4), np.nan), np.full((2, 15), 0.5))
    bad = s.copy()
    bad[0, 35] = 9.0
    with pytest.raises(ValueError, match="crash code"):
        aircraft.step(bad, np.zeros((2, 4)), np.full((2, 15), 0.5))
    with pytest.raises(ValueError, match="threads"):
        aircraft.step(s, np.zeros((2, 4)), np.full((2, 15), 0.5), threads=0)
    with pytest.raises(ValueError, match="states"):
        aircraft.observe(np.zeros((2, 12)))
    with pytest.raises(ValueError, match="actions, controller"):
        aircraft.simulate(np.full((2, 21), 0.5), np.full((2, 3, 15), 0.5))
    with pytest.raises(ValueError, match="noise"):
        aircraft.simulate(np.full((2, 21), 0.5), np.full((2, 3, 14), 0.5), actions=np.zeros((2, 3, 4)))
    with pytest.raises(ValueError, match="policy"):
        aircraft.simulate(np.full((2, 21), 0.5), np.full((2, 3, 15), 0.5), policy="hover")
    params = pegasus.AircraftParams()
    params.mass_kg = -1.0
    with pytest.raises(ValueError, match="params"):
        pegasus.Aircraft(params)
    with pytest.raises(ValueError, match="model"):
        pegasus.HoverProblem("not a model", seed=1, scenarios=2, horizon=10)
    with pytest.raises(ValueError, match="gamma"):
        pegasus.HoverProblem(aircraft, seed=1, scenarios=2, horizon=10, gamma=2.0)
    with pytest.raises(ValueError, match="model"):
        pegasus.LearnedHeliModel(3)
    with pytest.raises(ValueError, match="nothing.json"):
        pegasus.LearnedHeliModel(str(tmp_path / "nothing.json"))
    (tmp_path / "p.json").write_text('{"format": "pegasus-heli-policy", "version": 1, "class": "hover"}')
    with pytest.raises(ValueError, match="p.json"):
        pegasus.HeliPolicy.load(str(tmp_path / "p.json"))
    policy = pegasus.HeliPolicy.hover(pegasus.HoverPolicy().parameters.initial)
    with pytest.raises(ValueError, match="states"):
        policy.controls(np.zeros((3, 11)))
    with pytest.raises(ValueError, match="states: expected finite"):
        policy.controls(np.full((3, 12), np.inf))
    with pytest.raises(ValueError, match="time"):
        policy.controls(np.zeros((3, 12)), np.zeros(2))
    with pytest.raises(ValueError, match="theta"):
        pegasus.HeliPolicy.hover(np.zeros(5))
    with pytest.raises(ValueError, match="trim"):
        pegasus.HeliPolicy.hover(pegasus.HoverPolicy().parameters.initial, pegasus.SetPoint(), [2, 0, 0, 0])
    with pytest.raises(ValueError, match="yaw"):
        pegasus.SetPoint(0, 0, -10, float("nan"))
    learned = pegasus.LearnedHeliModel(str(model_json))
    rows = learned.initial_state(np.full((1, 6), 0.5))
    rows[0, -1] = 0.5
    with pytest.raises(ValueError, match="crashed"):
        learned.step(rows, np.zeros((1, 4)), np.full((1, 8), 0.5))


def test_the_pilot_flies_the_quadrotor_as_the_cli_does_with_estimate_errors_of_their_size(cli, source_dir,
                                                                                          tmp_path):
    flight = pegasus.fly_pilot("crazyflie2", seconds=30, seed=3)  # the aircraft's own gusts, as the CLI's
    assert flight["crash"] == "none"
    log, truth = flight["log"], flight["truth"]
    assert log.rows == 1500 and truth.shape == (1500, 12)
    # The same log as `pegasus pilot --vehicle crazyflie2.toml` (the CSV keeps 17 significant digits).
    vehicle = source_dir / "experiments" / "vehicles" / "crazyflie2.toml"
    result = subprocess.run([cli, "pilot", "--vehicle", str(vehicle), "--seconds", "30", "--seed", "3",
                             "--quiet", "--out", str(tmp_path / "pilot")], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    from_cli = pegasus.read_flight_log(str(tmp_path / "pilot" / "log.csv"))
    np.testing.assert_array_equal(from_cli.states, log.states)
    np.testing.assert_array_equal(from_cli.controls, log.controls)
    # The estimate differs from the truth by the quadrotor's documented errors: 0.01 m in position, 0.02 m/s
    # in velocity (Gauss-Markov, so the sample spread of 30 s lies within a generous band).
    error = log.states - truth
    assert 0.005 < error[:, 0:3].std() < 0.02
    assert 0.01 < error[:, 6:9].std() < 0.04
    with pytest.raises(ValueError, match="zeppelin"):
        pegasus.fly_pilot("zeppelin")


def test_the_ground_truths_shared_settings_say_what_they_are():
    shared = ["gust_sigma", "gust_tau", "est_sigma_pos", "est_sigma_vel", "est_sigma_angle", "est_sigma_rate",
              "est_tau", "max_tilt_rad", "max_rate_rad_s", "dt", "substeps", "start_yaw", "start_pos_sigma",
              "start_vel_sigma", "mean_wind_W", "start_p_W"]
    for cls in (pegasus.AircraftParams, pegasus.QuadrotorParams):
        assert [f for f in shared if len((getattr(cls, f).__doc__ or "").strip()) < 10] == [], cls.__name__


def test_the_set_point_bicycle_and_learned_model_settings_say_what_they_are():
    for cls in (pegasus.SetPoint, pegasus.LearnedModelOptions, pegasus.BicycleOptions, pegasus.BicycleGoal,
                pegasus.BicycleStart):
        undocumented = [name for name, value in vars(cls).items()
                        if isinstance(value, property) and len((value.__doc__ or "").strip()) < 5]
        assert undocumented == [], cls.__name__


def test_a_built_models_settings_cannot_be_changed_through_its_getters():
    # The getters give copies: a model's settings are checked and fixed when it is built (gusts, trims), so a
    # field written through a getter must not change it unchecked.
    aircraft = pegasus.Aircraft()
    aircraft.params.gust_sigma = 5.0
    assert aircraft.params.gust_sigma == pegasus.AircraftParams().gust_sigma
    quad = pegasus.Quadrotor()
    quad.params.substeps = 10**9
    assert quad.params.substeps == pegasus.QuadrotorParams().substeps
    bicycle = pegasus.Bicycle()
    bicycle.options.fall_reward = -1e308
    assert bicycle.options.fall_reward == pegasus.BicycleOptions().fall_reward
    objective = pegasus.FunctionObjective(pegasus.ParameterSpec([pegasus.Parameter("a")]), lambda t: -t[0] ** 2)
    objective.parameters.add(pegasus.Parameter("b"))
    assert len(objective.parameters) == 1
    policy = pegasus.HoverPolicy()
    policy.parameters.add(pegasus.Parameter("extra"))
    assert len(policy.parameters) == len(pegasus.HoverPolicy().parameters)


def test_every_hover_reward_weight_is_a_documented_field_the_reward_checks():
    # The fields come from HoverReward::VisitFields, the judged cost's two included (once left unbound).
    fields = pegasus.HoverReward._fields
    assert fields[:9] == ("alpha_pos", "alpha_vel", "alpha_yaw", "alpha_action", "centre", "alpha_attitude",
                          "alpha_rate", "alpha_body_rate", "alpha_quaternion")
    assert len(set(fields)) == len(fields)
    undocumented = [f for f in pegasus.HoverReward._fields
                    if len((getattr(pegasus.HoverReward, f).__doc__ or "").strip()) < 5]
    assert undocumented == []
    for field in ("alpha_body_rate", "alpha_quaternion"):
        reward = pegasus.HoverReward()
        np.testing.assert_array_equal(getattr(reward, field), [0.0, 0.0, 0.0])
        setattr(reward, field, [1.0, 2.0, -1.0])
        np.testing.assert_array_equal(getattr(reward, field), [1.0, 2.0, -1.0])
        assert reward.is_valid() == (False, f"{field}: expected numbers in [0, 1000000000000], got -1")


def test_train_hover_flies_its_scenarios_in_the_disturbance_as_the_cli_does(model_json, cli, tmp_path):
    flags = ["--scenarios", "3", "--seconds", "1", "--optimizer.gradient.max-iterations", "1",
             "--optimizer.hill-climbing.max-iterations", "1"]
    wind = ["--wind.steady", "0,1.5,0", "--wind.sigma", "0.5", "--wind.gust-sigma", "0.3", "--wind.gust-tau-s", "1"]
    result = subprocess.run([cli, "heli", "hover", "--model", str(model_json), *flags, *wind, "--quiet",
                             "--out", str(tmp_path / "cli")], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert summary["wind"] == {"steady_ned_mps": [0, 1.5, 0], "sigma_mps": 0.5, "gust_sigma_mps": 0.3,
                               "gust_tau_s": 1.0}
    options = pegasus.HoverTrainingOptions()
    options.scenarios, options.seconds = 3, 1.0
    options.optimizer.gradient.max_iterations = 1
    options.optimizer.hill_climbing.max_iterations = 1
    calm = pegasus.train_hover(str(model_json), options)
    windy = pegasus.Disturbance()
    windy.wind, windy.wind_sigma, windy.gust_sigma, windy.gust_tau_s = [0, 1.5, 0], 0.5, 0.3, 1.0
    options.disturbance = windy
    trained = pegasus.train_hover(str(model_json), options)
    assert trained.initial_uhat == summary["initial_uhat"] and trained.final_uhat == summary["final_uhat"]
    assert np.array_equal(pegasus.HeliPolicy.load(str(tmp_path / "cli" / "policy.json")).values, trained.theta)
    assert trained.initial_uhat != calm.initial_uhat  # the wind reached the scenarios


def test_a_disturbance_out_of_its_bounds_is_refused_naming_the_setting(model_json):
    for field, value, words in [("gust_tau_s", 0.0, "gust_tau_s: expected a number in (0, 3600] s, got 0"),
                                ("wind_sigma", 31.0, "wind_sigma: expected a number in [0, 30] m/s, got 31")]:
        d = pegasus.Disturbance()
        setattr(d, field, value)
        assert d.is_valid() == (False, words)
        options = pegasus.HoverTrainingOptions()
        options.disturbance = d
        with pytest.raises(ValueError, match=field):
            pegasus.train_hover(str(model_json), options)


def test_hover_training_numbers_carry_the_options_bounds_and_is_valid_refuses_beyond_them():
    # Each number HoverTrainingOptions describes once (issue 49 item 1) is a field named as `hover`'s option,
    # whose doc gives the option's range; is_valid refuses a value past either end, naming the field and range.
    described = re.compile(r"\(hover's (\w+); ([\[(])([-0-9.e+]+), ([-0-9.e+]+)\]")
    checked = []
    for field in pegasus.HoverTrainingOptions._fields:
        match = described.search(getattr(pegasus.HoverTrainingOptions, field).__doc__ or "")
        if not match:
            continue
        key, opening, lower, upper = match.group(1), match.group(2), float(match.group(3)), float(match.group(4))
        assert key == field
        default = getattr(pegasus.HoverTrainingOptions(), field)
        assert (default > lower if opening == "(" else default >= lower) and default <= upper, field
        kind = type(default)
        for bad in [kind(upper + 1), kind(lower if opening == "(" else lower - 1)]:
            options = pegasus.HoverTrainingOptions()
            setattr(options, field, bad)
            valid, message = options.is_valid()
            assert not valid and message.startswith(f"{field}: expected"), (field, bad, message)
            assert f"{opening}{match.group(3)}, {match.group(4)}]" in message, message
        checked.append(field)
    assert {"scenarios", "seconds", "gamma", "control_rate_hz", "command_margin", "max_tilt_rad"} <= set(checked)
