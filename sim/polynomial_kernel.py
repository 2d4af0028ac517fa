"""Compiled fast path of the polynomial calibration (optional, via numba).

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976): the correction
``true - measured = P(measured)`` per axis, a polynomial in the monomials
``(X / norm)^i (Y / norm)^j`` of the *measured* coordinates (mm), so every Monte-Carlo trial
has its own design ``A_t`` (``n x p``). :func:`sim.polynomial.fit_poly` builds the batch's
designs and hands them to :func:`sim.lsq.linear.lstsq`; that writes and reads every trial's
design (16 kB for Wolf's 198 points and ten terms) through memory several times. Here each
trial's design is formed in the processor's cache from its points and never stored:

* per trial (:func:`_points`): the monomials ``(X * (1 / norm))^i (Y * (1 / norm))^j``
  (powers by successive products, as :func:`sim.polynomial.design`) and
  ``D = true - measured``; ``N_t = A_t' A_t`` from its distinct entries (the moments) and
  ``u_t = A_t' D``, four products per pass over the points (:func:`_plan`);
* eight trials at a time, the engine's scaled rule and solve
  (:func:`sim.lsq.linear_kernel.solve_lanes`); trials it cannot prove regular are fitted
  again by :func:`sim.lsq.linear.lstsq` (the exact rule), so the decisions are the engine's;
* ``P(measured)``, the residual square sums per axis and, when asked, the corrected points
  ``measured + A_t x_t``.

The normal equations square the design's condition number; with coordinates normalised by
``norm`` (100 mm) Wolf's design has a condition number of about 44, so the coefficients
equal the QR-preconditioned path of :func:`sim.lsq.linear.lstsq` to about ``cond^2 eps``
relative (a test holds them to a bound derived from each trial's condition number).
Without numba, or with ``SIM_NO_JIT`` set, :func:`available` is False and
:func:`sim.polynomial.fit_poly` runs the NumPy path.
"""
from __future__ import annotations

import functools

import numpy as np

from .lsq import group_kernel
from .lsq import linear_kernel as lk
from .lsq.linear import lstsq
from .lsq.linear_kernel import LANES, NONFINITE, SOLVED, UNDECIDED, solve_lanes
from .lsq.normals import RCOND

try:  # the design helper is compiled into both kernels (inlined where they call it)
    from numba.extending import register_jitable
except ImportError:  # pragma: no cover - the NumPy path runs
    def register_jitable(f):
        return f

__all__ = ["available", "fit"]


def available() -> bool:
    """Whether the compiled kernels run (numba installed and ``SIM_NO_JIT`` unset)."""
    return group_kernel.available()


@register_jitable
def _points(meas, true, t, tt, inv, PX, PY, A, D, ex, ey):  # pragma: no cover - compiled
    """Trial ``t``'s design rows into ``A`` (p, n) and ``true - measured`` into ``D``
    (2, n), from ``meas`` (T, 2n) and ``true`` (1 or T, 2n) (x, y interleaved): the
    monomials of ``polynomial.design`` (``X * (1 / norm)``, its powers by successive
    products)."""
    n = PX.shape[1]
    m, g = meas[t], true[tt]
    for i in range(n):
        X, Y = m[2 * i], m[2 * i + 1]
        D[0, i] = g[2 * i] - X
        D[1, i] = g[2 * i + 1] - Y
        PX[0, i] = 1.0
        PY[0, i] = 1.0
        PX[1, i] = X * inv
        PY[1, i] = Y * inv
    for e in range(2, PX.shape[0]):
        for i in range(n):
            PX[e, i] = PX[e - 1, i] * PX[1, i]
    for e in range(2, PY.shape[0]):
        for i in range(n):
            PY[e, i] = PY[e - 1, i] * PY[1, i]
    for j in range(ex.size):
        a, b = PX[ex[j]], PY[ey[j]]
        for i in range(n):
            A[j, i] = a[i] * b[i]


