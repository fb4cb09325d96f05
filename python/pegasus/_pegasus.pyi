"""Type stubs of the compiled extension (python/src/*.cpp); see help(pegasus.X) for each item."""
from typing import Any, Callable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]

class ScenarioSet:
    def __init__(self, seed: int, count: int, horizon: int, noise_dim: int, initial_noise_dim: int = 0,
                 variant: str = "plain") -> None: ...
    count: int
    horizon: int
    noise_dim: int
    initial_noise_dim: int
    seed: int
    variant: str
    def initial_noise(self) -> Array: ...
    def step_noise(self) -> Array: ...

class Parameter:
    def __init__(self, name: str, initial: float = 0.0, lower: float = ..., upper: float = ...,
                 scale: float = 1.0, integer: bool = False) -> None: ...
    # Read-only: make a new Parameter to change one.
    @property
    def name(self) -> str: ...
    @property
    def initial(self) -> float: ...
    @property
    def lower(self) -> float: ...
    @property
    def upper(self) -> float: ...
    @property
    def scale(self) -> float: ...
    @property
    def integer(self) -> bool: ...

class ParameterSpec:
    def __init__(self, parameters: Sequence[Parameter] = ...) -> None: ...
    @staticmethod
    def from_names(names: Sequence[str], initial: float = 0.0, scale: float = 1.0) -> ParameterSpec: ...
    def add(self, parameter: Parameter) -> ParameterSpec: ...
    def __len__(self) -> int: ...
    def __getitem__(self, i: int) -> Parameter: ...
    names: list[str]
    initial: Array
    lower: Array
    upper: Array
    scales: Array
    def index_of(self, name: str) -> int: ...

class Objective:
    parameters: ParameterSpec
    def uhat(self, theta: ArrayLike) -> float: ...
    def uhat_batch(self, thetas: ArrayLike) -> Array: ...

class FunctionObjective(Objective):
    def __init__(self, parameters: ParameterSpec, f: Callable[[Array], float]) -> None: ...

class _Checkpointing:
    _fields: Tuple[str, ...]
    checkpoint_every: int
    on_checkpoint: Any
    resume_from: Optional[dict]
    def is_valid(self) -> Tuple[bool, str]: ...

class GradientAscentOptions(_Checkpointing):
    max_iterations: int
    max_evaluations: int
    relative_step: float
    initial_step: float
    max_step: float
    min_step: float
    step_growth: float
    max_backtracks: int
    function_tolerance: float

class HillClimbingOptions(_Checkpointing):
    seed: int
    stream: int
    max_iterations: int
    max_evaluations: int
    proposals_per_iteration: int
    initial_step: float
    max_step: float
    min_step: float
    step_growth: float
    step_shrink: float

class ExhaustiveSearchOptions(_Checkpointing):
    max_policies: int
    block_size: int
    keep_all_values: bool

class NloptOptions(_Checkpointing):
    algorithm: str
    max_evaluations: int
    initial_step: float
    x_tolerance: float
    function_tolerance: float
    population: int
    seed: int

class CmaesOptions(_Checkpointing):
    seed: int
    stream: int
    max_iterations: int
    max_evaluations: int
    population_size: int
    initial_step: float
    x_tolerance: float
    function_tolerance: float
    max_condition: float
    stall_generations: int
    stall_tolerance: float
    restarts: int

class AugmentedRandomSearchOptions(_Checkpointing):
    seed: int
    stream: int
    max_iterations: int
    max_evaluations: int
    directions: int
    top_directions: int
    step_size: float
    exploration_noise: float

class OptimizerOptions:
    _fields: Tuple[str, ...]
    def __init__(self, method: str = "cmaes") -> None: ...
    method: str
    exhaustive: ExhaustiveSearchOptions
    gradient: GradientAscentOptions
    hill_climbing: HillClimbingOptions
    nlopt: NloptOptions
    cmaes: CmaesOptions
    ars: AugmentedRandomSearchOptions
    def iteration_limit(self) -> int: ...
    def set_checkpointing(self, checkpoint_every: int, on_checkpoint: Optional[Callable[[dict], None]] = None,
                          resume_from: Optional[dict] = None) -> None: ...
    def is_valid(self) -> Tuple[bool, str]: ...

