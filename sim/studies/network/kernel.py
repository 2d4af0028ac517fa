"""Compiled residuals and gradient of a network's observations for the sparse Monte Carlo.

One pass over trials x observations computes each reading's computed value (the model of
:func:`sim.studies.network.model.computed`: distances ``(1 + s) sqrt(d^2 - beta^2) - alpha``
in mm, directions and angles in rad, coordinate differences and coordinates in mm), the
residual observed minus computed (angles wrapped to (-pi, pi]) and adds ``J' W r`` into the
gradient of the free unknowns -- without the Jacobian array, which for a network of thousands
of points and a chunk of trials would be the largest array of the run. Runs compiled by numba
(:func:`sim.lsq.compile.compiled`); without it (``SIM_NO_JIT``) its NumPy twin
:func:`residual_gradient_numpy` runs: the Jacobian on the pattern's slots
(:func:`sim.studies.network.model.jacobian_sparse`) and ``J' W r`` as one sparse product. The
bench row ``network_gradient`` times the two (``docs/benchmark.md``). Seed: Brown 1968 (``004``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse

from sim.lsq import compile as jit
from sim.studies.network.definition import Network
from sim.studies.network.model import jacobian_sparse, pattern

__all__ = ["residual_gradient", "residual_gradient_numpy"]


def _kernel(
    theta, obs, kind, ii, jj, kk, oset, n2, ic, isc, beta2, w, fpos, r, g
):  # pragma: no cover - compiled
    """Residuals ``r`` (T, m) and gradient ``g`` (T, p) (zeroed here) at ``theta`` (T, q)."""
    T, m = obs.shape
    two_pi = 2.0 * math.pi
    d = np.zeros(9)  # derivatives by x_i, y_i, x_j, y_j, x_k, y_k, orientation, constant, scale
    for t in range(T):
        g[t, :] = 0.0
        alpha = theta[t, ic]
        f = 1.0 + 1e-6 * theta[t, isc]
        for row in range(m):
            kd, i, j, k = kind[row], ii[row], jj[row], kk[row]
            xi, yi = theta[t, 2 * i], theta[t, 2 * i + 1]
            d[:] = 0.0
            if kd == 5:
                val, d[0] = xi, 1.0
            elif kd == 6:
                val, d[1] = yi, 1.0
            else:
                dx, dy = theta[t, 2 * j] - xi, theta[t, 2 * j + 1] - yi
                d2 = dx * dx + dy * dy
                if kd == 0:
                    s = math.sqrt(max(d2 - beta2, 0.0))
                    val = f * s - alpha
                    gx, gy = f * dx / s, f * dy / s
                    d[0], d[1], d[2], d[3], d[7], d[8] = -gx, -gy, gx, gy, -1.0, 1e-6 * s
                elif kd == 1:
                    val = math.atan2(dy, dx) - theta[t, n2 + oset[row]]
                    gx, gy = -dy / d2, dx / d2
                    d[0], d[1], d[2], d[3], d[6] = -gx, -gy, gx, gy, -1.0
                elif kd == 2:
                    ex, ey = theta[t, 2 * k] - xi, theta[t, 2 * k + 1] - yi
                    val = (math.atan2(ey, ex) - math.atan2(dy, dx)) % two_pi
                    gx, gy = dy / d2, -dx / d2
                    e2 = ex * ex + ey * ey
                    hx, hy = -ey / e2, ex / e2
                    d[0], d[1], d[2], d[3] = -(gx + hx), -(gy + hy), gx, gy
                    d[4], d[5] = hx, hy
                elif kd == 3:
                    val, d[0], d[2] = dx, -1.0, 1.0
                else:
                    val, d[1], d[3] = dy, -1.0, 1.0
            res = obs[t, row] - val
            if kd == 1 or kd == 2:
                res = (res + math.pi) % two_pi - math.pi
            r[t, row] = res
            wr = w[row] * res
            cols = (2 * i, 2 * i + 1, 2 * j, 2 * j + 1, 2 * k, 2 * k + 1, n2 + oset[row], ic, isc)
            for a in range(9):
                if d[a] != 0.0:
                    fp = fpos[cols[a]]
                    if fp >= 0:
                        g[t, fp] += d[a] * wr


def residual_gradient(net: Network, fpos: np.ndarray, theta: np.ndarray, obs: np.ndarray):
    """Residuals ``r`` (T, m) and the gradient ``A' W r`` (T, p) at ``theta`` (T, q) of the
    readings ``obs`` (T, m); ``fpos`` (q,) the position of each global among the free
    unknowns (-1: held)."""
    if not jit.available():
        return residual_gradient_numpy(net, fpos, theta, obs)
    T = theta.shape[0]
    p = int(fpos.max(initial=-1)) + 1
    r, g = np.empty((T, net.m)), np.empty((T, p))
    jit.compiled(_kernel)(
        np.ascontiguousarray(theta, dtype=np.float64),
        np.ascontiguousarray(obs, dtype=np.float64),
        net.kind.astype(np.int64),
        net.i.astype(np.int64),
        np.where(net.j >= 0, net.j, 0).astype(np.int64),
        np.where(net.k >= 0, net.k, 0).astype(np.int64),
        np.where(net.oset >= 0, net.oset, 0).astype(np.int64),
        2 * net.n,
        net.i_constant,
        net.i_scale,
        float(net.offset_mm**2),
        1.0 / net.sigma**2,
        np.asarray(fpos, np.int64),
        r,
        g,
    )
    return r, g


def residual_gradient_numpy(net: Network, fpos: np.ndarray, theta: np.ndarray, obs: np.ndarray):
    """:func:`residual_gradient` in NumPy: ``r = obs - computed`` (angles wrapped to
    (-pi, pi]) and ``g = J' W r`` with the Jacobian on the pattern's slots (T, m, s) summed
    into the free unknowns by one sparse product."""
    theta = np.asarray(theta, np.float64)
    val, vals = jacobian_sparse(net, theta)
    r = np.asarray(obs, np.float64) - val
    ang = np.isin(net.kind, (1, 2))
    r[:, ang] = (r[:, ang] + math.pi) % (2.0 * math.pi) - math.pi
    cols = pattern(net)
    fc = np.where(cols >= 0, np.asarray(fpos, np.int64)[np.maximum(cols, 0)], -1).ravel()
    p = int(np.max(fpos, initial=-1)) + 1
    use = np.flatnonzero(fc >= 0)
    S = sparse.csr_matrix((np.ones(use.size), (use, fc[use])), shape=(fc.size, p))
    wjr = (vals * (r / net.sigma**2)[..., None]).reshape(theta.shape[0], -1)
    return r, np.asarray((S.T @ wjr.T).T)
