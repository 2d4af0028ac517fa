"""Source of the compiled Gauss-Newton kernel of Brown's multilateration (numba-compilable
Python; :mod:`sim.instruments.ranges.multilateration_jit` compiles it by
:func:`sim.lsq.compile.compiled` and runs it).

Seed ``004_f5bd9e86c308241f.txt`` (Brown): ranges ``r = sqrt(d^2 - b) - alpha`` (mm) with
``b = beta^2``, Brown's datum (x1 = x3 = 0, y4 = -y2), the 2x2 point blocks eliminated per
point (reduced normal equations), a scaled Cholesky solve of the p x p reduced normals. It
equals :func:`sim.lsq.gauss_newton` on :class:`sim.instruments.ranges.positions.RangeModel`
with Brown's layout (the NumPy engine: :func:`sim.lsq.normals.reduced_normals`, then
:func:`sim.lsq.normals.bordered_solve`), trial by trial, to rounding. Singularity is the
engine's one rule: a point block is singular when :func:`sim.lsq.normals.block2_rcond` is
not above ``rcond`` (exact); the reduced normals are regular where the lower bound
``1 / (||C||_F ||L^-1||_F^2)`` of the scaled matrix's eigenvalue ratio is above ``4 rcond``,
else the trial is left *undecided* (status :data:`UNDECIDED`) and the caller runs it on the
NumPy engine, whose exact rule decides. The functions are plain loops over scalars, written
for the compiler: every lane array keeps the trial axis last, and ``W`` (the lane width) is an
argument, so one compiled kernel serves every width (a width frozen as a compile-time
constant ran no faster and cost a second compile of about 8 s per process on a cold cache:
measured 2026-11-27, 4,000 trials of 25 points). Not meant to be called uncompiled except in
a debugger (it is correct, but slow).
"""

from __future__ import annotations

import numpy as np

from sim.lsq.normals import block2_rcond  # compiled with the kernel (its helper)

__all__ = ["UNDECIDED"]  # the kernels are compiled and run by multilateration_jit

#: status of a trial whose reduced normals the kernel's bound could not prove regular
UNDECIDED = 4


def _lane_stations(TH, Sx, Sy):  # pragma: no cover
    """Station coordinates (4, lanes) from the globals (7, lanes) in Brown's datum
    (x1 = x3 = 0, y4 = -y2): :func:`sim.instruments.ranges.multilateration.stations`."""
    for w in range(TH.shape[1]):
        Sx[0, w] = 0.0
        Sy[0, w] = TH[0, w]
        Sx[1, w] = TH[1, w]
        Sy[1, w] = TH[2, w]
        Sx[2, w] = 0.0
        Sy[2, w] = TH[3, w]
        Sx[3, w] = TH[4, w]
        Sy[3, w] = -TH[2, w]


def _kernel(
    r_obs, theta, pts, p, tol, max_iter, rcond, status, iters, idx, cnt, res, ssq, W
):  # pragma: no cover
    """:func:`sim.lsq.gauss_newton` of Brown's range model on blocks of ``W`` trials (the lane
    width, an argument). Every array below keeps the lane (trial) axis last, so each
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
    Linv = np.empty((7, 7, W))
    FRO = np.empty(W)
    LINV2 = np.empty(W)
    und = np.empty(W, np.bool_)
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
                und[w] = False
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
                    if not block2_rcond(a, bb, bb, c) > rcond:  # the engine's rule
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
                            N[r, s, w] -= (
                                K[j, 0, r, w] * Npg[0, s, w] + K[j, 1, r, w] * Npg[1, s, w]
                            )
            # scaled Cholesky C = L L' of the reduced normals, lane by lane (a failed pivot
            # leaves the lane undecided and is replaced by 1 so the other lanes go on)
            for r in range(p):
                for w in range(W):
                    dsc[r, w] = np.sqrt(abs(N[r, r, w])) + 1e-300
            for w in range(W):
                FRO[w] = 0.0
                LINV2[w] = 0.0
            for r in range(p):
                for s in range(r + 1):
                    for w in range(W):
                        V[w] = N[s, r, w] / (dsc[r, w] * dsc[s, w])
                        FRO[w] += (1.0 if r == s else 2.0) * V[w] * V[w]  # ||C||_F^2
                    for m in range(s):
                        for w in range(W):
                            V[w] -= L[r, m, w] * L[s, m, w]
                    if r == s:
                        for w in range(W):
                            if V[w] > 0.0:
                                L[r, r, w] = np.sqrt(V[w])
                            else:
                                und[w] = True
                                L[r, r, w] = 1.0
                    else:
                        for w in range(W):
                            L[r, s, w] = V[w] / L[s, s, w]
            # the engine's rule by its bound: lambda_min / lambda_max of C is at least
            # 1 / (||C||_F ||L^-1||_F^2); L^-1 column by column
            for s in range(p):
                for w in range(W):
                    Linv[s, s, w] = 1.0 / L[s, s, w]
                    LINV2[w] += Linv[s, s, w] * Linv[s, s, w]
                for r in range(s + 1, p):
                    for w in range(W):
                        V[w] = 0.0
                    for m in range(s, r):
                        for w in range(W):
                            V[w] -= L[r, m, w] * Linv[m, s, w]
                    for w in range(W):
                        Linv[r, s, w] = V[w] / L[r, r, w]
                        LINV2[w] += Linv[r, s, w] * Linv[r, s, w]
            if p:
                for w in range(W):
                    if not 1.0 / (np.sqrt(FRO[w]) * LINV2[w]) > 4.0 * rcond:
                        und[w] = True
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
                elif ok and und[w]:
                    st[w] = UNDECIDED
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
                    v = R[j, k, w] - (np.sqrt(max(dx * dx + dy * dy - TH[6, w], 1e-300)) - TH[5, w])
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
    :func:`sim.instruments.ranges.multilateration.initial_points`), per trial and point."""
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