def optimizer_methods() -> list[str]: ...

class IterationRecord:
    _fields: Tuple[str, ...]
    iteration: int
    evaluations: int
    value: float
    seconds: float

class OptimizerSummary:
    _fields: Tuple[str, ...]
    method: str
    parameter_names: list[str]
    termination_type: str
    message: str
    iterations: int
    evaluations: int
    replayed_evaluations: int
    resumed: bool
    initial_value: float
    best_value: float
    best_theta: Array
    final_step: float
    wall_seconds: float
    history: list[IterationRecord]
    all_values: Array
    def brief_report(self) -> str: ...
    def full_report(self) -> str: ...
    def same_outcome(self, other: OptimizerSummary) -> Tuple[bool, str]: ...

def solve(objective: Objective, options: OptimizerOptions = ..., theta: Optional[ArrayLike] = None, *,
          callbacks: Optional[Sequence[IterationCallback]] = None) -> Tuple[Array, OptimizerSummary]: ...

class CallbackReturnType:
    CONTINUE: CallbackReturnType
    TERMINATE: CallbackReturnType

class IterationReport:
    method: str
    record: IterationRecord
    best_theta: Array

IterationCallback = Callable[[IterationReport], Union[None, bool, CallbackReturnType]]

class SeedDomains:
    _fields: Tuple[str, ...]
    def __init__(self, **kwargs: int) -> None: ...  # keywords: the names of _fields
    hill_climbing: int
    nlopt: int
    cmaes: int
    ars: int

REFINE_SEED_DOMAINS: SeedDomains
def derive_optimizer_seeds(run_seed: int, domains: SeedDomains, options: OptimizerOptions) -> None: ...

class TrainingSummary:
    _fields: Tuple[str, ...]
    stages: list[OptimizerSummary]
    stage_names: list[str]
    history: list[IterationRecord]
    initial_value: float
    best_value: float
    best_theta: Array
    stopped_by_callback: bool
    def brief_report(self) -> str: ...
    def same_outcome(self, other: TrainingSummary) -> Tuple[bool, str]: ...

def training_checkpoint_iterations(checkpoint: dict) -> int: ...
def _train(plan: Any, objective: Objective, theta: Optional[ArrayLike] = None) -> Tuple[Array, TrainingSummary]: ...

class BoxPolicy:
    parameters: ParameterSpec
    observation_dim: int
    action_dim: int
    def act(self, thetas: ArrayLike, observations: ArrayLike) -> Array: ...

def LinearPolicy(observation_dim: int, low: Sequence[float], high: Sequence[float], scale: float = 1.0
                 ) -> BoxPolicy: ...
def SigmoidPolicy(observation_dim: int, low: Sequence[float], high: Sequence[float], scale: float = 1.0
                  ) -> BoxPolicy: ...

class VectorizedProblem(Objective):
    def __init__(self, model: Any, policy: Any, *, seed: int, scenarios: int, horizon: int, gamma: float = 1.0,
                 variant: str = "plain", threads: int = 1) -> None: ...
    threads: int
    scenarios: ScenarioSet
    gamma: float
    horizon: int
    def returns(self, thetas: ArrayLike) -> Array: ...

class BicycleGoal:
    @staticmethod
    def circle(x: float, y: float, radius: float) -> BicycleGoal: ...
    @staticmethod
    def infinitely_far(direction: float) -> BicycleGoal: ...
    at_infinity: bool
    x: float
    y: float
    radius: float
    direction: float

class BicycleStart:
    omega: float
    omega_dot: float
    theta: float
    theta_dot: float
    goal_angle: float

class BicycleOptions:
    goal: BicycleGoal
    start: BicycleStart
    fall_reward: float
    goal_reward: float
    noise: float
    def is_valid(self) -> Tuple[bool, str]: ...

