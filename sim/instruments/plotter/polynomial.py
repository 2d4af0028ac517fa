"""Polynomial error models and plane transformations, batched over trials.

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976, *The Kern PG-2 as a
Monocomparator*). The paper corrects measured model coordinates ``X, Y`` (mm, already
reduced to the grid system) with a third-degree, ten-term polynomial per axis::

    x = X + A1 + A2 X + A3 X^2 + A4 Y + A5 Y^2 + A6 X Y + A7 X^2 Y + A8 X Y^2 + A9 X^3 + A10 Y^3
    y = Y + B1 + B2 X + B3 X^2 + B4 Y + B5 Y^2 + B6 X Y + B7 X^2 Y + B8 X Y^2 + B9 X^3 + B10 Y^3

fitted by least squares to the grid intersections of several independent sets. The ten
terms are the complete set of monomials of total degree <= 3, so the general degree-``d``
polynomial of :func:`poly_terms` (``(d+1)(d+2)/2`` terms) contains it as ``d = 3``
(with another ordering; :data:`WOLF_TERMS` keeps the paper's A1...A10 order).

The raw readings are reduced first with the paper's *non-redundant* two-point
transformation (:func:`two_point_transform`): scale from the length of line ``ab``,
translation to ``a``, rotation by ``alpha = atan(Y''_b / X''_b)``. It uses no redundancy
on purpose, so that the discrepancies of the measuring system are preserved. For
comparison, least-squares similarity and affine fits come from :mod:`sim.instruments.transforms2d`.

Shapes: every function takes a leading *trial* axis ``T``: points ``(T, n, 2)`` (a plain
``(n, 2)`` broadcasts). Coordinates in mm; the polynomial works internally in
``coordinate / norm_mm`` (default 100 mm) so that the normal equations stay well
conditioned up to degree 5 or more.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.instruments.plotter import polynomial_kernel
from sim.lsq import compile
from sim.lsq.linear import lstsq
from sim.lsq.normals import RCOND

__all__ = [
    "WOLF_TERMS",
    "poly_terms",
    "design",
    "PolyFit",
    "fit_poly",
    "fit_wolf",
    "apply_poly",
    "two_point_transform",
    "TwoPoint",
    "apply_two_point",
    "discrepancy_stats",
]

#: exponents (i, j) of X^i Y^j for the paper's A1 ... A10 (and B1 ... B10), in its order
WOLF_TERMS = ((0, 0), (1, 0), (2, 0), (0, 1), (0, 2), (1, 1), (2, 1), (1, 2), (3, 0), (0, 3))


def poly_terms(degree: int) -> tuple[tuple[int, int], ...]:
    """Exponents ``(i, j)`` of all monomials ``X^i Y^j`` with ``i + j <= degree``.

    Ordered by total degree, then by decreasing power of X: ``(d+1)(d+2)/2`` terms.
    """
    if degree < 0:
        raise ValueError(f"degree must be >= 0 (got {degree})")
    return tuple((t - j, j) for t in range(degree + 1) for j in range(t + 1))


def design(pts: np.ndarray, terms, norm_mm: float = 100.0) -> np.ndarray:
    """Design matrix ``(..., n, p)`` of the monomials ``terms`` at ``pts`` ``(..., n, 2)`` mm.

    Columns are ``(X / norm)^i (Y / norm)^j``. Each column is built as one contiguous vector
    over all trials and points (the returned array is a transposed view of a ``(p, ...)``
    array: every trial's block is Fortran-ordered, which the matrix products take as it is).
    """
    u = np.asarray(pts, float) / norm_mm
    lead = u.shape[:-1]
    N = int(np.prod(lead))
    x = np.ascontiguousarray(u[..., 0]).reshape(N)
    y = np.ascontiguousarray(u[..., 1]).reshape(N)
    mx = max(i for i, _ in terms)
    my = max(j for _, j in terms)
    px = np.empty((mx + 1, N))  # powers first: each power a contiguous array
    py = np.empty((my + 1, N))
    px[0], py[0] = 1.0, 1.0
    for i in range(mx):  # successive products: the same numbers as x**i
        np.multiply(px[i], x, out=px[i + 1])
    for j in range(my):
        np.multiply(py[j], y, out=py[j + 1])
    A = np.empty((len(terms), N))
    for c, (i, j) in enumerate(terms):  # over the p terms, not trials
        np.multiply(px[i], py[j], out=A[c])
    return A.T.reshape(lead + (len(terms),))


@dataclass(frozen=True)
class PolyFit:
    """A fitted correction polynomial per axis.

    coef : ``(T, p, 2)`` coefficients of the correction in mm (column 0: x, 1: y) on the
        normalised monomials; NaN where the fit was not estimable.
    terms : the exponents of the ``p`` monomials.
    norm_mm : coordinate normalisation.
    ok : ``(T,)`` the fit was estimable (the scaled singularity rule of :mod:`sim.lsq.linear`).
    rms_mm : ``(T, 2)`` rms residual per axis on the fitting data.
    corrected_mm : ``(T, n, 2)`` the fitting data corrected, ``X + P(X, Y)`` (the numbers of
        :func:`apply_poly` at the measured points, without building their design again), when
        asked for (``fit_poly(..., corrected=True)``), else None.
    """

    coef: np.ndarray
    terms: tuple
    norm_mm: float
    ok: np.ndarray
    rms_mm: np.ndarray
    corrected_mm: np.ndarray | None = None

    @property
    def degree(self) -> int:
        return max(i + j for i, j in self.terms)

    def coefficients_mm(self) -> np.ndarray:
        """Coefficients for unnormalised ``X, Y`` in mm (``A_k = c_k / norm^(i+j)``), ``(T, p, 2)``."""
        s = np.array([self.norm_mm ** -(i + j) for i, j in self.terms])
        return self.coef * s[None, :, None]


def fit_poly(
    measured: np.ndarray,
    true: np.ndarray,
    degree: int | None = 3,
    terms=None,
    norm_mm: float = 100.0,
    corrected: bool = False,
    jit: bool = True,
) -> PolyFit:
    """Fit the correction ``true - measured = P(measured)`` by least squares, per trial.

    Parameters
    ----------
    measured, true : ``(T, n, 2)`` mm (or ``(n, 2)`` for ``true``). Pool several sets by
        concatenating them along the point axis.
    degree : total degree of the complete polynomial (ignored when ``terms`` is given).
    terms : explicit exponents, e.g. :data:`WOLF_TERMS`.
    corrected : also return the fitting data corrected (:attr:`PolyFit.corrected_mm`).
    jit : use the compiled fast path where numba is installed (:mod:`sim.instruments.plotter.polynomial_kernel`,
        equal to the NumPy path to rounding); False: the NumPy path
        (:func:`sim.lsq.linear.lstsq` on the batch's designs).

    A degree-1 polynomial is the general affine transformation ``x = X + A1 + A2 X + A4 Y``.
    """
    measured = np.asarray(measured, float)
    true = np.broadcast_to(np.asarray(true, float), measured.shape)
    terms = tuple(terms) if terms is not None else poly_terms(degree)
    if jit and measured.ndim == 3 and compile.available():
        return _fit_compiled(measured, true, terms, float(norm_mm), corrected)
    A = design(measured, terms, norm_mm)  # (T, n, p): one R0 for all trials
    f = lstsq(A, true - measured)
    rms = np.sqrt(np.mean(f.residuals**2, axis=1))
    return PolyFit(
        f.x, terms, float(norm_mm), f.ok, rms, measured + np.matmul(A, f.x) if corrected else None
    )


def _fit_compiled(measured, true, terms, norm_mm, corrected) -> PolyFit:
    """:func:`fit_poly` on the compiled fast path (:mod:`sim.instruments.plotter.polynomial_kernel`): each
    trial's normal equations formed from its points in the cache, solved eight trials at a
    time by the engine's :func:`sim.lsq.linear_kernel.solve_lanes` (the scaled rule); trials
    it cannot prove regular are fitted again by :func:`sim.lsq.linear.lstsq` on their designs
    (the exact rule), so status and decisions are the engine's."""
    true_ = true[0] if true.strides[0] == 0 else true  # broadcast: one set of points
    x, status, sq, corr = polynomial_kernel.fit(measured, true_, terms, norm_mm, corrected, RCOND)
    rest = np.flatnonzero(status == polynomial_kernel.UNDECIDED)
    if rest.size:  # the exact rule: the engine's NumPy path
        A = design(measured[rest], terms, norm_mm)
        g = lstsq(A, true[rest] - measured[rest], rcond=RCOND)
        x[rest], status[rest], sq[rest] = g.x, g.status, g.vtpv
        if corrected:
            corr[rest] = measured[rest] + np.matmul(A, g.x)
    return PolyFit(x, terms, norm_mm, status == 0, np.sqrt(sq / measured.shape[1]), corr)


def fit_wolf(measured: np.ndarray, true: np.ndarray, norm_mm: float = 100.0) -> PolyFit:
    """The paper's ten-term third-degree polynomial (A1...A10, B1...B10 in its order)."""
    return fit_poly(measured, true, terms=WOLF_TERMS, norm_mm=norm_mm)


def apply_poly(fit: PolyFit, measured: np.ndarray) -> np.ndarray:
    """Refined coordinates ``X + P(X, Y)`` ``(T, n, 2)`` mm for new measured points."""
    measured = np.asarray(measured, float)
    A = design(measured, fit.terms, fit.norm_mm)
    return measured + np.matmul(A, fit.coef)


# ----------------------------------------------------------------------------- two-point reduction


@dataclass(frozen=True)
class TwoPoint:
    """The paper's non-redundant reduction: ``x = R(-alpha) (s C - s C_a) + g_a``.

    scale : ``(T,)`` mm per reading unit (``|ab| grid / |ab| measured``).
    origin : ``(T, 2)`` the reading of ``a`` (reading units).
    alpha : ``(T,)`` rotation (rad) from the scaled, translated system to the grid system.
    a_grid : ``(2,)`` grid coordinates of ``a`` (mm).
    """

    scale: np.ndarray
    origin: np.ndarray
    alpha: np.ndarray
    a_grid: np.ndarray


def two_point_transform(read_a: np.ndarray, read_b: np.ndarray, grid_a, grid_b) -> TwoPoint:
    """The non-redundant two-point transformation of Wolf & Pearsall.

    ``read_a, read_b`` ``(T, 2)`` readings (any unit, e.g. counts) of points ``a`` and ``b``;
    ``grid_a, grid_b`` ``(2,)`` their grid coordinates (mm). Scale from line ``ab``, translate
    to ``a``, rotate by ``alpha = atan2(Y''_b, X''_b)`` less the grid direction of ``ab`` (zero
    in the paper, where ``b`` lies on the grid x axis). ``a`` and ``b`` are reproduced exactly.
    """
    read_a = np.asarray(read_a, float)
    read_b = np.asarray(read_b, float)
    ga = np.asarray(grid_a, float)
    gb = np.asarray(grid_b, float)
    d = read_b - read_a
    L = np.hypot(d[..., 0], d[..., 1])
    scale = np.hypot(*(gb - ga)) / L
    alpha = np.arctan2(d[..., 1], d[..., 0]) - np.arctan2(gb[1] - ga[1], gb[0] - ga[0])
    return TwoPoint(scale, read_a, alpha, ga)


def apply_two_point(tp: TwoPoint, readings: np.ndarray) -> np.ndarray:
    """Reduce readings ``(T, n, 2)`` to the grid system (mm) with a :class:`TwoPoint`."""
    r = (np.asarray(readings, float) - tp.origin[:, None, :]) * tp.scale[:, None, None]
    c, s = np.cos(tp.alpha)[:, None], np.sin(tp.alpha)[:, None]
    x = c * r[..., 0] + s * r[..., 1]
    y = -s * r[..., 0] + c * r[..., 1]
    return np.stack([x, y], axis=-1) + tp.a_grid


# ----------------------------------------------------------------------------- statistics


def discrepancy_stats(d: np.ndarray, axis: int = -2) -> dict[str, np.ndarray]:
    """The paper's summary statistics of discrepancies: ``max``, ``rms``, ``mean``.

    All of absolute values along ``axis`` (the point axis): ``max |d|``,
    ``sqrt(mean d^2)``, ``mean |d|``. For ``d (T, n, 2)`` each is ``(T, 2)`` (x, y).
    """
    a = np.abs(np.asarray(d, float))
    if a.ndim == 3 and axis in (1, -2):  # points contiguous: reductions along the last axis
        a = np.ascontiguousarray(a.transpose(0, 2, 1))
        axis = -1
    return {
        "max": a.max(axis=axis),
        "rms": np.sqrt(np.mean(a * a, axis=axis)),
        "mean": a.mean(axis=axis),
    }
