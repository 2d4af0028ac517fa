"""Stereo-plotter encoder calibration pieces (Salsig 1985, seed ``002_fb81c7b0481438c4.txt``).

* :func:`line_fit` -- the z encoder: ``H = S z + z0`` fitted by least squares to readings
  ``z`` (digits) at known glass-scale elevations ``H`` (mm), with the standard errors of
  ``S`` (mm/digit) and ``z0`` (mm) from the a-posteriori variance (``n - 2`` degrees of
  freedom). ``z`` is taken as error-free and ``H`` as observed, as the paper's equation is
  written; a reading error ``sigma_z`` (digits) acts as ``S sigma_z`` in ``H``. Solved by the
  library's one linear routine :func:`sim.lsq.linear.lstsq` (one factorisation when ``z`` is
  shared by every trial).
* :func:`conformal3d_fit` -- the 3-D conformal (7-parameter) transformation
  ``Y = lam R X + t`` of model coordinates ``X`` to ground control ``Y``, equal weights:
  the library's one similarity fit :func:`sim.instruments.geometry.similarity_fit` (closed form,
  Umeyama 1991; Horn 1987), returned as a dict.
* :func:`rotation_matrix` is :func:`sim.instruments.geometry.rotation`, the library's one
  omega-phi-kappa convention ``R = R_x(omega) R_y(phi) R_z(kappa)``.

All functions take a leading trial axis ``T``.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.geometry import rotation as rotation_matrix
from sim.instruments.geometry import similarity_apply as apply_conformal3d
from sim.instruments.geometry import similarity_fit
from sim.lsq.linear import lstsq

__all__ = ["line_fit", "conformal3d_fit", "apply_conformal3d", "rotation_matrix"]


def line_fit(z: np.ndarray, H: np.ndarray) -> dict[str, np.ndarray]:
    """Least-squares line ``H = S z + z0``.

    Parameters
    ----------
    z : (T, n) or (n,) readings (digits). H : (T, n) elevations (mm).

    Returns
    -------
    dict with ``S``, ``z0``, ``se_S``, ``se_z0``, ``s0`` (each (T,)), ``residuals``
    (T, n) ``H - (S z + z0)`` and ``status`` (T,) (0 where solved).
    """
    H = np.atleast_2d(np.asarray(H, float))
    z = np.asarray(z, float)
    if z.ndim == 2:
        H = np.broadcast_to(H, z.shape)
    A = np.stack([z, np.ones_like(z)], -1)  # (n, 2) or (T, n, 2)
    f = lstsq(A, H)
    Q = f.cofactor()
    return {
        "S": f.x[:, 0, 0],
        "z0": f.x[:, 1, 0],
        "se_S": f.s0 * np.sqrt(Q[:, 0, 0]),
        "se_z0": f.s0 * np.sqrt(Q[:, 1, 1]),
        "s0": f.s0,
        "residuals": f.residuals[..., 0],
        "status": f.status,
    }


def conformal3d_fit(X: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
    """Seven-parameter 3-D conformal transformation ``Y ~ lam R X + t`` (least squares).

    Parameters
    ----------
    X : (T, n, 3) model coordinates; Y : (T, n, 3) control coordinates (same or other unit).

    Returns
    -------
    dict with ``scale`` (T,), ``R`` (T, 3, 3), ``t`` (T, 3), ``residuals`` (T, n, 3)
    ``Y - (lam R X + t)``, ``s0`` (T,) with ``3n - 7`` degrees of freedom and ``status``.
    """
    f = similarity_fit(X, Y)
    return {
        "scale": f.scale,
        "R": f.R,
        "t": f.t,
        "residuals": f.residuals,
        "s0": f.s0,
        "status": f.status,
    }
