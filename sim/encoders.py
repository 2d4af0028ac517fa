"""Stereo-plotter encoder calibration pieces (Salsig 1985, seed ``002_fb81c7b0481438c4.txt``).

* :func:`line_fit` -- the z encoder: ``H = S z + z0`` fitted by least squares to readings
  ``z`` (digits) at known glass-scale elevations ``H`` (mm), with the standard errors of
  ``S`` (mm/digit) and ``z0`` (mm) from the a-posteriori variance (``n - 2`` degrees of
  freedom). ``z`` is taken as error-free and ``H`` as observed, as the paper's equation is
  written; a reading error ``sigma_z`` (digits) acts as ``S sigma_z`` in ``H``.
* :func:`conformal3d_fit` -- the 3-D conformal (7-parameter) transformation
  ``Y = lam R X + t`` of model coordinates ``X`` to ground control ``Y``, equal weights,
  solved in closed form (Umeyama 1991; Horn 1987): the least-squares solution the iterated
  7-parameter adjustment converges to. Batched SVD of the 3 x 3 cross-covariance.

All functions take a leading trial axis ``T``.
"""
from __future__ import annotations

import numpy as np

__all__ = ["line_fit", "conformal3d_fit", "apply_conformal3d", "rotation_matrix"]


def line_fit(z: np.ndarray, H: np.ndarray) -> dict[str, np.ndarray]:
    """Least-squares line ``H = S z + z0``.

    Parameters
    ----------
    z : (T, n) or (n,) readings (digits). H : (T, n) elevations (mm).

    Returns
    -------
    dict with ``S``, ``z0``, ``se_S``, ``se_z0``, ``s0`` (each (T,)) and ``residuals``
    (T, n) ``H - (S z + z0)``.
    """
    H = np.atleast_2d(np.asarray(H, float))
    z = np.broadcast_to(np.asarray(z, float), H.shape)
    n = H.shape[1]
    zm, Hm = z.mean(1, keepdims=True), H.mean(1, keepdims=True)
    szz = ((z - zm) ** 2).sum(1)
    S = ((z - zm) * (H - Hm)).sum(1) / szz
    z0 = Hm[:, 0] - S * zm[:, 0]
    res = H - (S[:, None] * z + z0[:, None])
    s0 = np.sqrt((res ** 2).sum(1) / (n - 2))
    se_S = s0 / np.sqrt(szz)
    se_z0 = s0 * np.sqrt(1.0 / n + zm[:, 0] ** 2 / szz)
    return {"S": S, "z0": z0, "se_S": se_S, "se_z0": se_z0, "s0": s0, "residuals": res}


def rotation_matrix(omega, phi, kappa) -> np.ndarray:
    """Photogrammetric rotation ``R = R_z(kappa) R_y(phi) R_x(omega)`` (radians), (..., 3, 3)."""
    o, p, k = (np.asarray(a, float) for a in (omega, phi, kappa))
    o, p, k = np.broadcast_arrays(o, p, k)
    co, so, cp, sp, ck, sk = np.cos(o), np.sin(o), np.cos(p), np.sin(p), np.cos(k), np.sin(k)
    one, zero = np.ones_like(o), np.zeros_like(o)
    Rx = np.stack([one, zero, zero, zero, co, -so, zero, so, co], -1).reshape(o.shape + (3, 3))
    Ry = np.stack([cp, zero, sp, zero, one, zero, -sp, zero, cp], -1).reshape(o.shape + (3, 3))
    Rz = np.stack([ck, -sk, zero, sk, ck, zero, zero, zero, one], -1).reshape(o.shape + (3, 3))
    return Rz @ Ry @ Rx


def conformal3d_fit(X: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
    """Seven-parameter 3-D conformal transformation ``Y ~ lam R X + t`` (least squares).

    Parameters
    ----------
    X : (T, n, 3) model coordinates; Y : (T, n, 3) control coordinates (same or other unit).

    Returns
    -------
    dict with ``scale`` (T,), ``R`` (T, 3, 3), ``t`` (T, 3), ``residuals`` (T, n, 3)
    ``Y - (lam R X + t)`` and ``s0`` (T,) with ``3n - 7`` degrees of freedom.
    """
    X = np.asarray(X, float)
    Y = np.asarray(Y, float)
    n = X.shape[1]
    mx, my = X.mean(1, keepdims=True), Y.mean(1, keepdims=True)
    Xc, Yc = X - mx, Y - my
    C = np.einsum("tni,tnj->tij", Yc, Xc) / n                     # cross-covariance
    U, D, Vt = np.linalg.svd(C)
    d = np.sign(np.linalg.det(U @ Vt))
    Sfix = np.ones((X.shape[0], 3))
    Sfix[:, 2] = d
    R = U @ (Sfix[:, :, None] * Vt)
    varx = (Xc ** 2).sum((1, 2)) / n
    lam = (D * Sfix).sum(1) / varx
    t = my[:, 0] - lam[:, None] * np.einsum("tij,tj->ti", R, mx[:, 0])
    res = Y - apply_conformal3d(lam, R, t, X)
    dof = 3 * n - 7
    s0 = np.sqrt((res ** 2).sum((1, 2)) / dof) if dof > 0 else np.full(X.shape[0], np.nan)
    return {"scale": lam, "R": R, "t": t, "residuals": res, "s0": s0}


def apply_conformal3d(scale, R, t, X) -> np.ndarray:
    """``lam R X + t`` for (T,) scale, (T, 3, 3) R, (T, 3) t and (T, n, 3) X."""
    return (np.asarray(scale)[:, None, None] * np.einsum("tij,tnj->tni", R, X)
            + np.asarray(t)[:, None, :])
