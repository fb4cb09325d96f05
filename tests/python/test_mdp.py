"""Finite MDPs from numpy arrays and scipy.sparse: solvers, potential shaping (thesis Eq 3.1, Theorem 1,
Lemma 2) and the shaping audit."""
import numpy as np
import pytest
import scipy.sparse

import pegasus


def gridworld(n=5, gamma=0.95):
    """n x n grid, four actions that go where they point with probability 0.8 and to a random neighbour
    direction otherwise; the goal (last cell) is absorbing; -1 per step."""
    S, moves = n * n, [(-1, 0), (1, 0), (0, -1), (0, 1)]
    P = np.zeros((4, S, S))
    for s in range(S):
        r, c = divmod(s, n)
        for a in range(4):
            for k, (dr, dc) in enumerate(moves):
                p = 0.8 if k == a else 0.2 / 3
                rr, cc = min(max(r + dr, 0), n - 1), min(max(c + dc, 0), n - 1)
                P[a, s, rr * n + cc] += p
    R = np.full(S, -1.0)
    goal = S - 1
    distance = np.array([(n - 1 - s // n) + (n - 1 - s % n) for s in range(S)], dtype=float)
    return P, R, gamma, [goal], distance


def test_value_iteration_matches_a_numpy_solve_of_the_bellman_equation():
    P, R, gamma, absorbing, _ = gridworld()
    mdp = pegasus.finite_mdp(P, R, gamma, absorbing=absorbing)
    vi = mdp.value_iteration(epsilon=1e-10)
    pi = mdp.policy_iteration()
    assert np.array_equal(vi.policy[:-1], pi.policy[:-1]) or np.allclose(
        mdp.evaluate_policy(vi.policy), pi.value, atol=1e-9)
    # V^pi by numpy: (I - gamma P_pi) V = R over the non-absorbing states, V(goal) = 0.
    S = P.shape[1]
    P_pi = P[pi.policy, np.arange(S), :].copy()
    P_pi[absorbing, :] = 0.0
    P_pi[:, absorbing] = 0.0
    r = R.copy()
    r[absorbing] = 0.0
    v = np.linalg.solve(np.eye(S) - gamma * P_pi, r)
    assert pi.value == pytest.approx(v, abs=1e-10)
    assert vi.value == pytest.approx(v, abs=1e-7)
    assert mdp.evaluate_policy(pi.policy) == pytest.approx(v, abs=1e-10)


def test_sparse_and_dense_inputs_build_the_same_mdp():
    P, R, gamma, absorbing, _ = gridworld()
    dense = pegasus.finite_mdp(P, R, gamma, absorbing=absorbing)
    sparse = pegasus.finite_mdp([scipy.sparse.csr_matrix(m) for m in P], R, gamma, absorbing=absorbing)
    assert np.array_equal(dense.policy_iteration().value, sparse.policy_iteration().value)
    assert np.array_equal(dense.expected_reward, sparse.expected_reward)


def test_potential_shaping_keeps_the_optimal_policy_and_shifts_values_by_minus_phi():
    P, R, gamma, absorbing, distance = gridworld()
    mdp = pegasus.finite_mdp(P, R, gamma, absorbing=absorbing)
    phi = -distance
    phi[absorbing] = 0.0
    shaped = mdp.shape_with_potential(phi)
    v, v_shaped = mdp.policy_iteration(), shaped.policy_iteration()
    # Theorem 1: the shaped problem's optimal policy is optimal in M (ties may choose other actions).
    assert mdp.evaluate_policy(v_shaped.policy) == pytest.approx(v.value, abs=1e-9)
    assert v_shaped.value == pytest.approx(v.value - phi, abs=1e-9)  # Lemma 2


def test_the_audit_tells_a_potential_from_a_progress_bonus():
    P, R, gamma, absorbing, distance = gridworld()
    mdp = pegasus.finite_mdp(P, R, gamma, absorbing=absorbing)
    phi = -3.0 * distance
    phi[absorbing] = 0.0
    S = P.shape[1]
    moves = P > 0
    moves[:, absorbing, :] = False  # an absorbing state's only transition is its own self-loop
    potential_F = np.where(moves, gamma * phi[None, None, :] - phi[None, :, None], 0.0)
    audit = pegasus.audit_shaping(mdp, potential_F)
    assert audit.potential_based and audit.max_residual < 1e-9
    bonus_F = np.where(moves & (distance[None, None, :] < distance[None, :, None]), 5.0, 0.0)
    audit = pegasus.audit_shaping(mdp, bonus_F)
    assert not audit.potential_based
    assert audit.has_cycle or audit.has_action_dependence or audit.counterexample_verified
    shaped = pegasus.add_shaping(mdp, bonus_F)
    assert shaped.num_states == S


@pytest.mark.parametrize("build,message", [
    (lambda P, R: pegasus.finite_mdp(P[0], R, 0.9), r"P: expected an array of shape \(A, S, S\)"),
    (lambda P, R: pegasus.finite_mdp(P[:, :, :-1], R, 0.9), r"P\[0\]: expected shape"),
    (lambda P, R: pegasus.finite_mdp(P * 2, R, 0.9), "outside"),
    (lambda P, R: pegasus.finite_mdp(P, R[:-1], 0.9), "R: expected a 1-D array of length 25"),
    (lambda P, R: pegasus.finite_mdp(P, R * np.nan, 0.9), "R: expected finite numbers"),
    (lambda P, R: pegasus.finite_mdp(P, R, 1.5), "gamma"),
    (lambda P, R: pegasus.finite_mdp(P, R, 0.9, absorbing=[-1]), r"absorbing: expected integers in \[0, 25\)"),
    (lambda P, R: pegasus.finite_mdp(P.astype(complex), R, 0.9), "P.0.: expected real numbers"),
    (lambda P, R: pegasus.finite_mdp(P, R, 0.9).evaluate_policy(np.zeros(3)), "policy: expected a 1-D array of length 25"),
    (lambda P, R: pegasus.finite_mdp(P, R, 0.9).shape_with_potential(np.zeros(24)), "phi: expected a 1-D array"),
])
def test_bad_mdp_input_raises_value_error(build, message):
    P, R, _, _, _ = gridworld()
    with pytest.raises(ValueError, match=message):
        build(P, R)
