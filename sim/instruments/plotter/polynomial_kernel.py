"""Compiled fast path of the polynomial calibration (optional, via numba).

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976): the correction
``true - measured = P(measured)`` per axis, a polynomial in the monomials
``(X / norm)^i (Y / norm)^j`` of the *measured* coordinates (mm), so every Monte-Carlo trial
has its own design ``A_t`` (``n x p``). :func:`sim.instruments.plotter.polynomial.fit_poly` builds the batch's
designs and hands them to :func:`sim.lsq.linear.lstsq`; that writes and reads every trial's
design (16 kB for Wolf's 198 points and ten terms) through memory several times. Here each
trial's design is formed in the processor's cache from its points and never stored:

* per trial (:func:`_points`): the powers of ``X * (1 / norm)`` and ``Y * (1 / norm)`` (by
  successive products, as :func:`sim.instruments.plotter.polynomial.design`), the mixed monomials of the terms
  and ``D = true - measured`` (a term that is a pure power is read from its power's row);
  ``N_t = A_t' A_t`` from its distinct entries (the moments) and ``u_t = A_t' D``, the
  products grouped :data:`GROUP` to a pass over the points, each group sharing one row
  (:func:`_plan` packs them greedily);
* eight trials at a time, the engine's scaled rule and solve
  (:func:`sim.lsq.linear_kernel.solve_lanes`); trials it cannot prove regular are fitted
  again by :func:`sim.lsq.linear.lstsq` (the exact rule), so the decisions are the engine's;
* the residual square sums per axis: without corrected points from the sums already formed,
  ``v'v = D'D - 2 x'u + x'N x`` (``D'D`` two more products), where its rounding bound
  ``(n + p^2) eps (D'D + 2 |x'u| + |x'N x|)`` is below ``1e-9 v'v``; otherwise (a trial
  fitted almost exactly, or corrected points asked for) from ``P(measured)`` and the
  residuals themselves, with the corrected points ``measured + A_t x_t``.

The normal equations square the design's condition number; with coordinates normalised by
``norm`` (100 mm) Wolf's design has a condition number of about 44, so the coefficients
equal the QR-preconditioned path of :func:`sim.lsq.linear.lstsq` to about ``cond^2 eps``
relative (a test holds them to a bound derived from each trial's condition number).
Without numba, or with ``SIM_NO_JIT`` set, :func:`available` is False and
:func:`sim.instruments.plotter.polynomial.fit_poly` runs the NumPy path.
"""

from __future__ import annotations

import functools

import numpy as np

from sim.lsq import group_kernel
from sim.lsq import linear_kernel as lk
from sim.lsq.linear import lstsq
from sim.lsq.linear_kernel import LANES, NONFINITE, SOLVED, UNDECIDED, solve_lanes
from sim.lsq.normals import RCOND

EPS = float(np.finfo(float).eps)

try:  # the design helper is compiled into both kernels (inlined where they call it)
    from numba.extending import register_jitable
except ImportError:  # pragma: no cover - the NumPy path runs

    def register_jitable(f):
        return f


__all__ = ["available", "fit"]

#: products per pass over a trial's points (sharing one row; :func:`_plan`)
GROUP = 8  # the product loop of _fit is written out for eight


def available() -> bool:
    """Whether the compiled kernels run (numba installed and ``SIM_NO_JIT`` unset)."""
    return group_kernel.available()


@register_jitable
def _points(meas, true, t, tt, inv, ax, ay, mx, my, C):  # pragma: no cover - compiled
    """Trial ``t``'s rows into ``C`` (rows, n) from ``meas`` (T, 2n) and ``true`` (1 or T,
    2n) (x, y interleaved): ``x^0 ... x^ax``, ``y^1 ... y^ay`` (``x = X * (1 / norm)``, powers
    by successive products, as ``polynomial.design``), the mixed monomials ``C[mx] * C[my]``,
    then ``true - measured`` (the last two rows). A term that is a pure power is its row."""
    n = C.shape[1]
    m, g = meas[t], true[tt]
    r = C.shape[0] - 2
    for i in range(n):
        X, Y = m[2 * i], m[2 * i + 1]
        C[r, i] = g[2 * i] - X
        C[r + 1, i] = g[2 * i + 1] - Y
        C[0, i] = 1.0
        C[1, i] = X * inv
        C[ax + 1, i] = Y * inv
    for e in range(2, ax + 1):
        for i in range(n):
            C[e, i] = C[e - 1, i] * C[1, i]
    for e in range(ax + 2, ax + ay + 1):
        for i in range(n):
            C[e, i] = C[e - 1, i] * C[ax + 1, i]
    for k in range(mx.size):
        a, b, o = C[mx[k]], C[my[k]], C[ax + ay + 1 + k]
        for i in range(n):
            o[i] = a[i] * b[i]


