"""Compiled Gauss-Newton kernel for Brown's multilateration (optional, via numba).

The same model, parameterisation and reduction as the NumPy engine in
:mod:`sim.multilateration` (seed ``004_f5bd9e86c308241f.txt``): ranges
``r = sqrt(d^2 - b) - alpha`` with ``b = beta^2``, Brown's datum, the 2x2 point blocks
eliminated per point (reduced normal equations, Brown's EMBET), a scaled Cholesky solve of
the p x p reduced normals (p <= 7), convergence when the largest correction -- or the
remaining error estimated from the observed contraction, rho / (1 - rho) x correction with
rho the ratio of the last two corrections -- is below the tolerance. The loop over trials is compiled, so no Python runs per trial; the NumPy engine
stays the reference implementation and the tests require both to agree.

Status codes as in :class:`sim.multilateration.AdjustResult`: 0 converged, 1 iteration limit,
2 singular normals (a 2x2 point block with det below ``rcond`` of its scale, or a squared
Cholesky pivot of the scaled reduced normals below ``rcond_g`` = 1e-10, i.e. a condition
number of about 1e10: ten digits lost), 3 non-finite corrections.
"""
from __future__ import annotations

import numpy as np

try:
    from numba import njit
    AVAILABLE = True
except ImportError:  # pragma: no cover - the NumPy engine is used instead
    AVAILABLE = False

__all__ = ["AVAILABLE", "gauss_newton"]