class Bicycle:
    def __init__(self, options: BicycleOptions = ...) -> None: ...
    options: BicycleOptions
    noise_dim: int
    initial_noise_dim: int
    def initial_state(self, noise: ArrayLike) -> Array: ...
    def step(self, states: ArrayLike, actions: ArrayLike, noise: ArrayLike) -> Array: ...
    def observe(self, states: ArrayLike) -> Array: ...

def bicycle_features(observations: ArrayLike) -> Array: ...
def bicycle_policy_parameters() -> ParameterSpec: ...
def bicycle_balancing_theta() -> Array: ...
def read_bicycle_policy(path: str) -> Array: ...
def bicycle_controls(theta: ArrayLike, observations: ArrayLike) -> Array: ...

class BicycleProblem(Objective):
    def __init__(self, bicycle: BicycleOptions = ..., *, seed: int, scenarios: int, horizon: int,
                 gamma: float = 1.0, variant: str = "plain", threads: int = 1) -> None: ...
    def returns(self, theta: ArrayLike) -> Array: ...

class BicycleTrainingOptions:
    scenarios: int
    gamma: float
    horizon: int
    shaping: str
    shaping_per_metre: float
    estimator: str
    variant: str
    initial_policy: str
    bicycle: BicycleOptions
    optimizer: OptimizerOptions
    seed: int
    threads: int
    def is_valid(self) -> Tuple[bool, str]: ...

def train_bicycle(options: BicycleTrainingOptions, *, checkpoint_every: int = 0,
                  on_checkpoint: Optional[Callable[[dict], None]] = None, resume_from: Optional[dict] = None,
                  callbacks: Optional[Sequence[IterationCallback]] = None) -> Tuple[Array, OptimizerSummary]: ...
def bicycle_uhat(options: BicycleTrainingOptions, theta: ArrayLike) -> float: ...
def bicycle_training_problem(options: BicycleTrainingOptions) -> Objective: ...

class PendulumProblem(Objective):
    def __init__(self, *, seed: int, scenarios: int, horizon: int, gamma: float = 1.0, variant: str = "plain",
                 threads: int = 1, refinements: bool = True) -> None: ...
    def returns(self, theta: ArrayLike) -> Array: ...

class Pendulum:
    noise_dim: int
    initial_noise_dim: int
    def initial_state(self, noise: ArrayLike) -> Array: ...
    def step(self, states: ArrayLike, actions: ArrayLike) -> Array: ...
    def reward(self, states: ArrayLike, actions: ArrayLike) -> Array: ...

def pendulum_policy_parameters(refinements: bool = True) -> ParameterSpec: ...

class GridworldProblem(Objective):
    def __init__(self, n: int, intended: float = 0.8, *, seed: int, scenarios: int, horizon: int,
                 gamma: float = 1.0, variant: str = "plain", threads: int = 1) -> None: ...
    def returns(self, theta: ArrayLike) -> Array: ...

class PomdpGridworldProblem(Objective):
    def __init__(self, width: int = 5, height: int = 5, *, seed: int, scenarios: int, horizon: int,
                 gamma: float = 1.0, variant: str = "plain", threads: int = 1) -> None: ...
    def returns(self, theta: ArrayLike) -> Array: ...

def corner_gridworld_mdp(n: int, intended: float = 0.8, gamma: float = 1.0) -> FiniteMdp: ...
def corner_gridworld_potential(n: int, intended: float = 0.8, scale: float = 1.0) -> Array: ...

class SolveSummary:
    value: Array
    policy: npt.NDArray[np.int64]
    iterations: int
    polish_iterations: int
    residual: float
    policy_loss_bound: float
    value_error_bound: float
    converged: bool
    message: str
    def brief_report(self) -> str: ...

class PolicyChange:
    changes: bool
    states: list[int]
    loss_under_initial: float
    max_loss: float

class ShapingAudit:
    potential_based: bool
    potential: Array
    max_residual: float
    rms_residual: float
    scope_size: int
    has_action_dependence: bool
    has_cycle: bool
    counterexample_verified: bool
    counterexample_note: str
    policy_change: PolicyChange
    def brief_report(self) -> str: ...