def _fit(
    meas, true, ax, ay, mx, my, rows, h1, h2, ho, jq, norm, rcond, x, sq, corr, want, status
):  # pragma: no cover - compiled
    T, n, p = meas.shape[0], meas.shape[1] // 2, P_TERMS  # P_TERMS: a compile-time constant  # noqa: F821 (set by the compile helper)
    nr = ax + ay + 1 + mx.size + 2
    A = np.empty((LANES, nr, n))  # the monomial rows and true - measured
    nmom = jq.max() + 1
    dots, fin = np.empty(nmom + 2 * p + 2), np.empty(LANES, np.bool_)
    F, dd = np.empty((2, n)), np.empty((2, LANES))
    Nb, ub, xb = np.empty((p, p, LANES)), np.empty((p, 2, LANES)), np.empty((p, 2, LANES))
    s, L, G = np.empty((p, LANES)), np.empty((p, p, LANES)), np.empty((p, p, LANES))
    e, fro, g2, ok = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES, np.bool_)
    for t0 in range(0, T, LANES):
        nb = min(LANES, T - t0)
        for b in range(LANES):  # spare lanes repeat the block's first trial
            t = t0 + b if b < nb else t0
            Ab = A[b]
            _points(meas, true, t, t if true.shape[0] > 1 else 0, 1.0 / norm, ax, ay, mx, my, Ab)
            for g in range(h1.size):  # the products: GROUP per pass over the points
                a, c0, c1 = Ab[h1[g]], Ab[h2[g, 0]], Ab[h2[g, 1]]
                c2, c3 = Ab[h2[g, 2]], Ab[h2[g, 3]]
                c4, c5 = Ab[h2[g, 4]], Ab[h2[g, 5]]
                c6, c7 = Ab[h2[g, 6]], Ab[h2[g, 7]]
                v0 = v1 = v2 = v3 = v4 = v5 = v6 = v7 = 0.0
                for i in range(n):
                    ai = a[i]
                    v0 += ai * c0[i]
                    v1 += ai * c1[i]
                    v2 += ai * c2[i]
                    v3 += ai * c3[i]
                    v4 += ai * c4[i]
                    v5 += ai * c5[i]
                    v6 += ai * c6[i]
                    v7 += ai * c7[i]
                dots[ho[g, 0]], dots[ho[g, 1]], dots[ho[g, 2]], dots[ho[g, 3]] = v0, v1, v2, v3
                dots[ho[g, 4]], dots[ho[g, 5]], dots[ho[g, 6]], dots[ho[g, 7]] = v4, v5, v6, v7
            fin[b] = True
            for j in range(p):
                for q in range(p):
                    Nb[j, q, b] = dots[jq[j, q]]
                for c in range(2):
                    ub[j, c, b] = dots[nmom + 2 * j + c]
                    fin[b] &= np.isfinite(ub[j, c, b])  # non-finite data reach u
            dd[0, b], dd[1, b] = dots[nmom + 2 * p], dots[nmom + 2 * p + 1]
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
            if not want:  # v'v = D'D - 2 x'u + x'N x, if exact enough
                exact = True
                for c in range(2):
                    xu = axu = xnx = axnx = 0.0
                    for j in range(p):
                        v = xb[j, c, b] * ub[j, c, b]
                        xu += v
                        axu += abs(v)
                        for q in range(p):
                            v = xb[j, c, b] * Nb[j, q, b] * xb[q, c, b]
                            xnx += v
                            axnx += abs(v)
                    sq[t, c] = dd[c, b] - 2.0 * xu + xnx
                    bound = (n + p * p) * EPS * (dd[c, b] + 2.0 * axu + axnx)
                    exact &= bound < 1e-9 * sq[t, c]
                if exact:
                    continue  # else: the explicit residuals below
            Ab, Db = A[b], A[b, nr - 2 :]
            for i in range(n):  # P(measured), term by term over the points
                F[0, i] = F[1, i] = 0.0
            for j in range(p):
                a, c0, c1 = Ab[rows[j]], xb[j, 0, b], xb[j, 1, b]
                for i in range(n):
                    F[0, i] += a[i] * c0
                    F[1, i] += a[i] * c1
            q0 = q1 = 0.0
            for i in range(n):
                v0, v1 = Db[0, i] - F[0, i], Db[1, i] - F[1, i]
                q0 += v0 * v0
                q1 += v1 * v1
            if want:
                for i in range(n):
                    corr[t, i, 0] = meas[t, 2 * i] + F[0, i]
                    corr[t, i, 1] = meas[t, 2 * i + 1] + F[1, i]
            sq[t, 0] = q0
            sq[t, 1] = q1


