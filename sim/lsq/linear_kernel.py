"""Compiled kernels of the linear least-squares routine (:mod:`sim.lsq.linear`), via numba.

Model, per trial ``t`` (``k`` right-hand sides sharing the design)::

    b_t = A x_t + v_t,   minimise v_t' W v_t,   x_t = (A' W A)^-1 A' W b_t

* :func:`shared_solve` -- the shared-design path: the one solution operator
  ``M = R^-1 Q' sqrt(W)`` (``p x m``, from the QR ``sqrt(W) A = Q R`` computed once for all
  trials) times every trial's right-hand sides, and ``v' W v`` of the residuals
  ``v = b - A x``, summed as they are formed and not stored (:class:`sim.lsq.linear.LinearFit`
  forms the residuals only when they are asked for). One pass over each trial's
  observations, which stay in the processor's cache, instead of the whole batch's
  transposed copies through memory.
* :func:`normal_solve` (:func:`solve_lanes`, :data:`LANES` trials at once) -- every
  trial's small normal equations ``N x = u`` (``p x p``,
  ``k`` right-hand sides) solved by the engine's scaled rule: ``C = S N S`` with unit
  diagonal, its Cholesky factor ``L``, and the lower bound ``1 / (||C||_F ||L^-1||_F^2)`` of
  the ratio of its smallest to its largest eigenvalue (``lambda_max <= ||C||_F`` and
  ``1 / lambda_min = ||L^-1||_2^2 <= ||L^-1||_F^2``). The trial is solved where the bound is
  above ``4 rcond``; otherwise it is left *undecided* and the caller applies the exact rule
  (:func:`sim.lsq.normals.scaled_rcond`) and the NumPy path to it, so every decision is the
  engine's one rule. For model kernels that form their normal equations in the cache
  (e.g. :mod:`sim.instruments.plotter.polynomial_kernel`, which hands its undecided trials to
  :func:`sim.lsq.linear.lstsq`).

Sums are compiled with :data:`sim.lsq.compile.REASSOCIATE` (reordered into vector
lanes, deterministic): the numbers equal the NumPy path to rounding (tests hold them to a
tolerance from the design's condition number). A trial with a non-finite observation is
found by the sum of ``b * 0`` (NaN unless every term is finite) and flagged. Seed of the
method: Brown 1968 (``004_f5bd9e86c308241f.txt``), least squares by normal equations;
Wolf & Pearsall 1976 (``000_668e60e68f004f98.txt``) for the polynomial calibration whose
design is the same for every trial.
"""

from __future__ import annotations

import numpy as np

from sim.lsq import compile

__all__ = [
    "shared_solve",
    "normal_solve",
    "solve_lanes",
    "LANES",
    "SOLVED",
    "UNDECIDED",
    "NONFINITE",
]

#: statuses of the kernels: solved (as :data:`sim.lsq.linear.LINEAR_STATUS` 0), left to the
#: exact rule, non-finite input (as :data:`sim.lsq.linear.LINEAR_STATUS` 3)
SOLVED, UNDECIDED, NONFINITE = 0, 1, 3

#: trials solved side by side by :func:`solve_lanes` (a multiple of the vector width)
LANES = 8


def _shared_solve(M, At, w, b, x, vtpv, status):  # pragma: no cover - compiled
    """The NumPy path of :func:`sim.lsq.linear._shared`: ``x = M b`` and ``v' W v`` of
    ``v = b - A x``, trial by trial (``At`` = ``A'``)."""
    T, m = b.shape[0], At.shape[1]
    p, k = P_TERMS, K_RHS  # compile-time constants: the small loops unroll  # noqa: F821 (set by the compile helper)
    bb, xx = np.empty((k, m)), np.empty((p, k))
    for t in range(T):
        bt, z = b[t], 0.0
        for i in range(m):  # the trial's right-hand sides, one per row
            for c in range(k):
                v = bt[i * k + c]
                bb[c, i] = v
                z += v * 0.0  # NaN unless every observation is finite
        fin = z == 0.0
        for j in range(0, p, 2):  # x = M b, two rows by two right-hand sides
            j2 = min(j + 1, p - 1)
            Ma, Mb = M[j], M[j2]
            for c in range(0, k, 2):
                c2 = min(c + 1, k - 1)
                b0, b1 = bb[c], bb[c2]
                s00 = s01 = s10 = s11 = 0.0
                for i in range(m):
                    s00 += Ma[i] * b0[i]
                    s01 += Ma[i] * b1[i]
                    s10 += Mb[i] * b0[i]
                    s11 += Mb[i] * b1[i]
                xx[j, c], xx[j, c2], xx[j2, c], xx[j2, c2] = s00, s01, s10, s11
        for c in range(k):  # v' W v, point by point over the unknowns
            bc, q = bb[c], 0.0
            for i in range(m):
                f = 0.0
                for j in range(p):
                    f += At[j, i] * xx[j, c]
                v = bc[i] - f
                q += w[i] * v * v
            vtpv[t, c] = q if fin else np.nan
            for j in range(p):
                x[t, j, c] = xx[j, c] if fin else np.nan
        status[t] = SOLVED if fin else NONFINITE


def shared_solve(M: np.ndarray, A: np.ndarray, w: np.ndarray | None, b: np.ndarray):
    """``(x (T, p, k), vtpv (T, k), status (T,) int8)`` for the shared design ``A`` (m, p),
    its solution operator ``M`` (p, m), weights ``w`` (m,) or None, and ``b`` (T, m, k).
    Non-finite trials: NaN ``x`` and ``vtpv``, status :data:`NONFINITE`."""
    T, m, k = b.shape
    p = A.shape[1]
    x, vtpv = np.empty((T, p, k)), np.empty((T, k))
    status = np.empty(T, np.int8)
    c = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    compile.compiled(_shared_solve, reassociate=True, P_TERMS=p, K_RHS=k)(
        c(M), c(A.T), np.ones(m) if w is None else c(w), c(b).reshape(T, m * k), x, vtpv, status
    )
    return x, vtpv, status


