"""Linear engine rows of the benchmark: Wolf & Pearsall's polynomial calibration.

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

The SciPy side is what a user would write for one trial: ``scipy.linalg.lstsq`` (LAPACK
``gelsd``) of the trial's design against its two right-hand sides. Where a row falls below
the issue's 50x, its note times, beside both sides, LAPACK's QR least squares (``dgels``)
alone on a prepared design per trial, the floor of any per-trial loop.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg

from benchmarks.engines import Case
from sim.instruments.plotter import polynomial as pl
from sim.lsq.linear import lstsq

__all__ = ["polynomial", "polynomial_shared"]

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
    from scipy.linalg import lapack

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
    )
