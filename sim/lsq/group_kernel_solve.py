"""Compiled kernels of the group-block engine (:mod:`sim.lsq.groups`): the solve and the
cofactors, via numba (compiled by :func:`sim.lsq.compile.compiled`).

Seed of the method: Agnard, Nolette & Gagnon (``003_5ce730a990a7ebc5.txt``, SPACE-M's
reduced normals and Baarda's data snooping on the residuals of the block).

* :func:`dense_scaled` -- the reduced normal matrix (T, G b, G b) from its pair blocks,
  scaled to unit diagonal (``s = |diag|^-1/2``, 1 where the diagonal is 0).
* :func:`chol_vec` -- ``L L' x = y`` by forward and back substitution.
* :func:`chol_inv` -- ``(L L')^-1`` as ``L^-T L^-1``: ``L^-1`` by rows, then rank-one
  updates (a third of the work of substituting the identity).
* :func:`residual_cofactors` -- the diagonal of ``Q_vv = W^-1 - A Q_xx A'`` of the
  observation rows of chosen points, from the dense group cofactors ``Q`` (T, G b, G b):
  ``H_k = sum_{k2 on j} Q[g_k, g_k2] F_k2'``, ``Q(p_j) = Npp_j^-1 + sum_{k on j} F_k H_k``.

Each equals the NumPy path of :mod:`sim.lsq.groups` / :mod:`sim.lsq.group_solve` to
rounding (tests). Units: those of the model; cofactors for unit weight. Call only when
:func:`sim.lsq.compile.available`.
"""

from __future__ import annotations

import numpy as np

from sim.lsq.compile import compiled
from sim.lsq.group_kernel import _c

__all__ = ["dense_scaled", "chol_vec", "chol_inv", "residual_cofactors"]


def _dense_scaled(blocks, pg1, pg2, N, s):  # pragma: no cover - compiled
    """:func:`sim.lsq.group_solve.scaled` of :func:`sim.lsq.group_solve.dense`."""
    T, n_p, b = blocks.shape[0], blocks.shape[1], blocks.shape[2]
    n = N.shape[1]
    for t in range(T):
        N[t] = 0.0
        for p in range(n_p):
            r0, c0 = pg1[p] * b, pg2[p] * b
            for i in range(b):
                for j in range(b):
                    N[t, r0 + i, c0 + j] = blocks[t, p, i, j]
        for i in range(n):
            dg = abs(N[t, i, i])
            s[t, i] = 1.0 / np.sqrt(dg) if dg > 0 else 1.0
        for i in range(n):
            for j in range(n):
                N[t, i, j] = N[t, i, j] * s[t, i] * s[t, j]


def _chol_vec(L, y, x):  # pragma: no cover - compiled
    """:func:`sim.lsq.group_solve.chol_subst` of one right-hand side per trial."""
    T, n = y.shape
    z = np.empty(n)
    for t in range(T):
        for i in range(n):
            v = y[t, i]
            for k in range(i):
                v -= L[t, i, k] * z[k]
            z[i] = v / L[t, i, i]
        for i in range(n - 1, -1, -1):
            v = z[i]
            for k in range(i + 1, n):
                v -= L[t, k, i] * x[t, k]
            x[t, i] = v / L[t, i, i]


def _chol_inv(L, Q):  # pragma: no cover - compiled
    """``chol_subst(L, I)`` (:func:`sim.lsq.group_solve.chol_subst`), the inverse of
    ``L L'``, as ``L^-T L^-1``."""
    T, n = L.shape[0], L.shape[1]
    X = np.empty((n, n))
    for t in range(T):
        for i in range(n):  # X = L^-1 by rows (contiguous axpys)
            for j in range(i + 1):
                X[i, j] = 0.0
            for k in range(i):
                c = L[t, i, k]
                for j in range(k + 1):
                    X[i, j] -= c * X[k, j]
            X[i, i] += 1.0
            inv = 1.0 / L[t, i, i]
            for j in range(i + 1):
                X[i, j] *= inv
        for i in range(n):  # Q = X' X, lower triangle by rank-one updates
            for j in range(i + 1):
                Q[t, i, j] = 0.0
        for k in range(n):
            for i in range(k + 1):
                c = X[k, i]
                for j in range(i + 1):
                    Q[t, i, j] += c * X[k, j]
        for i in range(n):
            for j in range(i):
                Q[t, j, i] = Q[t, i, j]