def _kernel(r_obs, theta, pts, p, tol, max_iter, rcond, rcond_g, status, iters, idx, cnt, res,
            ssq):  # pragma: no cover
    T, n, _ = r_obs.shape
    Sx = np.empty(4)
    Sy = np.empty(4)
    g = np.empty(7)
    Npg = np.empty((n, 2, 7))
    K = np.empty((n, 2, 7))
    Ninv = np.empty((n, 3))
    up = np.empty((n, 2))
    N = np.empty((7, 7))
    L = np.empty((7, 7))
    u = np.empty(7)
    dg = np.empty(7)
    dsc = np.empty(7)
    for t in range(T):
        st = 1
        prev = np.nan  # no contraction estimate before two corrections
        for it in range(1, max_iter + 1):
            Sx[0] = 0.0
            Sy[0] = theta[t, 0]
            Sx[1] = theta[t, 1]
            Sy[1] = theta[t, 2]
            Sx[2] = 0.0
            Sy[2] = theta[t, 3]
            Sx[3] = theta[t, 4]
            Sy[3] = -theta[t, 2]
            alpha = theta[t, 5]
            b2 = theta[t, 6]
            for r in range(p):
                u[r] = 0.0
                for s in range(p):
                    N[r, s] = 0.0
            singular = False
            for j in range(n):
                a = 0.0
                bb = 0.0
                c = 0.0
                u0 = 0.0
                u1 = 0.0
                for r in range(p):
                    Npg[j, 0, r] = 0.0
                    Npg[j, 1, r] = 0.0
                for k in range(4):
                    dx = pts[t, j, 0] - Sx[k]
                    dy = pts[t, j, 1] - Sy[k]
                    q = np.sqrt(max(dx * dx + dy * dy - b2, 1e-300))
                    iq = 1.0 / q
                    ux = dx * iq
                    uy = dy * iq
                    e = r_obs[t, j, k] - (q - alpha)
                    a += ux * ux
                    bb += ux * uy
                    c += uy * uy
                    u0 += ux * e
                    u1 += uy * e
                    if p > 0:  # the station's nonzero Jacobian entries only
                        m = cnt[k]
                        if k == 0:
                            g[0] = -uy
                        elif k == 1:
                            g[0] = -ux
                            g[1] = -uy
                        elif k == 2:
                            g[0] = -uy
                        else:
                            g[0] = uy
                            g[1] = -ux
                        nst = 2 if (k == 1 or k == 3) else 1
                        g[nst] = -1.0
                        g[nst + 1] = -0.5 * iq
                        for i in range(m):
                            r = idx[k, i]
                            Npg[j, 0, r] += ux * g[i]
                            Npg[j, 1, r] += uy * g[i]
                            u[r] += g[i] * e
                            for i2 in range(i, m):  # idx rows are ascending: upper triangle
                                N[r, idx[k, i2]] += g[i] * g[i2]
                det = a * c - bb * bb
                if not det > rcond * (a + c) * (a + c):
                    singular = True
                    det = 1.0
                i00 = c / det
                i01 = -bb / det
                i11 = a / det
                Ninv[j, 0] = i00
                Ninv[j, 1] = i01
                Ninv[j, 2] = i11
                up[j, 0] = u0
                up[j, 1] = u1
                for r in range(p):  # K = Npp^-1 Npg; reduce the globals' normals
                    k0 = i00 * Npg[j, 0, r] + i01 * Npg[j, 1, r]
                    k1 = i01 * Npg[j, 0, r] + i11 * Npg[j, 1, r]
                    K[j, 0, r] = k0
                    K[j, 1, r] = k1
                    u[r] -= k0 * u0 + k1 * u1
                    for s in range(r, p):
                        N[r, s] -= k0 * Npg[j, 0, s] + k1 * Npg[j, 1, s]
            if p > 0 and not singular:  # scaled Cholesky of the reduced normals
                for r in range(p):
                    dsc[r] = np.sqrt(abs(N[r, r])) + 1e-300
                for r in range(p):
                    for s in range(r + 1):
                        v = N[s, r] / (dsc[r] * dsc[s])
                        for m in range(s):
                            v -= L[r, m] * L[s, m]
                        if r == s:
                            if not v > rcond_g:
                                singular = True
                                break
                            L[r, r] = np.sqrt(v)
                        else:
                            L[r, s] = v / L[s, s]
                    if singular:
                        break
                if not singular:
                    for r in range(p):  # forward, then back substitution
                        v = u[r] / dsc[r]
                        for m in range(r):
                            v -= L[r, m] * dg[m]
                        dg[r] = v / L[r, r]
                    for r in range(p - 1, -1, -1):
                        v = dg[r]
                        for m in range(r + 1, p):
                            v -= L[m, r] * dg[m]
                        dg[r] = v / L[r, r]
                    for r in range(p):
                        dg[r] /= dsc[r]
            if singular:
                st = 2
                break
            step = 0.0
            for r in range(p):
                step = max(step, abs(dg[r]))
            for j in range(n):
                d0 = Ninv[j, 0] * up[j, 0] + Ninv[j, 1] * up[j, 1]
                d1 = Ninv[j, 1] * up[j, 0] + Ninv[j, 2] * up[j, 1]
                for r in range(p):
                    d0 -= K[j, 0, r] * dg[r]
                    d1 -= K[j, 1, r] * dg[r]
                step = max(step, abs(d0), abs(d1))
                Npg[j, 0, 0] = d0  # reuse as scratch for the point corrections
                Npg[j, 1, 0] = d1
            if not np.isfinite(step):
                st = 3
                break
            for j in range(n):
                pts[t, j, 0] += Npg[j, 0, 0]
                pts[t, j, 1] += Npg[j, 1, 0]
            for r in range(p):
                theta[t, r] += dg[r]
            iters[t] = it
            rho = step / prev  # observed contraction: remaining error ~ rho / (1 - rho) * step
            if step < tol or (rho < 0.5 and rho / (1.0 - rho) * step < tol):
                st = 0
                break
            prev = step
        status[t] = st
        # residuals and the sum of their squares at the final values
        Sx[1] = theta[t, 1]
        Sx[3] = theta[t, 4]
        Sy[0] = theta[t, 0]
        Sy[1] = theta[t, 2]
        Sy[2] = theta[t, 3]
        Sy[3] = -theta[t, 2]
        vv = 0.0
        for j in range(n):
            for k in range(4):
                dx = pts[t, j, 0] - Sx[k]
                dy = pts[t, j, 1] - Sy[k]
                v = r_obs[t, j, k] - (np.sqrt(max(dx * dx + dy * dy - theta[t, 6], 1e-300))
                                      - theta[t, 5])
                res[t, j, k] = v
                vv += v * v
        ssq[t] = vv