class FiniteMdp:
    num_states: int
    num_actions: int
    gamma: float
    absorbing: list[int]
    initial: Array
    expected_reward: Array
    def value_iteration(self, epsilon: float = 1e-8, gauss_seidel: bool = False, max_iterations: int = 1000000
                        ) -> SolveSummary: ...
    def policy_iteration(self, max_iterations: int = 10000) -> SolveSummary: ...
    def evaluate_policy(self, policy: ArrayLike) -> Array: ...
    def shape_with_potential(self, phi: ArrayLike) -> FiniteMdp: ...

class FlightLog:
    rows: int
    dt: float
    time: Array
    states: Array
    controls: Array

def read_flight_log(path: str, min_rows: int = 100, vehicle: str = "") -> FlightLog: ...
def flight_log(data: ArrayLike, columns: Sequence[str], min_rows: int = 100) -> FlightLog: ...
def fly_pilot(simulator: str = "xcell", seconds: float = 60.0, seed: int = 1, gust_sigma: float = -1.0,
              estimate_noise: bool = True, hover_seconds: float = 10.0, sweeps: bool = True) -> dict: ...

class IdentifiedModel:
    dt: float
    is_global: bool
    sigma2: Array
    horizon_sd_factors: Array
    inv_bandwidth: Array
    def to_json(self) -> dict: ...
    def save(self, path: str) -> None: ...
    @staticmethod
    def load(path: str) -> IdentifiedModel: ...

def identify(log: FlightLog, *, rate_hz: float = 10.0, local: bool = True, extra_states: bool = True,
             intercept: bool = True, templates: bool = True, window_s: float = 16.0, cv_points: int = 300,
             scale_grid: Sequence[float] = ..., coordinate_passes: int = 1,
             bandwidth_floor: Mapping[str, float] = ..., noise: str = "white", calibrate_noise: bool = False,
             horizon_sd_factors: bool = True, calibration_leave_out_s: float = 2.0,
             calibration_spacing_s: float = 0.5, threads: int = 1) -> IdentifiedModel: ...
def horizon_mse(model: IdentifiedModel, test: FlightLog, *, horizon_s: float = 10.0, start_spacing_s: float = 2.0,
                threads: int = 1) -> dict: ...
def horizon_mse_as_trained(model: IdentifiedModel, test: FlightLog, *, control_rate_hz: float = 50.0,
                           horizon_s: float = 10.0, start_spacing_s: float = 2.0, threads: int = 1) -> dict: ...
def noise_check(model: IdentifiedModel, test: Union[FlightLog, Sequence[FlightLog]], *, reset_s: float = 2.0, threads: int = 1) -> dict: ...
def closed_loop_bias(model: IdentifiedModel) -> list[dict]: ...

class SetPoint:
    _fields: Tuple[str, ...]
    def __init__(self, x: float = 0.0, y: float = 0.0, z: float = -10.0, yaw: float = 0.0) -> None: ...
    x: float
    y: float
    z: float
    yaw: float

class HoverReward:
    _fields: Tuple[str, ...]
    alpha_pos: Array
    alpha_vel: Array
    alpha_yaw: float
    alpha_action: Array
    centre: Array
    alpha_attitude: Array
    alpha_rate: Array
    @staticmethod
    def from_typical(position_m: float, velocity_mps: float, yaw_rad: float, action: float,
                     centre: ArrayLike = ...) -> HoverReward: ...
    def is_valid(self) -> Tuple[bool, str]: ...

class HoverPolicyInit:
    _fields: Tuple[str, ...]
    trim: Array
    trim_roll: float
    trim_pitch: float
    k_pos: float
    k_vel: float
    k_att: float
    k_pos_lat: float
    k_vel_lat: float
    k_roll: float
    k_alt: float
    k_climb: float
    k_yaw: float
    k_yaw_rate: float
    integral_seconds: float

class HoverPolicy:
    def __init__(self, init: HoverPolicyInit = ...) -> None: ...
    parameters: ParameterSpec
    def act(self, theta: ArrayLike, states: ArrayLike, target: SetPoint = ...) -> Array: ...