def _residual_cofactors(Q, F, Ninv, Jg, Jp, w, og, op, pts, pstart, pobs, out):
    # pragma: no cover - compiled
    """The NumPy path of :meth:`sim.lsq.groups.GroupCofactors.residuals`:
    ``1 / w - (Jg Qgg Jg' - 2 Jg H Jp' + Jp Qpp Jp')`` per observation row."""
    T = F.shape[0]
    d, b, m = D_POINT, B_GROUP, M_ROWS  # noqa: F821 (compile-time constants, set by compile.compiled)
    nmax = 0
    for j in pts:
        nmax = max(nmax, pstart[j + 1] - pstart[j])
    H = np.empty((nmax, b, d))
    Qpp = np.empty((d, d))
    JH = np.empty((m, d))
    JQ = np.empty((m, b))
    for t in range(T):
        for j in pts:
            s0, s1 = pstart[j], pstart[j + 1]
            n = s1 - s0
            for u in range(n):
                k = pobs[s0 + u]
                gk = og[k] * b
                for i in range(b):
                    for a in range(d):
                        H[u, i, a] = 0.0
                for u2 in range(n):
                    k2 = pobs[s0 + u2]
                    g2 = og[k2] * b
                    for i in range(b):
                        for jj in range(b):
                            qv = Q[t, gk + i, g2 + jj]
                            for a in range(d):
                                H[u, i, a] += qv * F[t, k2, a, jj]
            for a in range(d):
                for c in range(d):
                    Qpp[a, c] = Ninv[t, j, a, c]
            for u in range(n):
                k = pobs[s0 + u]
                for a in range(d):
                    for c in range(d):
                        v = 0.0
                        for i in range(b):
                            v += F[t, k, a, i] * H[u, i, c]
                        Qpp[a, c] += v
            for u in range(n):
                k = pobs[s0 + u]
                gk = og[k] * b
                for c in range(m):
                    for i in range(b):
                        v = 0.0
                        for jj in range(b):
                            v += Jg[t, k, c, jj] * Q[t, gk + jj, gk + i]
                        JQ[c, i] = v
                    for a in range(d):
                        v = 0.0
                        for i in range(b):
                            v += Jg[t, k, c, i] * H[u, i, a]
                        JH[c, a] = v
                for c in range(m):
                    aqa = 0.0
                    for i in range(b):
                        aqa += JQ[c, i] * Jg[t, k, c, i]
                    x = 0.0
                    for a in range(d):
                        x += JH[c, a] * Jp[t, k, c, a]
                    aqa -= 2.0 * x
                    for a in range(d):
                        v = 0.0
                        for e in range(d):
                            v += Jp[t, k, c, e] * Qpp[e, a]
                        aqa += v * Jp[t, k, c, a]
                    wc = w[t, k, c]
                    out[t, k, c] = 1.0 / wc - aqa if wc > 0 else np.nan


def dense_scaled(st, blocks: np.ndarray):
    """The reduced normal matrix (T, G b, G b) from its pair blocks, scaled to unit diagonal,
    and the scale ``s`` (T, G b): :func:`sim.lsq.group_solve.dense` then ``scaled``."""
    T, n_p, b = blocks.shape[:3]
    n = st.n_groups * b
    N, s = np.empty((T, n, n)), np.empty((T, n))
    ix = st.kernel_index
    compiled(_dense_scaled)(_c(blocks), ix["pg1"], ix["pg2"], N, s)
    return N, s


def chol_vec(L: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Solve ``L L' x = y`` for ``L`` (T, n, n) lower triangular, ``y`` (T, n)."""
    x = np.empty(y.shape)
    compiled(_chol_vec)(_c(L), _c(y), x)
    return x


def chol_inv(L: np.ndarray) -> np.ndarray:
    """``(L L')^-1`` (T, n, n) for ``L`` (T, n, n) lower triangular: ``L^-1`` by rows, then
    ``L^-T L^-1`` (a third of the work of substituting the identity)."""
    Q = np.empty(L.shape)
    compiled(_chol_inv)(_c(L), Q)
    return Q


def residual_cofactors(st, Q, F, Ninv, Jg, Jp, w, points: np.ndarray) -> np.ndarray:
    """Diagonal of ``Q_vv`` (T, K, m) for the observations of ``points`` (indices), NaN
    elsewhere and where the weight is zero; ``Q`` (T, G b, G b) the group cofactors."""
    ix = st.kernel_index
    out = np.full(w.shape, np.nan)
    T, K, d, b = F.shape
    kernel = compiled(_residual_cofactors, D_POINT=d, B_GROUP=b, M_ROWS=Jg.shape[2])
    kernel(
        _c(Q),
        _c(F),
        _c(Ninv),
        _c(Jg),
        _c(Jp),
        _c(w),
        ix["og"],
        ix["op"],
        np.asarray(points, np.int64),
        ix["pstart"],
        ix["pobs"],
        out,
    )
    return out
