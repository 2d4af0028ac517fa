"""Linear engine rows of the benchmark: Wolf & Pearsall's polynomial calibration, and the
stress field of its error model.

Seed ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976): the ten-term third-degree
correction polynomial per axis (:data:`sim.instruments.plotter.polynomial.WOLF_TERMS`) fitted by least squares to
three calibration sets of the 66-point grid (20 mm quadrille over 200 x 100 mm, the study's
``plate.area_mm``), 198 points pooled, two right-hand sides (x and y) sharing the design.
Measured coordinates carry a smooth systematic field of a few um (a random amplitude per
trial) and 2 um of reading noise. Compared on the coefficients (mm, on the monomials of
coordinates / 100 mm).

* ``polynomial``: as the study fits it (:func:`sim.instruments.plotter.polynomial.fit_wolf`): the design is
  built from each trial's *measured* coordinates, so it differs per trial; the engine's
  compiled fast path (:mod:`sim.instruments.plotter.polynomial_kernel`) forms each trial's design in the cache,
  its normal equations from their distinct entries, and solves them eight trials at a time
  by the engine's scaled rule (:mod:`sim.lsq.linear_kernel`).
* ``polynomial_shared``: the same polynomial with its design on the grid's nominal
  coordinates (the correction as a function of position), shared by all trials: one QR for
  all trials (:func:`sim.lsq.linear.lstsq`), then every trial's solution and ``v' W v`` in a
  compiled pass over its observations.

* ``stress_field``: the ``stress`` component of the plotter's error field
  (:mod:`sim.instruments.plotter.errorfields`, the study's 8 um over 70 mm, 16 waves) at the
  198 points, compiled (:mod:`sim.instruments.plotter.errorfield_kernel`) and NumPy; its
  per-trial loop is NumPy's own formula trial by trial (no SciPy routine does this).
* ``stress_sincos``: the same compiled kernel with its own sine and cosine (fdlibm's
  polynomials, vectorised) against the same kernel calling the library's ``sin`` and ``cos``
  (its ``numpy_s``): the row that keeps the hand-written sine and cosine.

The SciPy side of the polynomial rows is what a user would write for one trial: ``scipy.linalg.lstsq`` (LAPACK
``gelsd``) of the trial's design against its two right-hand sides. Where a row falls below
the issue's 50x, its note times, beside both sides, LAPACK's QR least squares (``dgels``)
alone on a prepared design per trial, the floor of any per-trial loop.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg
from scipy.linalg import lapack

from benchmarks.case import Case
from sim.instruments.plotter import errorfield_kernel as ek
from sim.instruments.plotter import errorfields as ef
from sim.instruments.plotter import polynomial as pl
from sim.lsq import compile
from sim.lsq.linear import lstsq

__all__ = ["polynomial", "polynomial_shared", "stress", "stress_sincos"]

#: coefficients of both sides agree to this (mm); the fits are well conditioned (the
#: coordinates are normalised by 100 mm), so the difference is a few units of rounding
TOL_POLY_MM = 1e-13
_SCIPY = "scipy.linalg.lstsq (gelsd), per trial"
_WHY = (
    "a linear fit is one LAPACK call per trial, already compiled; the loop's overhead is "
    "Python's per call and the engine's cost is memory traffic over the trials' data"
)
_WHY_PER_TRIAL = (
    _WHY + "; with a design per trial the engine forms every trial's 198 x 10 "
    "design and its normal equations, about 60 products of 198 terms, and the "
    "SciPy loop is within a few times of LAPACK's own per-trial floor"
)
_FLOOR = "LAPACK dgels alone (design prepared)"


def _dgels(As, bs):
    """``floor(t)``: LAPACK ``dgels`` on trial ``t``'s prepared (Fortran-ordered) design."""
    m, p = As[0].shape
    lwork = int(lapack.dgels_lwork(m, p, bs[0].shape[1])[0])
    return lambda t: lapack.dgels(As[t], bs[t], lwork=lwork)


def _calibration(T: int, seed: int):
    """Grid ``(198, 2)`` mm (three sets) and measured coordinates ``(T, 198, 2)`` mm."""
    rng = np.random.default_rng(seed)
    xs, ys = np.arange(-100.0, 100.1, 20.0), np.arange(-40.0, 60.1, 20.0)
    yy, xx = np.meshgrid(ys[::-1], xs, indexing="ij")
    g = np.tile(np.column_stack([xx.ravel(), yy.ravel()]), (3, 1))
    u, v = g[:, 0] / 100.0, g[:, 1] / 100.0
    shape = np.stack(
        [np.sin(1.3 * u + 0.4) * v + 0.5 * u * u, np.cos(0.9 * v) * u - 0.3 * v * v * u], axis=-1
    )  # (198, 2), order 1
    amp = rng.normal(0.0, 4e-3, (T, 1, 2))  # a few um per trial
    return g, g + amp * shape + rng.normal(0.0, 2e-3, (T,) + g.shape)