def solve_lanes(N, u, x, ok, s, L, G, e, fro, g2, rcond):  # pragma: no cover - compiled
    """:data:`LANES` trials at once: ``N x = u`` per lane ``b`` (``N`` (p, p, LANES)
    symmetric, upper triangle read; ``u``, ``x`` (p, k, LANES)) by the scaled rule of the
    module docstring. ``ok`` (LANES,) True where solved, else the lane's ``x`` is NaN and
    it is left to the exact rule. Scratch: ``s`` (p, LANES), ``L``, ``G`` (p, p, LANES),
    ``e``, ``fro``, ``g2`` (LANES,). The trials are the innermost axis, so every step runs
    in vector lanes, without the latency of one small factorisation after another.
    Compiled into the kernels that call it (``helpers`` of :func:`sim.lsq.compile.compiled`)."""
    p, k = u.shape[0], u.shape[1]
    for b in range(LANES):
        ok[b] = True
        fro[b] = 0.0
        g2[b] = 0.0
    for j in range(p):
        for b in range(LANES):
            d = N[j, j, b]
            okd = d > 0.0 and d < np.inf
            ok[b] &= okd
            s[j, b] = 1.0 / np.sqrt(d if okd else 1.0)
    for j in range(p):  # C = S N S, ||C||_F^2
        for i in range(j, p):
            w = 1.0 if i == j else 2.0
            for b in range(LANES):
                cij = N[j, i, b] * s[j, b] * s[i, b]
                fro[b] += w * cij * cij
                L[i, j, b] = cij
    for j in range(p):  # Cholesky C = L L'; G[j, j] = 1 / L[j, j]
        for i in range(j, p):  # the diagonal first, then below it
            for b in range(LANES):
                e[b] = L[i, j, b]
            for q in range(j):
                for b in range(LANES):
                    e[b] -= L[i, q, b] * L[j, q, b]
            for b in range(LANES):
                if i == j:
                    okd = e[b] > 0.0
                    ok[b] &= okd
                    d = np.sqrt(e[b] if okd else 1.0)
                    L[j, j, b] = d
                    G[j, j, b] = 1.0 / d
                else:
                    L[i, j, b] = e[b] * G[j, j, b]
    for j in range(p):  # G = L^-1 (lower), ||G||_F^2
        for b in range(LANES):
            g2[b] += G[j, j, b] * G[j, j, b]
        for i in range(j + 1, p):
            for b in range(LANES):
                e[b] = 0.0
            for q in range(j, i):
                for b in range(LANES):
                    e[b] -= L[i, q, b] * G[q, j, b]
            for b in range(LANES):
                v = e[b] * G[i, i, b]
                G[i, j, b] = v
                g2[b] += v * v
    for b in range(LANES):  # the bound of the scaled rule
        ok[b] &= 1.0 / (np.sqrt(fro[b]) * g2[b]) > 4.0 * rcond
    for c in range(k):  # x = S G' G S u (G S u on L's diagonal)
        for i in range(p):
            for b in range(LANES):
                e[b] = 0.0
            for q in range(i + 1):
                for b in range(LANES):
                    e[b] += G[i, q, b] * (s[q, b] * u[q, c, b])
            for b in range(LANES):
                L[i, i, b] = e[b]
        for j in range(p):
            for b in range(LANES):
                e[b] = 0.0
            for i in range(j, p):
                for b in range(LANES):
                    e[b] += G[i, j, b] * L[i, i, b]
            for b in range(LANES):
                x[j, c, b] = s[j, b] * e[b] if ok[b] else np.nan


def _normal_solve(N, u, x, status, rcond):  # pragma: no cover - compiled
    """``np.linalg.solve(N, u)`` where ``scaled_rcond(N) > rcond`` is proved by the bound,
    :data:`LANES` trials at a time (:func:`solve_lanes`)."""
    T, p, k = u.shape
    Nb, ub, xb = np.empty((p, p, LANES)), np.empty((p, k, LANES)), np.empty((p, k, LANES))
    s, L, G = np.empty((p, LANES)), np.empty((p, p, LANES)), np.empty((p, p, LANES))
    e, fro, g2, ok = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES, np.bool_)
    for t0 in range(0, T, LANES):
        nb = min(LANES, T - t0)
        for b in range(LANES):  # spare lanes repeat the block's first
            tb = t0 + b if b < nb else t0
            for j in range(p):
                for q in range(p):
                    Nb[j, q, b] = N[tb, j, q]
                for c in range(k):
                    ub[j, c, b] = u[tb, j, c]
        solve_lanes(Nb, ub, xb, ok, s, L, G, e, fro, g2, rcond)
        for b in range(nb):
            status[t0 + b] = SOLVED if ok[b] else UNDECIDED
            for j in range(p):
                for c in range(k):
                    x[t0 + b, j, c] = xb[j, c, b]


def normal_solve(N: np.ndarray, u: np.ndarray, rcond: float):
    """``(x (T, p, k), status (T,) int8)``: every trial's ``N x = u`` (``N`` (T, p, p)
    symmetric, its upper triangle read; ``u`` (T, p, k)) by the scaled rule as described in
    the module docstring; :data:`UNDECIDED` trials (NaN ``x``) are left to the exact rule."""
    T, p, k = u.shape
    x = np.empty((T, p, k))
    status = np.empty(T, np.int8)
    c = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    compile.compiled(_normal_solve, helpers=(solve_lanes,))(c(N), c(u), x, status, float(rcond))
    return x, status
