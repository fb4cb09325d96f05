"""A finite MDP from numpy arrays, solved, shaped with a potential (thesis §3.3) and audited.

A 6 x 6 gridworld: four actions that go where they point with probability 0.8, the goal in a corner, -1 per
step. Shaping with Phi = -distance keeps the optimal policy (Theorem 1) and shifts every value by -Phi
(Lemma 2); a progress bonus that is not a potential is caught by the audit.
Run: PYTHONPATH=build/python /usr/bin/python3 <this file>
"""
import numpy as np
import scipy.sparse

import pegasus


def gridworld(n):
    S, moves = n * n, [(-1, 0), (1, 0), (0, -1), (0, 1)]
    P = [scipy.sparse.lil_matrix((S, S)) for _ in moves]
    for s in range(S):
        r, c = divmod(s, n)
        for a in range(4):
            for k, (dr, dc) in enumerate(moves):
                rr, cc = min(max(r + dr, 0), n - 1), min(max(c + dc, 0), n - 1)
                P[a][s, rr * n + cc] += 0.8 if k == a else 0.2 / 3
    distance = np.array([(n - 1 - s // n) + (n - 1 - s % n) for s in range(S)], dtype=float)
    return [p.tocsr() for p in P], distance


def main():
    n, gamma = 6, 0.95
    P, distance = gridworld(n)
    goal = n * n - 1
    mdp = pegasus.finite_mdp(P, R=np.full(n * n, -1.0), gamma=gamma, absorbing=[goal])
    solved = mdp.value_iteration(epsilon=1e-9)
    print("value iteration:", solved.brief_report())

    phi = -distance
    phi[goal] = 0.0
    shaped = mdp.shape_with_potential(phi).value_iteration(epsilon=1e-9)
    # Theorem 1: the shaped problem's optimal policy is optimal in the original one (ties may pick other actions).
    loss = np.max(mdp.evaluate_policy(solved.policy) - mdp.evaluate_policy(shaped.policy))
    same_policy = loss < 1e-8
    print("shaped with Phi = -distance: loss in M of the shaped optimal policy:", loss)
    print("V' + Phi - V (Lemma 2), largest:", np.max(np.abs(shaped.value + phi - solved.value)))
    assert same_policy and np.allclose(shaped.value + phi, solved.value, atol=1e-6)

    bonus = [p.multiply(distance[None, :] < distance[:, None]).astype(bool) * 0.9 for p in P]
    audit = pegasus.audit_shaping(mdp, bonus)
    print("progress bonus audit:", audit.brief_report())
    assert not audit.potential_based


if __name__ == "__main__":
    main()
