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
problems are solved apart and the covariance is block diagonal:
``cov = s0^2 diag((G^T W G)^-1, (G^T W G)^-1)`` with ``s0^2 = v^T W v / (2n - 6)`` (the
a-posteriori variance of unit weight) unless an a-priori ``sigma0`` is given.

Decompositions of the linear part ``M = [[a1, b1], [a2, b2]]`` (all angles in radians):

* :func:`decompose_rows` -- seed 001 (grid -> comparator): the rows of ``M`` are the comparator
  axes seen from the grid, divided by their scale::

      S = 1/sqrt(a1^2 + b1^2),  S' = 1/sqrt(a2^2 + b2^2),
      phi = atan(b1/a1),  phi' = atan(b2/a2),  eps = pi/2 - (phi' - phi)

* :func:`decompose_columns` -- seed 002 (instrument -> grid): the columns of ``M`` are the
  images of the instrument's unit steps::

      SX = sqrt(A^2 + D^2),  SY = sqrt(B^2 + E^2),
      theta_x = atan2(D, A),  theta_y = atan2(E, B),  E_angle = pi/2 - (theta_y - theta_x)

  With this sign Salsig's printed parameters give E = -14.0" (FIG. 2) and -59.2" (FIG. 3);
  the sign of D is lost in the OCR and must be negative for that (the other sign gives
  about -4630").

Both conventions measure the same non-orthogonality with opposite signs: the rows of ``M^-1``
are perpendicular to the columns of ``M``, so ``eps`` (rows) of a grid -> instrument affine
equals ``-E`` (columns) of its inverse instrument -> grid, and ``S`` equals ``SX cos(E)``
(the scales differ in second order only: 4e-8 at 59"). ``eps > 0`` means the rows (seed 001's
"axes") are less than 90 degrees apart; ``E < 0`` means the instrument's axes (columns) are
more than 90 degrees apart. Seed 001's correction formula of its FIG. 3
(``x_c = S x' + S' y' sin eps``, ``y_c = S' y' cos eps``) reads ``eps`` as the tilt of the
y' axis itself, which is the opposite sign of its own row definition; the code follows the
row definition (the paper's equations for ``phi`` and ``phi'``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Fit", "fit_similarity", "fit_affine", "apply_affine", "apply_similarity",
           "affine_from_columns", "affine_from_rows", "invert_affine", "inverse_decomposition", "decompose_rows", "decompose_columns",
           "propagate", "ARCSEC"]

#: radians per arc second
ARCSEC = np.pi / 180 / 3600


@dataclass
class Fit:
    """Result of a batched least-squares transformation fit.

    params : (T, p) parameters; cov : (T, p, p) covariance (``s0^2 Q`` or ``sigma0^2 Q``);
    cofactor : (T, p, p) ``Q = (A^T W A)^-1``; s0 : (T,) a-posteriori standard error of unit
    weight; residuals : (T, n, 2) ``dst - fitted`` (observed minus adjusted); dof : redundancy.
    """

    params: np.ndarray
    cov: np.ndarray
    cofactor: np.ndarray
    s0: np.ndarray
    residuals: np.ndarray
    dof: int


def _batch(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, float)
    return a[None] if a.ndim == 2 else a


def _weights(w, T: int, n: int) -> np.ndarray:
    if w is None:
        return np.ones((T, n))
    w = np.asarray(w, float)
    return np.broadcast_to(w, (T, n)) if w.ndim <= 2 else w


def fit_affine(src, dst, w=None, sigma0: float | None = None) -> Fit:
    """Six-parameter affine ``dst = M src + c`` by (weighted) least squares.

    Parameters
    ----------
    src, dst : (T, n, 2) or (n, 2) arrays; ``src`` is error-free, ``dst`` observed.
    w : optional weights per point, (n,) or (T, n), the same for x and y.
    sigma0 : a-priori standard error of unit weight; if given, ``cov = sigma0^2 Q``
        instead of ``s0^2 Q``.
    """
    src, dst = _batch(src), _batch(dst)
    T, n = dst.shape[0], dst.shape[1]
    src = np.broadcast_to(src, dst.shape)
    W = _weights(w, T, n)
    G = np.concatenate([src, np.ones((T, n, 1))], axis=-1)          # (T, n, 3)
    N = np.einsum("tni,tn,tnj->tij", G, W, G)
    Q3 = np.linalg.inv(N)
    rhs = np.einsum("tni,tn,tnk->tik", G, W, dst)                  # (T, 3, 2)
    sol = Q3 @ rhs                                                  # columns: x-row, y-row
    params = np.concatenate([sol[..., 0], sol[..., 1]], axis=-1)    # (T, 6)
    res = dst - np.einsum("tni,tik->tnk", G, sol)
    dof = 2 * n - 6
    s0 = np.sqrt(np.einsum("tnk,tn,tnk->t", res, W, res) / dof) if dof > 0 else np.full(T, np.nan)
    Q = np.zeros((T, 6, 6))
    Q[:, :3, :3] = Q3
    Q[:, 3:, 3:] = Q3
    scale = (s0 ** 2 if sigma0 is None else np.full(T, float(sigma0) ** 2))
    return Fit(params, Q * scale[:, None, None], Q, s0, res, dof)


def fit_similarity(src, dst, w=None, sigma0: float | None = None) -> Fit:
    """Four-parameter similarity ``x' = a x + b y + c``, ``y' = -b x + a y + c'``.

    Same arguments as :func:`fit_affine`; ``params = (a, b, c, c')``. Seed 001's variance
    of unit weight ``sum(vx^2 + vy^2) / (2N - 4)`` is ``s0^2``.
    """
    src, dst = _batch(src), _batch(dst)
    T, n = dst.shape[0], dst.shape[1]
    src = np.broadcast_to(src, dst.shape)
    W = _weights(w, T, n)
    x, y = src[..., 0], src[..., 1]
    one, zero = np.ones_like(x), np.zeros_like(x)
    Ax = np.stack([x, y, one, zero], -1)                            # rows for x'
    Ay = np.stack([y, -x, zero, one], -1)                           # rows for y'
    A = np.concatenate([Ax, Ay], axis=1)                            # (T, 2n, 4)
    l = np.concatenate([dst[..., 0], dst[..., 1]], axis=1)
    WW = np.concatenate([W, W], axis=1)
    N = np.einsum("tni,tn,tnj->tij", A, WW, A)
    Q = np.linalg.inv(N)
    params = np.einsum("tij,tnj,tn,tn->ti", Q, A, WW, l)
    v = l - np.einsum("tni,ti->tn", A, params)
    res = np.stack([v[:, :n], v[:, n:]], -1)
    dof = 2 * n - 4
    s0 = np.sqrt(np.einsum("tn,tn,tn->t", v, WW, v) / dof) if dof > 0 else np.full(T, np.nan)
    scale = (s0 ** 2 if sigma0 is None else np.full(T, float(sigma0) ** 2))
    return Fit(params, Q * scale[:, None, None], Q, s0, res, dof)


def apply_affine(params, pts) -> np.ndarray:
    """Apply affine ``params`` (T, 6) to ``pts`` (T, n, 2) or (n, 2); returns (T, n, 2)."""
    p = np.asarray(params, float)
    p = p[None] if p.ndim == 1 else p
    pts = np.asarray(pts, float)
    x, y = pts[..., 0], pts[..., 1]
    if pts.ndim == 2:
        x, y = x[None], y[None]
    X = p[:, 0, None] * x + p[:, 1, None] * y + p[:, 2, None]
    Y = p[:, 3, None] * x + p[:, 4, None] * y + p[:, 5, None]
    return np.stack([X, Y], -1)


def apply_similarity(params, pts) -> np.ndarray:
    """Apply similarity ``params`` (T, 4) ``(a, b, c, c')`` to ``pts``; returns (T, n, 2)."""
    p = np.asarray(params, float)
    p = p[None] if p.ndim == 1 else p
    a, b, c, c2 = (p[:, i] for i in range(4))
    return apply_affine(np.stack([a, b, c, -b, a, c2], -1), pts)


def affine_from_columns(sx, sy, e_rad, rot_rad=0.0, shift=(0.0, 0.0)) -> np.ndarray:
    """Affine parameters (..., 6) with the column decomposition ``(SX, SY, E)`` of seed 002,
    rotated by ``rot_rad`` (the image of the x step at angle ``rot_rad``) and shifted."""
    sx, sy, e, r = np.broadcast_arrays(*(np.asarray(v, float) for v in (sx, sy, e_rad, rot_rad)))
    tx = r
    ty = r + np.pi / 2 - e
    cx, cy = np.broadcast_to(shift[0], sx.shape), np.broadcast_to(shift[1], sx.shape)
    return np.stack([sx * np.cos(tx), sy * np.cos(ty), cx, sx * np.sin(tx), sy * np.sin(ty), cy], -1)


def affine_from_rows(s, s2, eps_rad, phi_rad=0.0, shift=(0.0, 0.0)) -> np.ndarray:
    """Affine parameters (..., 6) with the row decomposition ``(S, S', eps, phi)`` of seed 001:
    row 1 = ``(cos phi, sin phi)/S``, row 2 = ``(cos phi', sin phi')/S'`` with
    ``phi' = phi + pi/2 - eps``."""
    s, s2, e, f = np.broadcast_arrays(*(np.asarray(v, float) for v in (s, s2, eps_rad, phi_rad)))
    f2 = f + np.pi / 2 - e
    cx, cy = np.broadcast_to(shift[0], s.shape), np.broadcast_to(shift[1], s.shape)
    return np.stack([np.cos(f) / s, np.sin(f) / s, cx, np.cos(f2) / s2, np.sin(f2) / s2, cy], -1)


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def decompose_rows(params, cov=None) -> dict[str, np.ndarray]:
    """Seed 001's decomposition of an affine grid -> comparator.

    Returns ``S``, ``S2`` (S'), ``phi``, ``phi2`` (phi'), ``eps`` (radians; ``phi' - phi =
    pi/2 - eps``). With ``cov`` (T, 6, 6) also ``cov`` of ``(S, S', eps)`` (T, 3, 3) by
    first-order propagation.
    """
    p = np.asarray(params, float)
    a1, b1, a2, b2 = p[..., 0], p[..., 1], p[..., 3], p[..., 4]
    r1, r2 = np.hypot(a1, b1), np.hypot(a2, b2)
    phi, phi2 = np.arctan2(b1, a1), np.arctan2(b2, a2)
    eps = _wrap(np.pi / 2 - (phi2 - phi))
    out = {"S": 1 / r1, "S2": 1 / r2, "phi": phi, "phi2": phi2, "eps": eps}
    if cov is not None:
        J = np.zeros(p.shape[:-1] + (3, 6))
        J[..., 0, 0], J[..., 0, 1] = -a1 / r1 ** 3, -b1 / r1 ** 3
        J[..., 1, 3], J[..., 1, 4] = -a2 / r2 ** 3, -b2 / r2 ** 3
        # eps = pi/2 - phi2 + phi
        J[..., 2, 0], J[..., 2, 1] = -b1 / r1 ** 2, a1 / r1 ** 2
        J[..., 2, 3], J[..., 2, 4] = b2 / r2 ** 2, -a2 / r2 ** 2
        out["cov"] = propagate(J, cov)
    return out


def decompose_columns(params, cov=None) -> dict[str, np.ndarray]:
    """Salsig's (seed 002) decomposition of an affine instrument -> grid.

    Returns ``SX``, ``SY``, ``E`` (radians, ``theta_y - theta_x = pi/2 - E``), ``theta_x``,
    ``theta_y``. With ``cov`` (T, 6, 6) also ``cov`` of ``(SX, SY, E)`` (T, 3, 3).
    """
    p = np.asarray(params, float)
    A, B, D, E = p[..., 0], p[..., 1], p[..., 3], p[..., 4]
    sx, sy = np.hypot(A, D), np.hypot(B, E)
    tx, ty = np.arctan2(D, A), np.arctan2(E, B)
    e = _wrap(np.pi / 2 - (ty - tx))
    out = {"SX": sx, "SY": sy, "E": e, "theta_x": tx, "theta_y": ty}
    if cov is not None:
        J = np.zeros(p.shape[:-1] + (3, 6))
        J[..., 0, 0], J[..., 0, 3] = A / sx, D / sx
        J[..., 1, 1], J[..., 1, 4] = B / sy, E / sy
        # E = pi/2 - ty + tx ; d tx/dA = -D/sx^2, d tx/dD = A/sx^2 ; d ty/dB = -E/sy^2, dE: B/sy^2
        J[..., 2, 0], J[..., 2, 3] = -D / sx ** 2, A / sx ** 2
        J[..., 2, 1], J[..., 2, 4] = E / sy ** 2, -B / sy ** 2
        out["cov"] = propagate(J, cov)
    return out


def invert_affine(params) -> np.ndarray:
    """Parameters (..., 6) of the inverse of the affine ``params`` (..., 6)."""
    p = np.asarray(params, float)
    a, b, c, d, e, f = (p[..., i] for i in range(6))
    det = a * e - b * d
    ia, ib, id_, ie = e / det, -b / det, -d / det, a / det
    return np.stack([ia, ib, -(ia * c + ib * f), id_, ie, -(id_ * c + ie * f)], -1)


def inverse_decomposition(params, cov, h: float = 1e-7) -> dict[str, np.ndarray]:
    """Seed 002's ``(SX, SY, E)`` of the *inverse* of a fitted affine, with covariance.

    Salsig's program fits the observed system ``X2`` as the function of the control ``X1``
    (residuals ``VX2``, ``VY2`` in ``X2`` units) and prints the parameters of
    ``X1 = A X2 + B Y2 + C``. ``params``/``cov`` (T, 6)/(T, 6, 6) are those of the fitted
    direction ``X2 = f(X1)``; the Jacobian of inversion + decomposition is taken by central
    differences (relative step ``h``).
    """
    p = np.asarray(params, float)
    base = decompose_columns(invert_affine(p))
    J = np.zeros(p.shape[:-1] + (3, 6))
    for i in range(6):
        step = h * np.maximum(np.abs(p[..., i]), 1e-3)
        dp = np.zeros_like(p)
        dp[..., i] = step
        hi, lo = decompose_columns(invert_affine(p + dp)), decompose_columns(invert_affine(p - dp))
        for j, k in enumerate(("SX", "SY", "E")):
            J[..., j, i] = (hi[k] - lo[k]) / (2 * step)
    base["params"] = invert_affine(p)
    base["cov"] = propagate(J, cov)
    return base


def propagate(J, cov) -> np.ndarray:
    """First-order propagation ``J C J^T`` over a leading batch axis."""
    return np.einsum("...ia,...ab,...jb->...ij", J, cov, J)
