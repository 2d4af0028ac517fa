"""Compiled reduced normals of the P-position range model (:class:`sim.instruments.ranges.positions.RangeModel`).

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968). The reading of station ``k`` at point ``j``,
``r = sqrt(d^2 - b) - alpha`` (mm), touches only the point ``x_j, y_j``, the station
``X_k, Y_k``, ``alpha`` and ``b``; with ``u`` the unit vector station -> point and
``g = 1 / (2 q)`` its Jacobian rows are ``[u]`` (point) and ``[-u | -1 | -g]`` (station,
alpha, b). Two compiled passes over the observations, one trial after another, never build a
Jacobian:

1. :func:`point_normals`: each point's 2 x 2 normal block ``Npp_j = sum_k u u'`` and
   ``up_j = sum_k u r``; the engine then inverts the blocks under its one scaled singularity
   rule (:func:`sim.lsq.normals.inv_blocks`);
2. :func:`eliminate`: the normals of the ``2P + 2`` globals (``X_1, Y_1, ..., alpha, b``)
   with every point eliminated (Brown's reduced normals): ``Nbar = Ngg - sum_j Npg_j' K_j``,
   ``ubar = ug - sum_j K_j' up_j`` with ``K_j = Ninv_j Npg_j``, and ``dp0_j = Ninv_j up_j``
   (one compiled pass: each point's ``Npg_j`` is formed in a small scratch block, its
   ``K_j`` stored, and ``Npg_j' K_j`` taken from ``Nbar`` above the diagonal at once).

The same quantities as :func:`sim.lsq.normals.reduce` on the dense Jacobian, to rounding (a
test holds them to 1e-12 relative). Without numba, or with ``SIM_NO_JIT`` set
(:data:`AVAILABLE` false), the caller uses the NumPy blocks of
:meth:`sim.instruments.ranges.positions.RangeModel.normal_blocks` instead.
"""

from __future__ import annotations

import os

import numpy as np

try:
    from numba import njit

    AVAILABLE = not os.environ.get("SIM_NO_JIT")
except ImportError:  # pragma: no cover - the NumPy blocks are used instead
    AVAILABLE = False

__all__ = ["AVAILABLE", "point_normals", "eliminate"]


def _unit(px, py, sx, sy, b):  # pragma: no cover - compiled
    dx = px - sx
    dy = py - sy
    q = np.sqrt(max(dx * dx + dy * dy - b, 1e-300))
    return dx / q, dy / q, q


def _point_normals(pts, S, th, r_obs, has_r, Npp, up):  # pragma: no cover - compiled
    T, n, _ = pts.shape
    P = S.shape[1]
    for t in range(T):
        alpha, b = th[t, 2 * P], th[t, 2 * P + 1]
        for j in range(n):
            a00 = a01 = a11 = u0 = u1 = 0.0
            for k in range(P):
                ux, uy, q = _unit(pts[t, j, 0], pts[t, j, 1], S[t, k, 0], S[t, k, 1], b)
                a00 += ux * ux
                a01 += ux * uy
                a11 += uy * uy
                if has_r:
                    r = r_obs[t, j, k] - (q - alpha)
                    u0 += ux * r
                    u1 += uy * r
            Npp[t, j, 0, 0] = a00
            Npp[t, j, 0, 1] = a01
            Npp[t, j, 1, 0] = a01
            Npp[t, j, 1, 1] = a11
            up[t, j, 0] = u0
            up[t, j, 1] = u1


