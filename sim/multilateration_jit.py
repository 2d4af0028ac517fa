"""Compiled Gauss-Newton kernel for Brown's multilateration (optional, via numba).

The same model, parameterisation and reduction as the NumPy engine in
:mod:`sim.multilateration` (seed ``004_f5bd9e86c308241f.txt``): ranges
``r = sqrt(d^2 - b) - alpha`` with ``b = beta^2``, Brown's datum, the 2x2 point blocks
eliminated per point (reduced normal equations, Brown's EMBET), a scaled Cholesky solve of
the p x p reduced normals (p <= 7), convergence when the largest correction -- or the
remaining error estimated from the observed contraction, rho / (1 - rho) x correction with
rho the ratio of the last two corrections -- is below the tolerance. No Python runs per
trial: the kernel is compiled, and it adjusts ``LANES`` trials at a time in lock-step with
the trial axis innermost, so the compiler turns each sweep over the trials into SIMD
instructions (AVX on x86). Each trial's arithmetic is the scalar algorithm's, operation for
operation, so the results are bit-identical whatever the lane width; a test checks this.
The NumPy engine stays the reference implementation and the tests require both to agree.

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

__all__ = ["AVAILABLE", "LANES", "gauss_newton"]

LANES = 64  # trials per SIMD block; 8 or 16 leave the sweeps scalar (see make bench)
_LANE_BYTES = 216  # bytes of lane arrays per point and lane (R, X, Y, K, Ninv, up, D)
_MAX_LANE_MEMORY = 256 * 2**20
W = 1  # the lane width the kernel is compiled with; bound per variant in _compile


def _lane_stations(TH, Sx, Sy):  # pragma: no cover
    """Station coordinates (4, lanes) from the globals (7, lanes) in Brown's datum
    (x1 = x3 = 0, y4 = -y2)."""
    for w in range(TH.shape[1]):
        Sx[0, w] = 0.0
        Sy[0, w] = TH[0, w]
        Sx[1, w] = TH[1, w]
        Sy[1, w] = TH[2, w]
        Sx[2, w] = 0.0
        Sy[2, w] = TH[3, w]
        Sx[3, w] = TH[4, w]
        Sy[3, w] = -TH[2, w]


def _kernel(r_obs, theta, pts, p, tol, max_iter, rcond, rcond_g, status, iters, idx, cnt, res,
            ssq):  # pragma: no cover
    """Gauss-Newton on blocks of ``W`` trials (``W`` a compile-time constant, see
    :func:`_compile`). Every array below keeps the lane (trial) axis last, so each
    ``for w in range(W)`` loop is one SIMD-vectorisable sweep over the block's trials; the
    arithmetic of each lane is exactly the scalar algorithm's (no reassociation, no FMA
    contraction), so the result does not depend on ``W`` or on a trial's position. A block
    shorter than ``W`` is padded with copies of its first trial, which are computed but
    never updated or written back. A lane stops (and is no longer updated) when it converges,
    turns singular or non-finite; the block stops when no lane is active.
    """
    T, n, _ = r_obs.shape
    R = np.empty((n, 4, W))
    X = np.empty((n, W))
    Y = np.empty((n, W))
    TH = np.empty((7, W))
    Sx = np.empty((4, W))
    Sy = np.empty((4, W))
    N = np.empty((7, 7, W))
    u = np.empty((7, W))
    Npg = np.empty((2, 7, W))
    K = np.empty((n, 2, 7, W))
    Ninv = np.empty((n, 3, W))
    up = np.empty((n, 2, W))
    D = np.empty((n, 2, W))
    UX = np.empty(W)
    UY = np.empty(W)
    IQ = np.empty(W)
    E = np.empty(W)
    G = np.empty((4, W))
    A = np.empty(W)
    B = np.empty(W)
    C = np.empty(W)
    U0 = np.empty(W)
    U1 = np.empty(W)
    L = np.empty((7, 7, W))
    dsc = np.empty((7, W))
    dg = np.empty((7, W))
    V = np.empty(W)
    STEP = np.empty(W)
    FIN = np.empty(W)
    PREV = np.empty(W)
    sing = np.empty(W, np.bool_)
    act = np.empty(W, np.bool_)
    upd = np.empty(W, np.bool_)
    st = np.empty(W, np.int8)
    for t0 in range(0, T, W):
        wn = min(W, T - t0)
        for j in range(n):
            for k in range(4):
                for w in range(W):
                    R[j, k, w] = r_obs[t0 + (w if w < wn else 0), j, k]
            for w in range(W):
                X[j, w] = pts[t0 + (w if w < wn else 0), j, 0]
                Y[j, w] = pts[t0 + (w if w < wn else 0), j, 1]
        for r in range(7):
            for w in range(W):
                TH[r, w] = theta[t0 + (w if w < wn else 0), r]
        for w in range(W):
            act[w] = w < wn
            st[w] = 1
            PREV[w] = np.nan
        nact = wn
        for it in range(1, max_iter + 1):
            if nact == 0:
                break
            _lane_stations(TH, Sx, Sy)
            for w in range(W):
                sing[w] = False
            for r in range(p):
                for w in range(W):
                    u[r, w] = 0.0
                for s in range(p):
                    for w in range(W):
                        N[r, s, w] = 0.0
            for j in range(n):
                for w in range(W):
                    A[w] = 0.0
                    B[w] = 0.0
                    C[w] = 0.0
                    U0[w] = 0.0
                    U1[w] = 0.0
                for r in range(p):
                    for w in range(W):
                        Npg[0, r, w] = 0.0
                        Npg[1, r, w] = 0.0
                for k in range(4):
                    for w in range(W):
                        dx = X[j, w] - Sx[k, w]
                        dy = Y[j, w] - Sy[k, w]
                        q = np.sqrt(max(dx * dx + dy * dy - TH[6, w], 1e-300))
                        iq = 1.0 / q
                        ux = dx * iq
                        uy = dy * iq
                        e = R[j, k, w] - (q - TH[5, w])
                        A[w] += ux * ux
                        B[w] += ux * uy
                        C[w] += uy * uy
                        U0[w] += ux * e
                        U1[w] += uy * e
                        UX[w] = ux
                        UY[w] = uy
                        IQ[w] = iq
                        E[w] = e
                    m = cnt[k]
                    if m == 0:
                        continue
                    nst = 2 if (k == 1 or k == 3) else 1
                    for w in range(W):
                        if k == 0 or k == 2:
                            G[0, w] = -UY[w]
                        elif k == 1:
                            G[0, w] = -UX[w]
                            G[1, w] = -UY[w]
                        else:
                            G[0, w] = UY[w]
                            G[1, w] = -UX[w]
                        G[nst, w] = -1.0
                        G[nst + 1, w] = -0.5 * IQ[w]
                    for i in range(m):
                        r = idx[k, i]
                        for w in range(W):
                            Npg[0, r, w] += UX[w] * G[i, w]
                            Npg[1, r, w] += UY[w] * G[i, w]
                            u[r, w] += G[i, w] * E[w]
                        for i2 in range(i, m):
                            r2 = idx[k, i2]
                            for w in range(W):
                                N[r, r2, w] += G[i, w] * G[i2, w]
                for w in range(W):
                    a = A[w]
                    c = C[w]
                    bb = B[w]
                    det = a * c - bb * bb
                    if not det > rcond * (a + c) * (a + c):
                        sing[w] = True
                        det = 1.0
                    Ninv[j, 0, w] = c / det
                    Ninv[j, 1, w] = -bb / det
                    Ninv[j, 2, w] = a / det
                    up[j, 0, w] = U0[w]
                    up[j, 1, w] = U1[w]
                for r in range(p):
                    for w in range(W):
                        k0 = Ninv[j, 0, w] * Npg[0, r, w] + Ninv[j, 1, w] * Npg[1, r, w]
                        k1 = Ninv[j, 1, w] * Npg[0, r, w] + Ninv[j, 2, w] * Npg[1, r, w]
                        K[j, 0, r, w] = k0
                        K[j, 1, r, w] = k1
                        u[r, w] -= k0 * U0[w] + k1 * U1[w]
                    for s in range(r, p):
                        for w in range(W):
                            N[r, s, w] -= K[j, 0, r, w] * Npg[0, s, w] + K[j, 1, r, w] * Npg[1, s, w]
            # scaled Cholesky of the reduced normals, lane by lane (a failed pivot marks the
            # lane singular and is replaced by 1 so the other lanes go on)
            for r in range(p):
                for w in range(W):
                    dsc[r, w] = np.sqrt(abs(N[r, r, w])) + 1e-300
            for r in range(p):
                for s in range(r + 1):
                    for w in range(W):
                        V[w] = N[s, r, w] / (dsc[r, w] * dsc[s, w])
                    for m in range(s):
                        for w in range(W):
                            V[w] -= L[r, m, w] * L[s, m, w]
                    if r == s:
                        for w in range(W):
                            if V[w] > rcond_g:
                                L[r, r, w] = np.sqrt(V[w])
                            else:
                                sing[w] = True
                                L[r, r, w] = 1.0
                    else:
                        for w in range(W):
                            L[r, s, w] = V[w] / L[s, s, w]
            for r in range(p):
                for w in range(W):
                    V[w] = u[r, w] / dsc[r, w]
                for m in range(r):
                    for w in range(W):
                        V[w] -= L[r, m, w] * dg[m, w]
                for w in range(W):
                    dg[r, w] = V[w] / L[r, r, w]
            for r in range(p - 1, -1, -1):
                for w in range(W):
                    V[w] = dg[r, w]
                for m in range(r + 1, p):
                    for w in range(W):
                        V[w] -= L[m, r, w] * dg[m, w]
                for w in range(W):
                    dg[r, w] = V[w] / L[r, r, w]
            for w in range(W):
                STEP[w] = 0.0
                FIN[w] = 0.0
            for r in range(p):
                for w in range(W):
                    dg[r, w] /= dsc[r, w]
                    STEP[w] = max(STEP[w], abs(dg[r, w]))
                    FIN[w] += 0.0 * dg[r, w]  # NaN if any correction is not finite
            for j in range(n):
                for w in range(W):
                    V[w] = Ninv[j, 0, w] * up[j, 0, w] + Ninv[j, 1, w] * up[j, 1, w]
                    UX[w] = Ninv[j, 1, w] * up[j, 0, w] + Ninv[j, 2, w] * up[j, 1, w]
                for r in range(p):
                    for w in range(W):
                        V[w] -= K[j, 0, r, w] * dg[r, w]
                        UX[w] -= K[j, 1, r, w] * dg[r, w]
                for w in range(W):
                    D[j, 0, w] = V[w]
                    D[j, 1, w] = UX[w]
                    STEP[w] = max(STEP[w], abs(V[w]), abs(UX[w]))
                    FIN[w] += 0.0 * V[w] + 0.0 * UX[w]
            for w in range(W):
                ok = act[w]
                if ok and sing[w]:
                    st[w] = 2
                    ok = False
                elif ok and not FIN[w] == 0.0:
                    st[w] = 3
                    ok = False
                upd[w] = ok
                if not ok:
                    act[w] = False
            for j in range(n):
                for w in range(W):
                    if upd[w]:
                        X[j, w] += D[j, 0, w]
                        Y[j, w] += D[j, 1, w]
            for r in range(p):
                for w in range(W):
                    if upd[w]:
                        TH[r, w] += dg[r, w]
            nact = 0
            for w in range(W):
                if upd[w]:
                    iters[t0 + w] = it
                    step = STEP[w]
                    rho = step / PREV[w]
                    if step < tol or (rho < 0.5 and rho / (1.0 - rho) * step < tol):
                        st[w] = 0
                        act[w] = False
                    else:
                        nact += 1
                    PREV[w] = step
        # residuals at the final values; write the lanes back
        _lane_stations(TH, Sx, Sy)
        for w in range(W):
            V[w] = 0.0
        for j in range(n):
            for k in range(4):
                for w in range(W):
                    dx = X[j, w] - Sx[k, w]
                    dy = Y[j, w] - Sy[k, w]
                    v = R[j, k, w] - (np.sqrt(max(dx * dx + dy * dy - TH[6, w], 1e-300))
                                      - TH[5, w])
                    V[w] += v * v
                    if w < wn:
                        res[t0 + w, j, k] = v
        for w in range(wn):
            ssq[t0 + w] = V[w]
            status[t0 + w] = st[w]
            for j in range(n):
                pts[t0 + w, j, 0] = X[j, w]
                pts[t0 + w, j, 1] = Y[j, w]
            for r in range(7):
                theta[t0 + w, r] = TH[r, w]


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


def _compile(fn, name: str, width: int):
    """``fn`` compiled with the global ``W`` frozen to ``width`` (numba treats globals as
    compile-time constants), cached on disk under its own name."""
    import types

    glb = dict(fn.__globals__, W=width)
    f = types.FunctionType(fn.__code__, glb, name, fn.__defaults__, fn.__closure__)
    f.__qualname__ = name
    # error_model="numpy": no ZeroDivisionError branches, which would block vectorisation
    return njit(cache=True, error_model="numpy")(f)


if AVAILABLE:
    _lane_stations = njit(cache=True)(_lane_stations)
    _kernel_lanes = _compile(_kernel, "_kernel_lanes", LANES)
    _kernel_one = _compile(_kernel, "_kernel_one", 1)
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
    kernel = _kernel_lanes if use_lanes(T, n) else _kernel_one
    kernel(r_obs, theta, pts, int(p), float(tol), int(max_iter), float(rcond), float(rcond_g),
           status, iters, idx, cnt, res, ssq)
    return pts, status, iters, res, ssq


def use_lanes(trials: int, points: int) -> bool:
    """The SIMD kernel for batches of at least half a block whose lane arrays fit in
    ``_MAX_LANE_MEMORY`` (about 19,000 points); one trial at a time otherwise."""
    return 2 * trials >= LANES and points * LANES * _LANE_BYTES <= _MAX_LANE_MEMORY


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