class AircraftParams:
    _fields: Tuple[str, ...]
    mass_kg: float
    ixx: float
    iyy: float
    izz: float
    gravity: float
    air_density: float
    omega_mr: float
    radius_mr: float
    chord_mr: float
    lift_slope_mr: float
    profile_drag_mr: float
    hub_height: float
    hub_stiffness: float
    tau_flap: float
    a_lon: float
    b_lat: float
    cyclic_max_rad: float
    collective_mid_rad: float
    collective_span_rad: float
    gear_tr: float
    radius_tr: float
    chord_tr: float
    lift_slope_tr: float
    arm_tr: float
    height_tr: float
    tail_mid_rad: float
    tail_span_rad: float
    gyro_gain: float
    gyro_tau: float
    fus_area_x: float
    fus_area_y: float
    fus_area_z: float
    servo_rate: float
    mean_wind_W: Array
    gust_sigma: float
    gust_tau: float
    est_sigma_pos: float
    est_sigma_vel: float
    est_sigma_angle: float
    est_sigma_rate: float
    est_tau: float
    max_tilt_rad: float
    max_rate_rad_s: float
    max_thrust_coeff_over_solidity: float
    dt: float
    substeps: int
    start_p_W: Array
    start_yaw: float
    start_pos_sigma: float
    start_vel_sigma: float
    def is_valid(self) -> Tuple[bool, str]: ...

class _HeliBatchModel:
    STATE_COLUMNS: list[str]
    noise_dim: int
    initial_noise_dim: int
    def initial_state(self, noise: ArrayLike, *, threads: int = 1) -> Array: ...
    def step(self, states: ArrayLike, actions: ArrayLike, noise: ArrayLike, *, threads: int = 1) -> Array: ...
    def observe(self, states: ArrayLike) -> Array: ...
    def terminal(self, states: ArrayLike) -> npt.NDArray[np.bool_]: ...
    def simulate(self, initial_noise: ArrayLike, noise: ArrayLike, *, actions: Optional[ArrayLike] = None,
                 policy: Optional[HeliPolicy] = None, threads: int = 1) -> dict: ...

class Aircraft(_HeliBatchModel):
    def __init__(self, params: AircraftParams = ...) -> None: ...
    params: AircraftParams
    hover_trim: dict
    def true_state(self, states: ArrayLike) -> Array: ...
    def crash_reason(self, states: ArrayLike) -> list[str]: ...

class QuadrotorParams:
    _fields: Tuple[str, ...]
    mass_kg: float
    ixx: float
    iyy: float
    izz: float
    arm_m: float
    gravity: float
    thrust_coeff: float
    torque_per_thrust_m: float
    max_motor_thrust_n: float
    motor_tau: float
    drag_xy: float
    drag_z: float
    max_tilt_command_rad: float
    max_yaw_rate_command: float
    attitude_gain: float
    rate_gain: float
    yaw_rate_gain: float
    mean_wind_W: Array
    gust_sigma: float
    gust_tau: float
    est_sigma_pos: float
    est_sigma_vel: float
    est_sigma_angle: float
    est_sigma_rate: float
    est_tau: float
    max_tilt_rad: float
    max_rate_rad_s: float
    dt: float
    substeps: int
    start_p_W: Array
    start_yaw: float
    start_pos_sigma: float
    start_vel_sigma: float
    def is_valid(self) -> Tuple[bool, str]: ...

class Quadrotor(_HeliBatchModel):
    def __init__(self, params: QuadrotorParams = ...) -> None: ...
    params: QuadrotorParams
    hover_trim: dict
    hover_rotor_speed: float
    def true_state(self, states: ArrayLike) -> Array: ...
    def crash_reason(self, states: ArrayLike) -> list[str]: ...

class LearnedModelOptions:
    _fields: Tuple[str, ...]
    dt: float
    refit_every: int
    support_bandwidths: float
    crash_reward: float
    max_tilt_rad: float
    noise: bool
    start: Array
    start_pos_sigma: float
    start_vel_sigma: float
    def is_valid(self) -> Tuple[bool, str]: ...