def _eliminate(pts, S, th, r_obs, has_r, Ninv, up, K, Ngg, ubar, dp0):  # pragma: no cover
    T, n, _ = pts.shape
    P = S.shape[1]
    m = 2 * P + 2
    A, B = 2 * P, 2 * P + 1
    G = np.empty((2, m))
    for t in range(T):
        alpha, b = th[t, A], th[t, B]
        N = Ngg[t]
        u = ubar[t]
        N[:, :] = 0.0
        u[:] = 0.0
        for j in range(n):
            G[:, :] = 0.0
            for k in range(P):
                ux, uy, q = _unit(pts[t, j, 0], pts[t, j, 1], S[t, k, 0], S[t, k, 1], b)
                g = 0.5 / q
                r = r_obs[t, j, k] - (q - alpha) if has_r else 0.0
                X, Y = 2 * k, 2 * k + 1
                # Npg_j (Jp' Jg of this reading) and the globals' own normals Ngg, ug
                G[0, X] -= ux * ux
                G[0, Y] -= ux * uy
                G[1, X] -= ux * uy
                G[1, Y] -= uy * uy
                G[0, A] -= ux
                G[1, A] -= uy
                G[0, B] -= g * ux
                G[1, B] -= g * uy
                N[X, X] += ux * ux
                N[X, Y] += ux * uy
                N[Y, Y] += uy * uy
                N[X, A] += ux
                N[Y, A] += uy
                N[X, B] += g * ux
                N[Y, B] += g * uy
                N[A, A] += 1.0
                N[A, B] += g
                N[B, B] += g * g
                u[X] -= ux * r
                u[Y] -= uy * r
                u[A] -= r
                u[B] -= g * r
            n00, n01, n10, n11 = (
                Ninv[t, j, 0, 0],
                Ninv[t, j, 0, 1],
                Ninv[t, j, 1, 0],
                Ninv[t, j, 1, 1],
            )
            up0, up1 = up[t, j, 0], up[t, j, 1]
            dp0[t, j, 0] = n00 * up0 + n01 * up1
            dp0[t, j, 1] = n10 * up0 + n11 * up1
            Kj = K[t, j]
            for c in range(m):
                k0 = n00 * G[0, c] + n01 * G[1, c]
                k1 = n10 * G[0, c] + n11 * G[1, c]
                Kj[0, c] = k0
                Kj[1, c] = k1
                u[c] -= k0 * up0 + k1 * up1
            for c in range(m):  # Nbar = Ngg - sum_j Npg_j' K_j, above the diagonal
                g0, g1 = G[0, c], G[1, c]
                for e in range(c, m):
                    N[c, e] -= g0 * Kj[0, e] + g1 * Kj[1, e]
        for c in range(m):  # filled above the diagonal only: mirror
            for e in range(c):
                N[c, e] = N[e, c]


if AVAILABLE:
    _unit = njit(cache=True, inline="always")(_unit)
    _point_normals = njit(cache=True, error_model="numpy")(_point_normals)
    _eliminate = njit(cache=True, error_model="numpy")(_eliminate)


def _args(points, theta, r_obs):
    P = (theta.shape[1] - 2) // 2
    S = np.ascontiguousarray(theta[:, : 2 * P].reshape(-1, P, 2))
    has_r = r_obs is not None
    r = np.ascontiguousarray(r_obs, dtype=float) if has_r else np.zeros((1, 1, 1))
    return np.ascontiguousarray(points, dtype=float), S, np.ascontiguousarray(theta), r, has_r


def point_normals(points: np.ndarray, theta: np.ndarray, r_obs: np.ndarray | None):
    """``Npp`` (T, n, 2, 2) and ``up`` (T, n, 2) at ``points`` (T, n, 2) mm, ``theta``
    (T, 2P + 2) (``X_1, Y_1, ..., alpha, b``), readings ``r_obs`` (T, n, P) mm or None."""
    pts, S, th, r, has_r = _args(points, theta, r_obs)
    T, n, _ = pts.shape
    Npp, up = np.empty((T, n, 2, 2)), np.empty((T, n, 2))
    _point_normals(pts, S, th, r, has_r, Npp, up)
    return Npp, up


def eliminate(points, theta, r_obs, Ninv: np.ndarray, up: np.ndarray):
    """``(K (T, n, 2, 2P+2), Nbar (T, 2P+2, 2P+2), ubar (T, 2P+2), dp0 (T, n, 2))`` of all
    ``2P + 2`` globals, the points eliminated with the inverse blocks ``Ninv``."""
    pts, S, th, r, has_r = _args(points, theta, r_obs)
    T, n, _ = pts.shape
    m = th.shape[1]
    K, Nbar = np.empty((T, n, 2, m)), np.empty((T, m, m))
    ubar, dp0 = np.empty((T, m)), np.empty((T, n, 2))
    _eliminate(
        pts,
        S,
        th,
        r,
        has_r,
        np.ascontiguousarray(Ninv),
        np.ascontiguousarray(up),
        K,
        Nbar,
        ubar,
        dp0,
    )
    return K, Nbar, ubar, dp0