@functools.lru_cache(maxsize=16)
def _plan(terms):
    """The products a trial's fit needs, for the kernel. The kernel's rows (per trial): the
    powers ``x^0 ... x^ax`` and ``y^1 ... y^ay``, the mixed monomials of the terms
    (``x^a y^b`` with ``a, b > 0``: the product of rows ``mx``, ``my``), then ``D = true -
    measured`` (two rows); ``rows[j]`` is term ``j``'s row (a pure power is its power's row,
    not a copy). Then the distinct entries of ``N = A' A`` (moments ``x^a y^b``, one pair of
    terms each, ``jq[j, q]`` the moment of entry ``(j, q)``) and the entries of ``u = A' D``,
    grouped four by four under a shared first row: ``g1`` (G,), ``g2``, ``go`` (G, 4) the
    rows of the products (kernel rows) and where each goes (moments first, then ``u[j, c]``
    at ``n_moments + 2 j + c``; a short group repeats its last product)."""
    p = len(terms)
    ax, ay = max(max(a for a, _ in terms), 1), max(max(b for _, b in terms), 1)
    mixed = [(a, b) for a, b in terms if a and b]
    row = {(a, 0): a for a in range(ax + 1)}  # monomial -> the kernel's row
    row.update({(0, b): ax + b for b in range(1, ay + 1)})
    row.update({t: ax + ay + 1 + k for k, t in enumerate(mixed)})
    nr = ax + ay + 1 + len(mixed) + 2
    keys = sorted({(a + b, c + d) for a, c in terms for b, d in terms})
    jq = np.array([[keys.index((a + b, c + d)) for b, d in terms] for a, c in terms], np.int64)
    # every product wanted (its place in the kernel's sums) and the row pairs that give it
    ways: dict[int, set] = {}
    for o, k in enumerate(keys):
        ways[o] = {
            (r1, r2)
            for m1, r1 in row.items()
            for m2, r2 in row.items()
            if (m1[0] + m2[0], m1[1] + m2[1]) == k
        }
    for j, t in enumerate(terms):
        for c in range(2):
            ways[len(keys) + 2 * j + c] = {(row[t], nr - 2 + c), (nr - 2 + c, row[t])}
    for c in range(2):  # D_c' D_c
        ways[len(keys) + 2 * p + c] = {(nr - 2 + c, nr - 2 + c)}
    left, g1, g2, go = set(ways), [], [], []
    while left:  # greedy: the row shared by the most products still wanted, GROUP at a time
        best = None
        for r in range(nr):
            mine = sorted(
                (o for o in left if any(a == r for a, _ in ways[o])),
                key=lambda o: (len(ways[o]), o),
            )
            if mine and (best is None or min(len(mine), GROUP) > best[0]):
                best = (min(len(mine), GROUP), r, mine[:GROUP])
        _, r, chunk = best
        g1.append(r)
        g2.append([min(b for a, b in ways[o] if a == r) for o in chunk])
        go.append(chunk)
        left -= set(chunk)
        g2[-1] += g2[-1][-1:] * (GROUP - len(chunk))  # a short group repeats its last
        go[-1] += go[-1][-1:] * (GROUP - len(chunk))
    arr = lambda v: np.array(v, np.int64)  # noqa: E731
    return (
        ax,
        ay,
        arr([a for a, _ in mixed]),
        arr([ax + b for _, b in mixed]),
        arr([row[t] for t in terms]),
        arr(g1),
        arr(g2),
        arr(go),
        jq,
    )


def fit(
    measured: np.ndarray,
    true: np.ndarray,
    terms,
    norm_mm: float,
    corrected: bool,
    rcond: float = RCOND,
):
    """``(coef (T, p, 2), status (T,) int8, square sums (T, 2) mm^2, corrected (T, n, 2) or
    None)`` of the correction polynomial for measured ``(T, n, 2)`` and true ``(n, 2)`` or
    ``(T, n, 2)`` mm; status codes of :data:`sim.lsq.linear.LINEAR_STATUS`; NaN where not
    solved. Trials the compiled bound leaves undecided are fitted again by
    :func:`sim.lsq.linear.lstsq` (the exact rule) on their designs."""
    from sim.instruments.plotter.polynomial import design

    f = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    meas, tr = f(measured), f(true)
    tr = tr[None] if tr.ndim == 2 else tr
    terms = tuple(terms)
    ax, ay, mx, my, rows, g1, g2, go, jq = _plan(terms)
    T, n, k = meas.shape
    x, sq, status = np.empty((T, len(terms), k)), np.empty((T, k)), np.empty(T, np.int8)
    corr = np.full((T, n, k) if corrected else (1, 1, k), np.nan)
    kernel = group_kernel.compiled(
        _fit, reassociate=True, P_TERMS=len(terms), SOLVE_TAG=lk.SOURCE_TAG
    )
    kernel(
        meas.reshape(T, 2 * n),
        tr.reshape(tr.shape[0], 2 * n),
        ax,
        ay,
        mx,
        my,
        rows,
        g1,
        g2,
        go,
        jq,
        float(norm_mm),
        float(rcond),
        x,
        sq,
        corr,
        bool(corrected),
        status,
    )
    rest = np.flatnonzero(status == UNDECIDED)
    if rest.size:  # the exact rule: the engine's NumPy path
        A = design(meas[rest], terms, norm_mm)
        g = lstsq(
            A, tr[rest if tr.shape[0] > 1 else np.zeros(rest.size, int)] - meas[rest], rcond=rcond
        )
        x[rest], status[rest] = g.x, g.status
        sq[rest] = g.vtpv
        if corrected:
            corr[rest] = meas[rest] + np.matmul(A, g.x)
    return x, status, sq, (corr if corrected else None)
