"""Finite MDPs from numpy arrays or scipy.sparse matrices (thesis §2.1), potential shaping (Eq 3.1) and the
shaping audit (§3.A), over the C++ FiniteMdp and its solvers.

Layout: P[a] is the S x S matrix of P_sa(s') for action a (a numpy array of shape (A, S, S), or a sequence of A
matrices, dense or scipy.sparse); a transition-form reward or shaping function F is laid out the same way."""
import numpy as np

from ._pegasus import FiniteMdp


def _is_sparse(x):
    return hasattr(x, "tocoo") and hasattr(x, "nnz")


def _per_action(matrices, name, num_states=None):
    """[(rows, cols, values)] of each action's S x S matrix, from an (A, S, S) array or a sequence of A
    matrices (dense or scipy.sparse)."""
    if _is_sparse(matrices):
        raise ValueError(f"{name}: expected an (A, S, S) array or a sequence of A matrices, got one sparse matrix")
    if isinstance(matrices, np.ndarray) and matrices.ndim != 3:
        raise ValueError(f"{name}: expected an array of shape (A, S, S), got shape {matrices.shape}")
    out = []
    for a, m in enumerate(matrices):
        if _is_sparse(m):
            coo = m.tocoo()
            rows, cols, values = coo.row, coo.col, np.asarray(coo.data, dtype=float)
            shape = coo.shape
        else:
            dense = np.asarray(m)
            if dense.dtype.kind not in "biuf":
                raise ValueError(f"{name}[{a}]: expected real numbers, got dtype {dense.dtype}")
            if dense.ndim != 2:
                raise ValueError(f"{name}[{a}]: expected an S x S matrix, got shape {dense.shape}")
            shape = dense.shape
            rows, cols = np.nonzero(dense)
            values = dense[rows, cols].astype(float)
        num_states = shape[0] if num_states is None else num_states
        if shape != (num_states, num_states):
            raise ValueError(f"{name}[{a}]: expected shape ({num_states}, {num_states}), got {shape}")
        out.append((np.asarray(rows), np.asarray(cols), values))
    if not out:
        raise ValueError(f"{name}: expected at least one action")
    return out, num_states


def _triplets(per_action):
    s = np.concatenate([r for r, _, _ in per_action])
    n = np.concatenate([c for _, c, _ in per_action])
    a = np.concatenate([np.full(len(r), k) for k, (r, _, _) in enumerate(per_action)])
    v = np.concatenate([v for _, _, v in per_action])
    return s, a, n, v


def _lookup(per_action_values, s, a, n, num_states):
    """The values of a transition-form function at the triplets (s, a, n); 0 where it has no entry."""
    out = np.zeros(len(s))
    for k, (rows, cols, values) in enumerate(per_action_values):
        table = dict(zip((rows * num_states + cols).tolist(), values.tolist()))
        mask = a == k
        keys = (s[mask] * num_states + n[mask]).tolist()
        out[mask] = [table.get(key, 0.0) for key in keys]
    return out


def finite_mdp(P, R=None, gamma=1.0, *, absorbing=None, initial=None):
    """A FiniteMdp from transition matrices P (see the module docstring) and a reward R in one of the forms of
    §2.1: shape (S,) for R(s) (the reward of the state being left), (S, A) for R(s, a), or laid out as P for
    R(s, a, s'). Absorbing states (a list of indices) end an episode; initial is D (default: uniform over the
    non-absorbing states). ValueError names the argument on bad input."""
    per_action, num_states = _per_action(P, "P")
    s, a, n, p = _triplets(per_action)
    reward = np.zeros(len(p))
    state_reward = state_action_reward = None
    if R is not None:
        if not _is_sparse(R) and not isinstance(R, (list, tuple)) and np.asarray(R).ndim in (1, 2):
            R = np.asarray(R)
            if R.ndim == 1:
                state_reward = R
            else:
                state_action_reward = R
        else:
            r_per_action, _ = _per_action(R, "R", num_states)
            if len(r_per_action) != len(per_action):
                raise ValueError(f"R: expected {len(per_action)} actions like P, got {len(r_per_action)}")
            reward = _lookup(r_per_action, s, a, n, num_states)
    return FiniteMdp._from_triplets(num_states, len(per_action), gamma, s, a, n, p, reward, state_reward,
                                    state_action_reward, absorbing, initial)


def _shaping_triplets(mdp, F):
    per_action, _ = _per_action(F, "F", mdp.num_states)
    if len(per_action) != mdp.num_actions:
        raise ValueError(f"F: expected {mdp.num_actions} actions, got {len(per_action)}")
    return _triplets(per_action)


def add_shaping(mdp, F):
    """M + F for a shaping function F(s, a, s') laid out as P (any F, potential-based or not)."""
    return mdp._add_shaping(*_shaping_triplets(mdp, F))


def audit_shaping(mdp, F, tolerance=1e-9):
    """The shaping audit of F on mdp: is it potential-based, and if not, the evidence and whether the
    optimal policy changes (thesis §3.3, Theorem 1 and Appendix 3.A). Returns a ShapingAudit."""
    return mdp._audit_shaping(*_shaping_triplets(mdp, F), tolerance)