class LearnedHeliModel(_HeliBatchModel):
    def __init__(self, model: Union[IdentifiedModel, str], options: LearnedModelOptions = ...) -> None: ...
    options: LearnedModelOptions
    def reward(self, states: ArrayLike, actions: ArrayLike, next_states: ArrayLike) -> Array: ...

class HoverTrainingOptions:
    _fields: Tuple[str, ...]
    scenarios: int
    seconds: float
    gamma: float
    refit_every: int
    cpu_budget_s: float
    control_rate_hz: float
    lqr_start: bool
    lqr_action_factor: float
    max_tilt_rad: float
    target: SetPoint
    start_pos_sigma: float
    start_vel_sigma: float
    reward: HoverReward
    centre_at_trim: bool
    optimizer: OptimizerOptions
    then_hill_climb: bool
    seed: int
    max_start_crash_fraction: float
    integral_seconds: float
    integral_limit_position: float
    integral_limit_yaw: float
    def horizon(self) -> int: ...
    def gamma_per_step(self) -> float: ...
    def refit_steps(self, model: Union[str, IdentifiedModel]) -> int: ...
    def is_valid(self) -> Tuple[bool, str]: ...

class HoverProblem(Objective):
    def __init__(self, model: Union[Aircraft, Quadrotor, LearnedHeliModel], *, target: SetPoint = ...,
                 reward: HoverReward = ...,
                 init: HoverPolicyInit = ..., seed: int, scenarios: int, horizon: int, gamma: float = 0.9995,
                 variant: str = "plain", threads: int = 1) -> None: ...
    @staticmethod
    def from_training_options(model: Union[IdentifiedModel, str], options: HoverTrainingOptions = ..., *,
                              threads: int = 1) -> HoverProblem: ...
    def returns(self, theta: ArrayLike) -> Array: ...

def hover_init_from_model(model: Union[IdentifiedModel, str]) -> HoverPolicyInit: ...
def lqr_hover_init(model: Union[str, IdentifiedModel], options: HoverTrainingOptions = ...) -> dict: ...
def hover_reward_for(model: Union[IdentifiedModel, str], options: HoverTrainingOptions = ...) -> HoverReward: ...

class StartingPolicyCheck:
    _fields: Tuple[str, ...]
    scenarios: int
    crashed: int
    mean_seconds_to_crash: float
    uhat: float

class HoverTrainingResult:
    _fields: Tuple[str, ...]
    theta: Array
    initial_uhat: float
    final_uhat: float
    gradient: OptimizerSummary
    hill_climb: OptimizerSummary
    progress: list[IterationRecord]
    start: StartingPolicyCheck
    lqr_action_factor: float

def train_hover(model: Union[IdentifiedModel, str], options: HoverTrainingOptions = ..., *, checkpoint_every: int = 1,
                on_checkpoint: Optional[Callable[[dict], None]] = None, resume_from: Optional[dict] = None,
                callbacks: Optional[Sequence[IterationCallback]] = None, threads: int = 1) -> HoverTrainingResult: ...

class HeliPolicy:
    @staticmethod
    def load(path: str) -> HeliPolicy: ...
    @staticmethod
    def from_json(policy: dict, source: str = "policy") -> HeliPolicy: ...
    @staticmethod
    def hover(theta: ArrayLike, target: SetPoint = ..., trim: ArrayLike = ..., init: HoverPolicyInit = ...,
              integral_dt: float = 0.02) -> HeliPolicy: ...
    class_name: str
    names: list[str]
    values: Array
    target: SetPoint
    trim: Array
    options: dict
    provenance: dict
    def to_json(self) -> dict: ...
    def save(self, path: str) -> None: ...
    def controls(self, states: ArrayLike, time: Union[float, ArrayLike] = 0.0, *, threads: int = 1,
                 one_flight: bool = False) -> Array: ...
    def target_at(self, time: float) -> SetPoint: ...

def heli_policy_classes() -> list[str]: ...