def polynomial(T: int, seed: int = 6) -> Case:
    """The study's fit: per-trial designs from the measured coordinates."""
    g, meas = _calibration(T, seed)

    def engine():
        return pl.fit_wolf(meas, g).coef  # (T, 10, 2)

    def one(t):
        return linalg.lstsq(pl.design(meas[t], pl.WOLF_TERMS), g - meas[t])[0]

    n = min(T, 400)  # the most the bench's SciPy loop times
    As = [np.asfortranarray(pl.design(meas[t], pl.WOLF_TERMS)) for t in range(n)]
    bs = [np.asfortranarray(g - meas[t]) for t in range(n)]
    return Case(
        len(g),
        engine,
        one,
        TOL_POLY_MM,
        "mm (coefficients)",
        _SCIPY,
        _WHY_PER_TRIAL,
        _dgels(As, bs),
        _FLOOR,
        module="sim.instruments.plotter.polynomial_kernel (with sim.lsq.linear_kernel.solve_lanes)",
    )


def polynomial_shared(T: int, seed: int = 6) -> Case:
    """The same polynomial on the grid's nominal coordinates: one design for all trials."""
    g, meas = _calibration(T, seed)
    A = pl.design(g, pl.WOLF_TERMS)
    d = meas - g

    def engine():
        return lstsq(A, d).x

    def one(t):
        return linalg.lstsq(A, d[t])[0]

    n = min(T, 400)
    Af = np.asfortranarray(A)
    return Case(
        len(g),
        engine,
        one,
        TOL_POLY_MM,
        "mm (coefficients)",
        _SCIPY,
        _WHY,
        _dgels([Af] * n, [np.asfortranarray(d[t]) for t in range(n)]),
        _FLOOR,
        module="sim.lsq.linear_kernel (shared_solve)",
    )


#: the stress field's values agree to this (um; values of a few um, rounding of 16 terms)
TOL_STRESS_UM = 1e-11
_STRESS_WHY = "a field evaluation per trial is a few NumPy calls; its cost is the sines"


def _stress_draw(T: int, seed: int):
    """The study's stress field (8 um rms, 70 mm, 16 waves) drawn for ``T`` trials, at the
    198 calibration points: ``(spec, params, points (198, 2) mm)``."""
    g, _ = _calibration(1, seed)
    spec = ef.FieldSpec(stress_um=8.0, stress_length_mm=70.0)
    return spec, ef.draw(spec, np.random.default_rng(seed), T), g


def _stress_one(params, g):
    """Trial ``t``'s field by NumPy's formula (the loop side)."""
    q = params["stress"]
    K = q["w"].shape[1]

    def one(t):
        ph = g @ q["w"][t].T
        bc, bs = q["b"][t] * np.cos(q["phi"][t]), q["b"][t] * np.sin(q["phi"][t])
        return q["a"][t] * np.sqrt(2.0 / K) * (np.cos(ph) @ bc - np.sin(ph) @ bs)

    return one


def stress(T: int, seed: int = 7) -> Case:
    """The stress component, compiled or NumPy, at the 198 points."""
    spec, params, g = _stress_draw(T, seed)

    def engine():
        return ef.evaluate_components(spec, params, g, skip_zero=True)["stress"]

    return Case(
        len(g),
        engine,
        _stress_one(params, g),
        TOL_STRESS_UM,
        "um (displacements)",
        "NumPy per trial (no SciPy routine)",
        _STRESS_WHY,
        module="sim.instruments.plotter.errorfield_kernel",
    )


def _stress_libm(X, Y, w, bc, bs, scale, out):  # pragma: no cover - compiled
    """errorfield_kernel._stress with the library's ``np.sin``, ``np.cos`` (the bench's
    counterpart of the hand-written :func:`~sim.instruments.plotter.errorfield_kernel.sincos`)."""
    T, n = X.shape
    K = w.shape[1]
    f0, f1 = np.empty(n), np.empty(n)
    for t in range(T):
        f0[:] = 0.0
        f1[:] = 0.0
        for k in range(K):
            wx, wy = w[t, k, 0], w[t, k, 1]
            c0, c1, s0, s1 = bc[t, k, 0], bc[t, k, 1], bs[t, k, 0], bs[t, k, 1]
            for i in range(n):
                ph = X[t, i] * wx + Y[t, i] * wy
                s, c = np.sin(ph), np.cos(ph)
                f0[i] += c * c0 - s * s0
                f1[i] += c * c1 - s * s1
        for i in range(n):
            out[t, i, 0] = scale[t] * f0[i]
            out[t, i, 1] = scale[t] * f1[i]


def stress_sincos(T: int, seed: int = 7) -> Case:
    """The compiled stress kernel with its own sine and cosine against the library's."""
    spec, params, g = _stress_draw(T, seed)
    q = params["stress"]
    P = np.broadcast_to(g, (T,) + g.shape)
    scale = q["a"] * np.sqrt(2.0 / q["w"].shape[1])

    def engine():
        return ek.stress_field(P, q["w"], q["b"], q["phi"], scale)

    def libm():
        X = np.ascontiguousarray(P[..., 0])
        Y = np.ascontiguousarray(P[..., 1])
        bc = np.ascontiguousarray(q["b"] * np.cos(q["phi"]))
        bs = np.ascontiguousarray(q["b"] * np.sin(q["phi"]))
        out = np.empty((T, len(g), 2))
        if compile.available():
            compile.compiled(_stress_libm)(X, Y, q["w"], bc, bs, scale, out)
        return out

    return Case(
        len(g),
        engine,
        _stress_one(params, g),
        TOL_STRESS_UM,
        "um (displacements)",
        "NumPy per trial (no SciPy routine)",
        _STRESS_WHY,
        module="sim.instruments.plotter.errorfield_kernel (sincos)",
        numpy=libm,
        numpy_label="the same compiled kernel with the library's sin and cos",
    )
