"""Randlov and Alstrom's bicycle written in numpy over a batch of rollouts: the equations, constants and update
order of src/envs/bicycle.cpp (bike.c; the plain transcription in tests/bicycle/bicycle_reference.hpp), for
pegasus.VectorizedProblem. A state row is [omega, omega_dot, theta, theta_dot, xf, yf, xb, yb, psi, status]
(status 0 riding, 1 fallen, 2 at the goal)."""
import numpy as np

import pegasus

DT, V, G = 0.01, 10.0 / 3.6, 9.82
D_CM, C, H = 0.3, 0.66, 0.94
M_C, M_D, M_P = 15.0, 1.7, 60.0
M = M_C + M_P
R, L = 0.34, 1.11
SIGMA_DOT = V / R
I_BIKE = 13.0 / 3.0 * M_C * H * H + M_P * (H + D_CM) ** 2
I_DC, I_DV, I_DL = M_D * R * R, 1.5 * M_D * R * R, 0.5 * M_D * R * R
MAX_HANDLEBAR, STRAIGHT_RADIUS, FALL_ANGLE = 1.3963, 9999999.0, np.pi / 15
RIDING, FALLEN, AT_GOAL = 0.0, 1.0, 2.0


def wrap_angle(a):
    """Into (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


class NumpyBicycle:
    """The bicycle with a goal circle (goal=(x, y, radius)) or a goal direction at infinity
    (goal_direction, radians from +x); optional potential shaping Phi = per_metre * progress (thesis Eq 3.1,
    Phi of absorbing states 0)."""

    noise_dim = 1
    initial_noise_dim = 5

    def __init__(self, goal=None, goal_direction=0.0, fall_reward=-100.0, goal_reward=0.0, noise=0.02,
                 start=(0.05, 0.1, 0.05, 0.2, np.pi), shaping_per_metre=0.0, gamma=1.0):
        self.goal = goal
        self.goal_direction = goal_direction
        self.fall_reward, self.goal_reward, self.noise = fall_reward, goal_reward, noise
        self.start = np.asarray(start, dtype=float)
        self.shaping_per_metre, self.gamma = shaping_per_metre, gamma

    def initial_state(self, p0):
        n = p0.shape[0]
        s = np.zeros((n, 10))
        s[:, 0:4] = self.start[:4] * (2.0 * p0[:, 0:4] - 1.0)
        goal_angle = self.start[4] * (2.0 * p0[:, 4] - 1.0)
        to_goal = self.goal_direction if self.goal is None else np.arctan2(self.goal[1], self.goal[0])
        psi = wrap_angle(to_goal - goal_angle - np.pi / 2)
        s[:, 8] = psi
        s[:, 4] = -L * np.sin(psi)
        s[:, 5] = L * np.cos(psi)
        return s

    def step(self, s, a, p):
        omega, omega_dot, theta, theta_dot = s[:, 0], s[:, 1], s[:, 2], s[:, 3]
        xf, yf, xb, yb, psi = s[:, 4], s[:, 5], s[:, 6], s[:, 7], s[:, 8]
        T = np.minimum(np.maximum(a[:, 0], -2.0), 2.0)
        d = np.minimum(np.maximum(a[:, 1], -0.02), 0.02) + self.noise * (2.0 * p[:, 0] - 1.0)

        turning = theta != 0.0
        sin_t, tan_t = np.sin(theta), np.tan(theta)
        safe_tan = np.where(turning, tan_t, 1.0)  # bike.c: r = 9999999 m when theta = 0
        inv_rf = np.where(turning, np.abs(sin_t) / L, 1.0 / STRAIGHT_RADIUS)
        inv_rb = np.where(turning, np.abs(tan_t) / L, 1.0 / STRAIGHT_RADIUS)
        inv_rcm = np.where(turning, 1.0 / np.sqrt((L - C) ** 2 + L * L / (safe_tan * safe_tan)), 1.0 / STRAIGHT_RADIUS)
        phi = omega + np.arctan(d / H)
        omega_dd = (H * M * G * np.sin(phi) - np.cos(phi) * (
            I_DC * SIGMA_DOT * theta_dot + np.sign(theta) * V * V * (M_D * R * (inv_rf + inv_rb) + M * H * inv_rcm))) / I_BIKE
        theta_dd = (T - I_DV * omega_dot * SIGMA_DOT) / I_DL

        omega_dot = omega_dot + omega_dd * DT
        omega = omega + omega_dot * DT
        theta_dot = theta_dot + theta_dd * DT
        theta = theta + theta_dot * DT
        theta = np.where(np.abs(theta) > MAX_HANDLEBAR, np.sign(theta) * MAX_HANDLEBAR, theta)

        step = V * DT
        turn_f = np.sign(psi + theta) * np.arcsin(np.minimum(step * 0.5 * inv_rf, 1.0))
        xf = xf - step * np.sin(psi + theta + turn_f)
        yf = yf + step * np.cos(psi + theta + turn_f)
        turn_b = np.sign(psi) * np.arcsin(np.minimum(step * 0.5 * inv_rb, 1.0))
        xb = xb - step * np.sin(psi + turn_b)
        yb = yb + step * np.cos(psi + turn_b)

        length = np.sqrt((xf - xb) * (xf - xb) + (yf - yb) * (yf - yb))
        fix = np.abs(length - L) > 0.01
        xb = np.where(fix, xb + (xb - xf) * (L - length) / length, xb)
        yb = np.where(fix, yb + (yb - yf) * (L - length) / length, yb)

        dy, dx = yf - yb, xb - xf
        ahead = dy > 0.0
        psi = np.where(ahead, np.arctan(dx / np.where(ahead, dy, 1.0)),
                       np.sign(dx) * (np.pi / 2) - np.arctan(dy / np.where(dx != 0.0, dx, 1.0)))
        psi = np.where((dx == 0.0) & (dy < 0.0), np.pi, psi)

        status = np.where(np.abs(omega) > FALL_ANGLE, FALLEN, RIDING)
        if self.goal is not None:
            inside = (xf - self.goal[0]) ** 2 + (yf - self.goal[1]) ** 2 <= self.goal[2] ** 2
            status = np.where((status == RIDING) & inside, AT_GOAL, status)
        return np.column_stack((omega, omega_dot, theta, theta_dot, xf, yf, xb, yb, psi, status))

    def terminal(self, s):
        return s[:, 9] != RIDING

    def observe(self, s):
        frame = s[:, 8] + np.pi / 2
        if self.goal is None:
            to_goal = np.full(s.shape[0], self.goal_direction)
        else:
            to_goal = np.arctan2(self.goal[1] - s[:, 5], self.goal[0] - s[:, 4])
        return np.stack([s[:, 0], s[:, 1], s[:, 2], s[:, 3], wrap_angle(to_goal - frame)], axis=1)

    def progress(self, s):
        if self.goal is None:
            return s[:, 4] * np.cos(self.goal_direction) + s[:, 5] * np.sin(self.goal_direction)
        return -np.hypot(s[:, 4] - self.goal[0], s[:, 5] - self.goal[1])

    def reward(self, s, a, nxt):
        r = np.where(nxt[:, 9] == FALLEN, self.fall_reward, np.where(nxt[:, 9] == AT_GOAL, self.goal_reward, 0.0))
        if self.shaping_per_metre:
            phi_next = np.where(nxt[:, 9] == RIDING, self.shaping_per_metre * self.progress(nxt), 0.0)
            r = r + self.gamma * phi_next - self.shaping_per_metre * self.progress(s)
        return r

    def event_fraction(self, s, a, nxt):
        """When in the step the fall happened (omega interpolated linearly), as Bicycle::event_fraction."""
        fallen = nxt[:, 9] == FALLEN
        bound = np.where(nxt[:, 0] > 0.0, FALL_ANGLE, -FALL_ANGLE)
        change = nxt[:, 0] - s[:, 0]
        moved = change != 0.0
        tau = np.minimum(np.maximum((bound - s[:, 0]) / np.where(moved, change, 1.0), 0.0), 1.0)
        return np.where(fallen & moved, tau, 0.0)


_FEATURE_SCALES = np.array([np.pi / 15, 1.0, np.pi / 4, 2.0])


def features(observations):
    """The bicycle policy's 15 features (envs/bicycle_policy.hpp): v, v|v|, v^3 of each scaled state variable,
    then g, g|g| and sin of the goal angle (g = goal angle / pi)."""
    n = observations.shape[0]
    out = np.empty((n, 15))
    v = observations[:, :4] / _FEATURE_SCALES
    grid = out[:, :12].reshape(n, 4, 3)  # a view: column 3k + j of out
    grid[:, :, 0] = v
    grid[:, :, 1] = v * np.abs(v)
    grid[:, :, 2] = v * v * v
    g = observations[:, 4] / np.pi
    out[:, 12] = g
    out[:, 13] = g * np.abs(g)
    out[:, 14] = np.sin(observations[:, 4])
    return out


class NumpyBicyclePolicy:
    """T = 4 sigmoid(w_T . x) - 2, d = 0.04 sigmoid(w_d . x) - 0.02: the bicycle policy class in numpy."""

    parameters = pegasus.bicycle_policy_parameters()
    _LOW, _WIDTH = np.array([-2.0, -0.02]), np.array([4.0, 0.04])

    def act(self, thetas, observations):
        x = features(observations)
        z = np.einsum("ikj,ij->ik", thetas.reshape(-1, 2, 15), x)  # [w_T . x, w_d . x] of each row
        with np.errstate(over="ignore"):  # exp(-z) = inf gives the low end of the box, as in C++
            return self._LOW + self._WIDTH / (1.0 + np.exp(-z))


class FeatureBicycle(NumpyBicycle):
    """The same bicycle observed through the 15 features, for the built-in pegasus.SigmoidPolicy."""

    def observe(self, s):
        return features(NumpyBicycle.observe(self, s))


def feature_policy():
    return pegasus.SigmoidPolicy(15, [-2.0, -0.02], [2.0, 0.02])