def _start(r_obs, theta, pts):  # pragma: no cover
    """Linear trilateration from differences of squared range equations (as
    :func:`sim.multilateration.initial_points`), per trial and point."""
    T, n, _ = r_obs.shape
    S = np.empty((4, 2))
    A = np.empty((3, 2))
    for t in range(T):
        S[0, 0] = 0.0
        S[0, 1] = theta[t, 0]
        S[1, 0] = theta[t, 1]
        S[1, 1] = theta[t, 2]
        S[2, 0] = 0.0
        S[2, 1] = theta[t, 3]
        S[3, 0] = theta[t, 4]
        S[3, 1] = -theta[t, 2]
        s0 = S[0, 0] ** 2 + S[0, 1] ** 2
        for k in range(3):
            A[k, 0] = -2.0 * (S[k + 1, 0] - S[0, 0])
            A[k, 1] = -2.0 * (S[k + 1, 1] - S[0, 1])
        a = b = c = 0.0
        for k in range(3):
            a += A[k, 0] * A[k, 0]
            b += A[k, 0] * A[k, 1]
            c += A[k, 1] * A[k, 1]
        det = a * c - b * b
        for j in range(n):
            D0 = (r_obs[t, j, 0] + theta[t, 5]) ** 2 + theta[t, 6]
            u0 = 0.0
            u1 = 0.0
            for k in range(3):
                Dk = (r_obs[t, j, k + 1] + theta[t, 5]) ** 2 + theta[t, 6]
                rhs = Dk - D0 - (S[k + 1, 0] ** 2 + S[k + 1, 1] ** 2 - s0)
                u0 += A[k, 0] * rhs
                u1 += A[k, 1] * rhs
            pts[t, j, 0] = (c * u0 - b * u1) / det
            pts[t, j, 1] = (a * u1 - b * u0) / det


if AVAILABLE:
    _kernel = njit(cache=True)(_kernel)
    _start = njit(cache=True)(_start)


def gauss_newton(r_obs: np.ndarray, theta: np.ndarray, pts: np.ndarray | None, p: int,
                 tol: float, max_iter: int, rcond: float = 1e-13, rcond_g: float = 1e-10):
    """Run the compiled kernel in place on ``theta`` (T, 7) (and ``pts`` (T, n, 2); None:
    start from linear trilateration). Needs numba (:data:`AVAILABLE`).

    Returns ``(points, status, iterations, residuals, sum of squared residuals)``.
    """
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    r_obs = np.ascontiguousarray(r_obs, dtype=np.float64)
    T, n, _ = r_obs.shape
    if pts is None:
        pts = np.empty((T, n, 2))
        _start(r_obs, theta, pts)
    status = np.ones(T, np.int8)
    iters = np.zeros(T, np.int32)
    res = np.empty((T, n, 4))
    ssq = np.empty(T)
    idx, cnt = _sparsity(p)
    _kernel(r_obs, theta, pts, int(p), float(tol), int(max_iter), float(rcond), float(rcond_g),
            status, iters, idx, cnt, res, ssq)
    return pts, status, iters, res, ssq


def _sparsity(p: int):
    """Global indices touched by each station's readings (those < p), in the order the kernel
    fills ``g``: station coordinates, then alpha (5), then b (6)."""
    rows = ([0, 5, 6], [1, 2, 5, 6], [3, 5, 6], [2, 4, 5, 6])
    idx = np.zeros((4, 4), np.int64)
    cnt = np.zeros(4, np.int64)
    for k, r in enumerate(rows):
        keep = [g for g in r if g < p]
        idx[k, :len(keep)] = keep
        cnt[k] = len(keep)
    return idx, cnt