def _fit(meas, true, ex, ey, h1, h2, ho, jq, norm, rcond, x, sq, corr, want,
         status):  # pragma: no cover - compiled
    T, n, p = meas.shape[0], meas.shape[1] // 2, P_TERMS  # P_TERMS: a compile-time constant
    PX, PY = np.empty((max(ex.max(), 1) + 1, n)), np.empty((max(ey.max(), 1) + 1, n))
    A = np.empty((LANES, p + 2, n))               # the design rows and true - measured
    nmom = jq.max() + 1
    dots, fin = np.empty(nmom + 2 * p), np.empty(LANES, np.bool_)
    x0, x1, F = np.empty(p), np.empty(p), np.empty((2, n))
    Nb, ub, xb = np.empty((p, p, LANES)), np.empty((p, 2, LANES)), np.empty((p, 2, LANES))
    s, L, G = np.empty((p, LANES)), np.empty((p, p, LANES)), np.empty((p, p, LANES))
    e, fro, g2, ok = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES, np.bool_)
    for t0 in range(0, T, LANES):
        nb = min(LANES, T - t0)
        for b in range(LANES):                  # spare lanes repeat the block's first trial
            t = t0 + b if b < nb else t0
            Ab = A[b]
            _points(meas, true, t, t if true.shape[0] > 1 else 0, 1.0 / norm, PX, PY, Ab, Ab[p:],
                    ex, ey)
            for g in range(h1.size):            # the products: four per pass over the points
                a, c0, c1 = Ab[h1[g]], Ab[h2[g, 0]], Ab[h2[g, 1]]
                c2, c3 = Ab[h2[g, 2]], Ab[h2[g, 3]]
                v0 = v1 = v2 = v3 = 0.0
                for i in range(n):
                    ai = a[i]
                    v0 += ai * c0[i]
                    v1 += ai * c1[i]
                    v2 += ai * c2[i]
                    v3 += ai * c3[i]
                dots[ho[g, 0]], dots[ho[g, 1]], dots[ho[g, 2]], dots[ho[g, 3]] = v0, v1, v2, v3
            fin[b] = True
            for j in range(p):
                for q in range(p):
                    Nb[j, q, b] = dots[jq[j, q]]
                for c in range(2):
                    ub[j, c, b] = dots[nmom + 2 * j + c]
                    fin[b] &= np.isfinite(ub[j, c, b])   # non-finite data reach u
        solve_lanes(Nb, ub, xb, ok, s, L, G, e, fro, g2, rcond)
        for b in range(nb):
            t = t0 + b
            status[t] = (SOLVED if ok[b] else UNDECIDED) if fin[b] else NONFINITE
            for j in range(p):
                for c in range(2):
                    x[t, j, c] = xb[j, c, b] if status[t] == SOLVED else np.nan
            if status[t] != SOLVED:
                sq[t, 0] = sq[t, 1] = np.nan
                continue
            Ab, Db = A[b], A[b, p:]
            for j in range(p):
                x0[j], x1[j] = xb[j, 0, b], xb[j, 1, b]
            q0 = q1 = 0.0                       # residuals, point by point over the terms
            for i in range(n):
                f0 = f1 = 0.0
                for j in range(p):
                    f0 += Ab[j, i] * x0[j]
                    f1 += Ab[j, i] * x1[j]
                v0, v1 = Db[0, i] - f0, Db[1, i] - f1
                q0 += v0 * v0
                q1 += v1 * v1
                F[0, i], F[1, i] = f0, f1
            if want:
                for i in range(n):
                    corr[t, i, 0] = meas[t, 2 * i] + F[0, i]
                    corr[t, i, 1] = meas[t, 2 * i + 1] + F[1, i]
            sq[t, 0] = q0
            sq[t, 1] = q1


