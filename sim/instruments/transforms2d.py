"""Plane coordinate transformations fitted by least squares, batched over trials.

Seeds: ``001_7e3a2951e7fed426.txt`` (*Calibration of a Comparator*, two grid plates, Zeiss
PSK) and ``002_fb81c7b0481438c4.txt`` (Salsig 1985, *Calibrating Stereo Plotter Encoders*).

Models (``src`` -> ``dst``; both ``(T, n, 2)``, any consistent length unit):

* similarity (4 parameters, seed 001's "isogonal affine")::

      x' =  a x + b y + c
      y' = -b x + a y + c'          p = (a, b, c, c')

* affine (6 parameters, seed 001's equation 2 and Salsig's ``X1 = A X2 + B Y2 + C``,
  ``Y1 = D X2 + E Y2 + F``)::

      x' = a1 x + b1 y + c1
      y' = a2 x + b2 y + c2          p = (a1, b1, c1, a2, b2, c2) = (A, B, C, D, E, F)

The affine's two rows share one design matrix ``G = [x, y, 1]``, so the two 3-parameter
problems are one solve with two right-hand sides of the library's one linear routine
(:func:`sim.lsq.linear.lstsq`; factorised once when ``src`` is shared by every trial) and the
covariance is block diagonal:
``cov = s0^2 diag((G^T W G)^-1, (G^T W G)^-1)`` with ``s0^2 = v^T W v / (2n - 6)`` (the
a-posteriori variance of unit weight) unless an a-priori ``sigma0`` is given.

The similarity is :func:`sim.instruments.geometry.similarity_fit`; the affine apply, build, invert and
decomposition functions live in :mod:`sim.instruments.geometry` (one convention for the whole library)
and are re-exported here. A singular trial (collinear points) is flagged in ``Fit.status``
with NaN parameters, never raised.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim.instruments.geometry import (
    ARCSEC,
    _wrap,
    affine_from_columns,
    affine_from_rows,
    apply_affine,
    apply_similarity,
    decompose_columns,
    decompose_rows,
    inverse_decomposition,
    invert_affine,
    propagate,
    similarity_fit,
)
from sim.lsq.linear import lstsq

__all__ = [
    "Fit",
    "fit_similarity",
    "fit_affine",
    "apply_affine",
    "apply_similarity",
    "affine_from_columns",
    "affine_from_rows",
    "invert_affine",
    "inverse_decomposition",
    "decompose_rows",
    "decompose_columns",
    "propagate",
    "ARCSEC",
    "_wrap",
]


@dataclass
class Fit:
    """Result of a batched least-squares transformation fit.

    params : (T, p) parameters; cov : (T, p, p) covariance (``s0^2 Q`` or ``sigma0^2 Q``);
    cofactor : (T, p, p) ``Q = (A^T W A)^-1``; s0 : (T,) a-posteriori standard error of unit
    weight; residuals : (T, n, 2) ``dst - fitted`` (observed minus adjusted); dof : redundancy;
    status : (T,) int8, 0 where solved (:data:`sim.lsq.linear.LINEAR_STATUS`).
    """

    params: np.ndarray
    cov: np.ndarray
    cofactor: np.ndarray
    s0: np.ndarray
    residuals: np.ndarray
    dof: int
    status: np.ndarray | None = None


def _cov(Q, s0, sigma0):
    scale = s0**2 if sigma0 is None else np.full(len(s0), float(sigma0) ** 2)
    return Q * scale[:, None, None]


def fit_affine(src, dst, w=None, sigma0: float | None = None) -> Fit:
    """Six-parameter affine ``dst = M src + c`` by (weighted) least squares.

    Parameters
    ----------
    src, dst : (T, n, 2) or (n, 2) arrays; ``src`` is error-free, ``dst`` observed.
    w : optional weights per point, (n,) or (T, n), the same for x and y.
    sigma0 : a-priori standard error of unit weight; if given, ``cov = sigma0^2 Q``
        instead of ``s0^2 Q``.
    """
    dst = np.asarray(dst, float)
    dst = dst[None] if dst.ndim == 2 else dst
    src = np.asarray(src, float)
    G = np.concatenate([src, np.ones(src.shape[:-1] + (1,))], axis=-1)  # (n, 3) or (T, n, 3)
    if G.ndim == 3 and G.shape[0] != dst.shape[0]:
        G = np.broadcast_to(G, dst.shape[:2] + (3,))
    f = lstsq(G, dst, w)  # x: (T, 3, 2)
    params = np.concatenate([f.x[..., 0], f.x[..., 1]], axis=-1)  # (T, 6)
    T = dst.shape[0]
    Q3 = f.cofactor()
    Q = np.zeros((T, 6, 6))
    Q[:, :3, :3] = Q3
    Q[:, 3:, 3:] = Q3
    dof = 2 * f.dof
    return Fit(params, _cov(Q, f.s0, sigma0), Q, f.s0, f.residuals, dof, f.status)


def fit_similarity(src, dst, w=None, sigma0: float | None = None) -> Fit:
    """Four-parameter similarity ``x' = a x + b y + c``, ``y' = -b x + a y + c'``.

    Same arguments as :func:`fit_affine`; ``params = (a, b, c, c')``. Seed 001's variance
    of unit weight ``sum(vx^2 + vy^2) / (2N - 4)`` is ``s0^2``. The fit is
    :func:`sim.instruments.geometry.similarity_fit`.
    """
    s = similarity_fit(src, dst, w)
    f = s.linear
    Q = f.cofactor()
    return Fit(f.x[..., 0], _cov(Q, s.s0, sigma0), Q, s.s0, s.residuals, s.dof, s.status)
