"""Compiled fast path of the polynomial calibration (optional, via numba).

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976): the correction
``true - measured = P(measured)`` per axis, a polynomial in the monomials
``(X / norm)^i (Y / norm)^j`` of the *measured* coordinates (mm), so every Monte-Carlo trial
has its own design ``A_t`` (``n x p``). The NumPy path of
:func:`sim.instruments.plotter.polynomial.fit_poly` builds the batch's designs
(:func:`~sim.instruments.plotter.polynomial.design`) and hands them to
:func:`sim.lsq.linear.lstsq`, which writes and reads every trial's design through memory
several times. :func:`fit` equals ``lstsq(design(measured, terms, norm), true - measured)``
to rounding, with each trial's design formed in the processor's cache and never stored:

* the trial's design rows as :func:`~sim.instruments.plotter.polynomial.design` forms them
  (powers of ``X / norm`` and ``Y / norm`` by successive products, a term the product of
  its two powers) and ``D = true - measured``;
* its normal equations ``N = A' A``, ``u = A' D`` (both axes share ``N``), then
  :data:`~sim.lsq.linear_kernel.LANES` trials at a time the engine's scaled rule and solve
  (:func:`sim.lsq.linear_kernel.solve_lanes`); a trial it cannot prove regular is left
  *undecided*, and the caller fits it again by :func:`sim.lsq.linear.lstsq` (the exact rule);
* the residuals ``D - A x`` and their square sums per axis, and the corrected points
  ``measured + A x`` when asked for.

The normal equations square the design's condition number; with coordinates normalised by
``norm`` (100 mm) Wolf's design has a condition number of about 44, so the coefficients
equal the QR path of :func:`sim.lsq.linear.lstsq` to about ``cond^2 eps`` relative (a test
holds them to a bound derived from each trial's condition number). Runs where
:func:`sim.lsq.compile.available`.
"""

from __future__ import annotations

import numpy as np

from sim.lsq import compile
from sim.lsq.linear_kernel import LANES, NONFINITE, SOLVED, UNDECIDED, solve_lanes

__all__ = ["fit", "UNDECIDED"]


def _fit(meas, true, ex, ey, norm, rcond, x, sq, corr, want, status):  # pragma: no cover
    """The fits of :func:`fit` (``meas`` (T, 2n), ``true`` (1 or T, 2n) with x, y
    interleaved; ``ex``, ``ey`` the terms' exponents, their number an argument: one compile
    serves every term count, with the same answers bit for bit as a count frozen into the
    kernel, since only the sums over the points are vectorised)."""
    T, n, p = meas.shape[0], meas.shape[1] // 2, ex.shape[0]
    px, py = np.empty((ex.max() + 1, n)), np.empty((ey.max() + 1, n))
    A, D, F = np.empty((LANES, p, n)), np.empty((LANES, 2, n)), np.empty((2, n))
    Nb, ub, xb = np.empty((p, p, LANES)), np.empty((p, 2, LANES)), np.empty((p, 2, LANES))
    s, L, G = np.empty((p, LANES)), np.empty((p, p, LANES)), np.empty((p, p, LANES))
    e, fro, g2, ok = np.empty(LANES), np.empty(LANES), np.empty(LANES), np.empty(LANES, np.bool_)
    fin = np.empty(LANES, np.bool_)
    for t0 in range(0, T, LANES):
        nb = min(LANES, T - t0)
        for b in range(LANES):  # spare lanes repeat the block's first trial
            t = t0 + b if b < nb else t0
            tt = t if true.shape[0] > 1 else 0
            for i in range(n):  # design(): powers by successive products, then the terms
                px[0, i] = py[0, i] = 1.0
                D[b, 0, i] = true[tt, 2 * i] - meas[t, 2 * i]
                D[b, 1, i] = true[tt, 2 * i + 1] - meas[t, 2 * i + 1]
            for k in range(1, px.shape[0]):
                for i in range(n):
                    px[k, i] = px[k - 1, i] * (meas[t, 2 * i] / norm)
            for k in range(1, py.shape[0]):
                for i in range(n):
                    py[k, i] = py[k - 1, i] * (meas[t, 2 * i + 1] / norm)
            for j in range(p):
                for i in range(n):
                    A[b, j, i] = px[ex[j], i] * py[ey[j], i]
            fin[b] = True
            for j in range(p):  # N = A' A (upper triangle), u = A' D
                for q in range(j, p):
                    v = 0.0
                    for i in range(n):
                        v += A[b, j, i] * A[b, q, i]
                    Nb[j, q, b] = Nb[q, j, b] = v
                for c in range(2):
                    v = 0.0
                    for i in range(n):
                        v += A[b, j, i] * D[b, c, i]
                    ub[j, c, b] = v
                    fin[b] &= np.isfinite(v)  # non-finite data reach u
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
            F[:, :] = 0.0
            for j in range(p):  # F = A x, term by term over the points
                for c in range(2):
                    for i in range(n):
                        F[c, i] += A[b, j, i] * xb[j, c, b]
            for c in range(2):  # residuals v = D - A x and v'v
                v = 0.0
                for i in range(n):
                    r = D[b, c, i] - F[c, i]
                    v += r * r
                sq[t, c] = v
                if want:
                    for i in range(n):
                        corr[t, i, c] = meas[t, 2 * i + c] + F[c, i]


def fit(measured: np.ndarray, true: np.ndarray, terms, norm_mm: float, corrected: bool, rcond):
    """``(coef (T, p, 2), status (T,) int8, square sums (T, 2) mm^2, corrected (T, n, 2) or
    None)`` of the correction polynomial for measured ``(T, n, 2)`` and true ``(n, 2)`` or
    ``(T, n, 2)`` mm; status codes of :data:`sim.lsq.linear.LINEAR_STATUS`, or
    :data:`UNDECIDED` (NaN) where the caller must apply the exact rule."""
    f = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    meas, tr = f(measured), f(true)
    tr = tr[None] if tr.ndim == 2 else tr
    T, n, k = meas.shape
    ex = np.array([a for a, _ in terms], np.int64)
    ey = np.array([b for _, b in terms], np.int64)
    x, sq, status = np.empty((T, len(terms), k)), np.empty((T, k)), np.empty(T, np.int8)
    corr = np.full((T, n, k) if corrected else (1, 1, k), np.nan)
    kernel = compile.compiled(_fit, reassociate=True, helpers=(solve_lanes,))
    kernel(
        meas.reshape(T, 2 * n), tr.reshape(tr.shape[0], 2 * n), ex, ey, float(norm_mm),
        float(rcond), x, sq, corr, bool(corrected), status,
    )  # fmt: skip
    return x, status, sq, (corr if corrected else None)