@functools.lru_cache(maxsize=16)
def _plan(terms):
    """The products a trial's fit needs, for the kernel: ``ex``, ``ey`` the terms' exponents;
    the distinct entries of ``N = A A'`` (moments ``x^a y^b``, one pair of terms each,
    ``jq[j, q]`` the moment of entry ``(j, q)``) and the entries of ``u = A D'`` (rows ``p``,
    ``p + 1`` of the kernel's extended design are ``D``), grouped four by four under a shared
    first row: ``g1`` (G,), ``g2``, ``go`` (G, 4) the second rows and where each product goes
    (moments first, then ``u[j, c]`` at ``n_moments + 2 j + c``; a short group repeats its
    last product)."""
    p = len(terms)
    pair = {}                                   # moment exponents -> the first pair giving it
    for j, (a, c) in enumerate(terms):
        for q, (b, d) in enumerate(terms):
            pair.setdefault((a + b, c + d), (j, q))
    keys = sorted(pair)
    jq = np.array([[keys.index((a + b, c + d)) for b, d in terms] for a, c in terms], np.int64)
    second: dict[int, list] = {}
    for o, m in enumerate(keys):
        second.setdefault(pair[m][0], []).append((pair[m][1], o))
    for j in range(p):
        second.setdefault(j, []).extend([(p, len(keys) + 2 * j), (p + 1, len(keys) + 2 * j + 1)])
    g1, g2, go = [], [], []
    for j, lst in sorted(second.items()):
        for s in range(0, len(lst), 4):
            chunk = lst[s:s + 4]
            chunk += chunk[-1:] * (4 - len(chunk))
            g1.append(j)
            g2.append([q for q, _ in chunk])
            go.append([o for _, o in chunk])
    arr = lambda v: np.array(v, np.int64)  # noqa: E731
    return (arr([i for i, _ in terms]), arr([j for _, j in terms]), arr(g1), arr(g2), arr(go),
            jq)


def fit(measured: np.ndarray, true: np.ndarray, terms, norm_mm: float, corrected: bool,
        rcond: float = RCOND):
    """``(coef (T, p, 2), status (T,) int8, square sums (T, 2) mm^2, corrected (T, n, 2) or
    None)`` of the correction polynomial for measured ``(T, n, 2)`` and true ``(n, 2)`` or
    ``(T, n, 2)`` mm; status codes of :data:`sim.lsq.linear.LINEAR_STATUS`; NaN where not
    solved. Trials the compiled bound leaves undecided are fitted again by
    :func:`sim.lsq.linear.lstsq` (the exact rule) on their designs."""
    from .polynomial import design

    f = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    meas, tr = f(measured), f(true)
    tr = tr[None] if tr.ndim == 2 else tr
    terms = tuple(terms)
    ex, ey, g1, g2, go, jq = _plan(terms)
    T, n, k = meas.shape
    x, sq, status = np.empty((T, len(terms), k)), np.empty((T, k)), np.empty(T, np.int8)
    corr = np.full((T, n, k) if corrected else (1, 1, k), np.nan)
    kernel = group_kernel.compiled(_fit, reassociate=True, P_TERMS=len(terms),
                                   SOLVE_TAG=lk.SOURCE_TAG)
    kernel(meas.reshape(T, 2 * n), tr.reshape(tr.shape[0], 2 * n), ex, ey, g1, g2, go, jq,
           float(norm_mm), float(rcond), x, sq, corr, bool(corrected), status)
    rest = np.flatnonzero(status == UNDECIDED)
    if rest.size:                               # the exact rule: the engine's NumPy path
        A = design(meas[rest], terms, norm_mm)
        g = lstsq(A, tr[rest if tr.shape[0] > 1 else np.zeros(rest.size, int)] - meas[rest],
                  rcond=rcond)
        x[rest], status[rest] = g.x, g.status
        sq[rest] = g.vtpv
        if corrected:
            corr[rest] = meas[rest] + np.matmul(A, g.x)
    return x, status, sq, (corr if corrected else None)
