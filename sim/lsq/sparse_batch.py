"""Sparse ``L D L'`` of a batch of matrices that share one pattern but not their values: ordered
and analysed once, factorised numerically per trial in one compiled pass over the batch.

Where every trial has its own normals (a block of independent models: each trial's models lie
in their own frames, so no two trials share a Jacobian) the factor of :mod:`sim.lsq.sparse`
cannot be reused across trials, but its order and its pattern can. :func:`analyse` takes the
pattern of the symmetric matrix (``b x b`` blocks on the pairs of groups that share a point),
orders the groups once by minimum degree (SciPy's SuperLU ``MMD_AT_PLUS_A`` on the group
graph, each group's ``b`` unknowns kept together), and builds the filled pattern of the factor
(the elimination tree: :func:`sim.lsq.selinv.symbolic`) and its row lists.
:func:`solve_batch` scales each trial's matrix to unit diagonal, factorises all trials by a
left-looking ``L D L'`` on that pattern (the trial as the innermost loop) and solves. A
trial is flagged when a scaled pivot is at or below ``rcond`` (or not finite): the pivots
bound the smallest eigenvalue of the unit-diagonal matrix from above, so what the dense rule
(:func:`sim.lsq.normals.scaled_rcond`) refuses with so small a pivot is refused here too.

The work per trial is that of the factor's columns (sum of their squared counts), not of a
band: on a block of 200 models in 8 strips the factor has 87,000 entries against the
block-tridiagonal band's 163,000, and the solve takes a thirtieth of the banded one's time. Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``, the
reduced normals of the models); the order and elimination tree as :mod:`sim.lsq.sparse`.
Needs the compiled kernels (:func:`sim.lsq.compile.available`); without them the caller takes
its NumPy path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from sim.lsq import compile as jit
from sim.lsq import selinv
from sim.lsq.normals import RCOND

__all__ = ["BatchPattern", "analyse", "solve_batch"]


@dataclass
class BatchPattern:
    """The analysed pattern: ``n`` unknowns; ``src`` (k,) flat indices into the pair blocks
    ``(n_pairs, b, b)`` of the entries on or below the diagonal in the factor's order, going to
    ``dst`` (k,) (``< 0``: diagonal ``-1 - j``, else the factor entry); ``order`` (n,) the
    factor position of each unknown; ``Lp``, ``Li`` the filled strictly lower pattern (CSC,
    sorted); ``Rp``, ``Rk``, ``Rq`` its rows (row ``j``: the columns ``k`` and positions ``q``
    of its entries ``L[j, k]``)."""

    n: int
    src: np.ndarray
    dst: np.ndarray
    order: np.ndarray
    Lp: np.ndarray
    Li: np.ndarray
    Rp: np.ndarray
    Rk: np.ndarray
    Rq: np.ndarray

    @property
    def nnz(self) -> int:
        """Nonzeros of the factor (strictly lower part plus diagonal)."""
        return int(self.Li.size + self.n)


def analyse(pair_g1: np.ndarray, pair_g2: np.ndarray, n_groups: int, b: int) -> BatchPattern:
    """Order and filled pattern of a matrix of ``b x b`` blocks on the group pairs
    ``(pair_g1, pair_g2)`` (both orders and every diagonal pair present), once per block."""
    G = n_groups
    A = sparse.csc_matrix((np.ones(pair_g1.size), (pair_g1, pair_g2)), shape=(G, G))
    A = A + sparse.identity(G, format="csc") * G  # diagonally dominant: only the order is used
    lu = splu(
        sparse.csc_matrix(A),
        permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0,
        options={"SymmetricMode": True},
    )
    gpos = np.asarray(lu.perm_c, np.int64)  # group -> its position
    n = G * b
    order = (gpos[:, None] * b + np.arange(b)).ravel()  # unknown g b + i -> its position
    ii, jj = np.meshgrid(np.arange(b), np.arange(b), indexing="ij")
    r = order[(pair_g1[:, None, None] * b + ii).ravel()]
    c = order[(pair_g2[:, None, None] * b + jj).ravel()]
    flat = np.arange(r.size, dtype=np.int64)
    low = r > c
    lower = sparse.csc_matrix((np.ones(int(low.sum())), (r[low], c[low])), shape=(n, n))
    lower.sort_indices()
    Lp, Li = selinv.symbolic(n, lower.indptr, lower.indices)
    key = np.repeat(np.arange(n, dtype=np.int64), np.diff(Lp)) * n + Li
    dst = np.where(r == c, -1 - r, -1)
    at = np.searchsorted(key, c[low] * n + r[low])
    dst[low] = at
    use = r >= c
    rows = np.argsort(Li, kind="stable")  # entries by row; columns ascending within a row
    Rp = np.zeros(n + 1, np.int64)
    Rp[1:] = np.cumsum(np.bincount(Li, minlength=n))
    Rk = np.repeat(np.arange(n, dtype=np.int64), np.diff(Lp))[rows]
    return BatchPattern(n, flat[use], dst[use], order, Lp, Li, Rp, Rk, rows.astype(np.int64))


def _ldl_batch(Lp, Li, Rp, Rk, Rq, Lx, D, rcond, bad):  # pragma: no cover - compiled
    """Left-looking ``L D L'`` of every trial in place: ``Lx`` (nnz, T) the strictly lower
    entries in, ``L`` out; ``D`` (n, T) the diagonal in, the pivots out; ``bad`` (T,) set where
    a pivot is at or below ``rcond`` or not finite (its pivot is taken as 1 to go on)."""
    n, T = D.shape
    x = np.zeros((n, T))
    for j in range(n):
        for t in range(T):
            x[j, t] = D[j, t]
        for p in range(Lp[j], Lp[j + 1]):
            i = Li[p]
            for t in range(T):
                x[i, t] = Lx[p, t]
        for r in range(Rp[j], Rp[j + 1]):
            k = Rk[r]
            q = Rq[r]
            for t in range(T):
                x[j, t] -= Lx[q, t] * D[k, t] * Lx[q, t]
            for p in range(q + 1, Lp[k + 1]):
                i = Li[p]
                for t in range(T):
                    x[i, t] -= Lx[p, t] * D[k, t] * Lx[q, t]
        for t in range(T):
            d = x[j, t]
            if not d > rcond or not d < np.inf:
                bad[t] = True
                d = 1.0
            D[j, t] = d
        for p in range(Lp[j], Lp[j + 1]):
            i = Li[p]
            for t in range(T):
                Lx[p, t] = x[i, t] / D[j, t]


def _subst_batch(Lp, Li, Lx, D, X):  # pragma: no cover - compiled
    """``X <- L'^-1 D^-1 L^-1 X`` in place, each trial with its own factor (``X`` (n, T))."""
    n, T = X.shape
    for j in range(n):
        for p in range(Lp[j], Lp[j + 1]):
            i = Li[p]
            for t in range(T):
                X[i, t] -= Lx[p, t] * X[j, t]
        for t in range(T):
            X[j, t] /= D[j, t]
    for j in range(n - 1, -1, -1):
        for p in range(Lp[j], Lp[j + 1]):
            i = Li[p]
            for t in range(T):
                X[j, t] -= Lx[p, t] * X[i, t]


def solve_batch(
    pat: BatchPattern, blocks: np.ndarray, rhs: np.ndarray, rcond: float = RCOND
) -> tuple[np.ndarray, np.ndarray]:
    """Solve every trial's ``N x = rhs``: ``blocks`` (T, n_pairs, b, b) the pair blocks of
    ``N`` (the pattern :func:`analyse` saw), ``rhs`` (T, n). Returns ``x`` (T, n) and ``ok``
    (T,): False where a scaled pivot is at or below ``rcond``, the matrix or the solution is
    not finite (those trials' ``x`` is meaningless)."""
    T = blocks.shape[0]
    n = pat.n
    vals = blocks.reshape(T, -1)[:, pat.src]
    on = pat.dst < 0
    diag = np.zeros((T, n))
    diag[:, -1 - pat.dst[on]] = vals[:, on]
    ok = np.isfinite(vals).all(axis=1) & (diag > 0).all(axis=1) & np.isfinite(rhs).all(axis=1)
    s = 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0))  # (T, n) in the factor's order
    cols = np.repeat(np.arange(n, dtype=np.int64), np.diff(pat.Lp))
    Lx = np.zeros((pat.Li.size, T))
    Lx[pat.dst[~on]] = vals[:, ~on].T
    Lx *= (s[:, pat.Li] * s[:, cols]).T
    D = np.ones((n, T))
    bad = ~ok
    Lx[:, bad] = 0.0
    Lx = np.ascontiguousarray(Lx)
    jit.compiled(_ldl_batch)(pat.Lp, pat.Li, pat.Rp, pat.Rk, pat.Rq, Lx, D, float(rcond), bad)
    X = np.zeros((n, T))
    X[pat.order] = np.where(ok[:, None], rhs, 0.0).T
    X *= s.T
    jit.compiled(_subst_batch)(pat.Lp, pat.Li, Lx, D, X)
    x = (X * s.T)[pat.order].T
    ok = ~bad & np.isfinite(x).all(axis=1)
    return x, ok
