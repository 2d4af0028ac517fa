"""Geometry of the library: one rotation convention, one similarity fit, plane affines.

**Rotation convention (omega-phi-kappa).** ``rotation(omega, phi, kappa)`` (radians) is

    R = R_x(omega) R_y(phi) R_z(kappa),

each factor the active right-handed rotation about a fixed axis (counter-clockwise seen from
the positive axis, e.g. ``R_z(k) = [[cos k, -sin k, 0], [sin k, cos k, 0], [0, 0, 1]]``).
``R`` maps model (image-space) coordinates into object space, ``X = s R x + t``; its
transpose is the photogrammetric orientation matrix ``M = M_kappa M_phi M_omega`` of Wolf's
*Elements of Photogrammetry*. :func:`rotation_angles` inverts it
(``phi = asin R[0, 2]``, ``omega = atan2(-R[1, 2], R[2, 2])``, ``kappa = atan2(-R[0, 1], R[0, 0])``).

**Similarity** (:func:`similarity_fit`), ``dst ~ s R src + t`` by least squares with a
weight per point (the same for every coordinate), batched over trials:

* 2-D: linear in ``(a, b, c, c')`` with ``x' = a x + b y + c``, ``y' = -b x + a y + c'``
  (seed 001's "isogonal affine"), so ``s R = [[a, b], [-b, a]]``; the normal equations of
  that linear fit solved in closed form (centroids, then ``a, b``; the cofactors of
  ``(a, b, c, c')`` and the scaled singularity rule of :mod:`sim.lsq.normals` too);
  ``s0^2 = v'Pv / (2n - 4)``.
* 3-D (the 7-parameter conformal transformation): the closed form of Umeyama (1991) / Horn
  (1987) from the SVD of the weighted cross-covariance, the least-squares solution the
  iterated 7-parameter adjustment converges to; ``s0^2 = v'Pv / (3n - 7)``. Seeds
  ``002_fb81c7b0481438c4.txt`` (Salsig, absolute orientation) and ``003_5ce730a990a7ebc5.txt``
  (Agnard, independent models).

A degenerate configuration (collinear or coincident points) is flagged per trial
(``status``, the codes of :data:`sim.lsq.linear.LINEAR_STATUS`), never raised.

**Plane affines** ``(p = (a1, b1, c1, a2, b2, c2) = (A, B, C, D, E, F))``,
``x' = a1 x + b1 y + c1``, ``y' = a2 x + b2 y + c2``: apply, invert, build and decompose
(seed ``001_7e3a2951e7fed426.txt``, *Calibration of a Comparator*, and Salsig 1985).

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

from sim.lsq.linear import LinearFit
from sim.lsq.normals import RCOND

__all__ = [
    "ARCSEC",
    "rotation",
    "rotation_angles",
    "Similarity",
    "similarity_fit",
    "similarity_apply",
    "apply_affine",
    "apply_similarity",
    "affine_from_columns",
    "affine_from_rows",
    "invert_affine",
    "decompose_rows",
    "decompose_columns",
    "inverse_decomposition",
    "propagate",
]

#: radians per arc second
ARCSEC = np.pi / 180 / 3600


# ----------------------------------------------------------------------------- rotation


def rotation(omega, phi, kappa) -> np.ndarray:
    """``R = R_x(omega) R_y(phi) R_z(kappa)`` (radians, broadcast), shape ``(..., 3, 3)``."""
    o, p, k = np.broadcast_arrays(*(np.asarray(a, float) for a in (omega, phi, kappa)))
    co, so, cp, sp, ck, sk = np.cos(o), np.sin(o), np.cos(p), np.sin(p), np.cos(k), np.sin(k)
    one, zero = np.ones_like(o), np.zeros_like(o)
    Rx = np.stack([one, zero, zero, zero, co, -so, zero, so, co], -1).reshape(o.shape + (3, 3))
    Ry = np.stack([cp, zero, sp, zero, one, zero, -sp, zero, cp], -1).reshape(o.shape + (3, 3))
    Rz = np.stack([ck, -sk, zero, sk, ck, zero, zero, zero, one], -1).reshape(o.shape + (3, 3))
    return Rx @ Ry @ Rz


def rotation_angles(R) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(omega, phi, kappa)`` of ``R`` ``(..., 3, 3)`` (inverse of :func:`rotation`;
    ``|phi| <= pi/2``)."""
    R = np.asarray(R, float)
    phi = np.arcsin(np.clip(R[..., 0, 2], -1.0, 1.0))
    omega = np.arctan2(-R[..., 1, 2], R[..., 2, 2])
    kappa = np.arctan2(-R[..., 0, 1], R[..., 0, 0])
    return omega, phi, kappa


# ----------------------------------------------------------------------------- similarity


@dataclass
class Similarity:
    """Result of :func:`similarity_fit` (leading axis: trials).

    scale : (T,); R : (T, d, d) rotation; t : (T, d) so that ``dst ~ scale R src + t``;
    residuals : (T, n, d) ``dst - fitted`` (observed minus adjusted); s0 : (T,) standard
    error of unit weight; dof : ``2n - 4`` or ``3n - 7``; status : (T,) int8 (0 = solved);
    linear : the 2-D :class:`~sim.lsq.linear.LinearFit` of ``(a, b, c, c')`` (None in 3-D).
    """

    scale: np.ndarray
    R: np.ndarray
    t: np.ndarray
    residuals: np.ndarray
    s0: np.ndarray
    dof: int
    status: np.ndarray
    linear: LinearFit | None = None

    @property
    def ok(self) -> np.ndarray:
        return self.status == 0

    def apply(self, pts) -> np.ndarray:
        """``scale R pts + t`` for ``pts`` (T, n, d) or (n, d)."""
        return similarity_apply(self.scale, self.R, self.t, pts)


def similarity_apply(scale, R, t, pts) -> np.ndarray:
    """``scale R pts + t`` for (T,) scale, (T, d, d) R, (T, d) t and (T, n, d) or (n, d) pts."""
    R = np.asarray(R, float)
    pts = np.broadcast_to(np.asarray(pts, float), (R.shape[0],) + np.shape(pts)[-2:])
    return (
        np.asarray(scale, float)[:, None, None] * np.einsum("tij,tnj->tni", R, pts)
        + np.asarray(t, float)[:, None, :]
    )


def similarity_fit(src, dst, w=None) -> Similarity:
    """Least-squares similarity ``dst ~ s R src + t`` in 2-D or 3-D (see the module docstring).

    src : (T, n, d) or (n, d) (error-free); dst : (T, n, d) observed; w : optional point
    weights (n,) or (T, n). Degenerate trials get ``status`` 2 and NaN parameters.
    """
    dst = np.asarray(dst, float)
    dst = dst[None] if dst.ndim == 2 else dst
    src = np.asarray(src, float)
    if dst.shape[-1] == 2:
        return _similarity_2d(src, dst, w)
    if dst.shape[-1] == 3:
        return _similarity_3d(np.broadcast_to(src, dst.shape), dst, w)
    raise ValueError(f"similarity_fit: points must be 2-D or 3-D (got shape {dst.shape})")


def _similarity_2d(src, dst, w) -> Similarity:
    """Closed form of the 2-D least-squares similarity (the linear fit of ``(a, b, c, c')``
    solved analytically): with weighted centroids and centred coordinates ``x, y`` (src) and
    ``X, Y`` (dst), ``D = sum w (x^2 + y^2)``, ``a = sum w (x X + y Y) / D``,
    ``b = sum w (y X - x Y) / D``, ``c = X0 - a x0 - b y0``, ``c' = Y0 + b x0 - a y0``.

    The normal matrix ``N`` of ``(a, b, c, c')`` scaled to unit diagonal has the eigenvalues
    ``1 +- rho`` (each twice), ``rho^2 = (sx^2 + sy^2) / (S W)`` with ``S = sum w |p|^2``,
    ``sx, sy = sum w p``, ``W = sum w``; so the scaled singularity rule's eigenvalue ratio is
    ``(1 - rho) / (1 + rho) = (D / S) / (1 + rho)^2`` (``1 - rho^2 = D / S``). The cofactor
    ``Q = N^-1`` is closed form too: ``Q_aa = Q_bb = 1 / D``, ``Q_ac = -x0 / D``,
    ``Q_ac' = -y0 / D``, ``Q_bc = -y0 / D``, ``Q_bc' = x0 / D``,
    ``Q_cc = Q_c'c' = 1 / W + (x0^2 + y0^2) / D``, the rest zero."""
    T, n, _ = dst.shape
    shared = src.ndim == 2
    src = np.broadcast_to(src, dst.shape)
    w = (
        np.ones((T, n))
        if w is None
        else np.clip(np.broadcast_to(np.asarray(w, float), (T, n)), 0.0, None)
    )
    fin = (
        np.isfinite(src).all(axis=(1, 2))
        & np.isfinite(dst).all(axis=(1, 2))
        & np.isfinite(w).all(axis=1)
    )
    if not fin.all():
        src, dst = (np.where(fin[:, None, None], v, 0.0) for v in (src, dst))
        w = np.where(fin[:, None], w, 1.0)
    W = w.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ms = np.einsum("tn,tnc->tc", w, src) / W[:, None]  # weighted centroids
        md = np.einsum("tn,tnc->tc", w, dst) / W[:, None]
        a_ = src - ms[:, None, :]
        b_ = dst - md[:, None, :]
        wa = w[..., None] * a_
        D = np.einsum("tnc,tnc->t", wa, a_)
        S = np.einsum("tn,tnc,tnc->t", w, src, src)
        rho = np.sqrt(np.einsum("tc,tc->t", ms, ms) * W / S)  # |sum w p| / sqrt(S W)
        rc = (D / S) / (1.0 + rho) ** 2
        ok = fin & (W > 0) & np.isfinite(rc) & (rc > RCOND) & (2 * n >= 4)
        Dg = np.where(ok, D, 1.0)
        a = np.einsum("tnc,tnc->t", wa, b_) / Dg
        b = (
            np.einsum("tn,tn->t", wa[..., 1], b_[..., 0])
            - np.einsum("tn,tn->t", wa[..., 0], b_[..., 1])
        ) / Dg
    x0, y0 = ms[:, 0], ms[:, 1]
    c = md[:, 0] - a * x0 - b * y0
    c2 = md[:, 1] + b * x0 - a * y0
    a, b, c, c2 = (np.where(ok, v, np.nan) for v in (a, b, c, c2))
    x, y = src[..., 0], src[..., 1]
    res = np.stack(
        [
            dst[..., 0] - (a[:, None] * x + b[:, None] * y + c[:, None]),
            dst[..., 1] - (-b[:, None] * x + a[:, None] * y + c2[:, None]),
        ],
        -1,
    )
    vtpv = np.einsum("tn,tnc,tnc->t", w, res, res)
    dof = 2 * n - 4
    s0 = np.sqrt(vtpv / dof) if dof > 0 else np.full(T, np.nan)
    iD, z = 1.0 / Dg, np.zeros(T)
    qc = 1.0 / np.where(ok, W, 1.0) + (x0 * x0 + y0 * y0) * iD
    Q = np.stack(
        [
            np.stack(r, -1)
            for r in (
                (iD, z, -x0 * iD, -y0 * iD),
                (z, iD, -y0 * iD, x0 * iD),
                (-x0 * iD, -y0 * iD, qc, z),
                (-y0 * iD, x0 * iD, z, qc),
            )
        ],
        -2,
    )
    status = np.where(fin, np.where(ok, 0, 2), 3).astype(np.int8)
    s = np.hypot(a, b)
    R = np.stack([np.stack([a, b], -1), np.stack([-b, a], -1)], -2) / s[:, None, None]
    lin = LinearFit(
        np.stack([a, b, c, c2], -1)[..., None],
        np.concatenate([res[..., 0], res[..., 1]], 1)[..., None],
        vtpv[:, None],
        dof,
        status,
        shared,
        None,
        Q,
    )
    return Similarity(s, R, np.stack([c, c2], -1), res, s0, dof, status, lin)


def _similarity_3d(src, dst, w) -> Similarity:
    T, n, d = dst.shape
    w = np.ones((T, n)) if w is None else np.broadcast_to(np.asarray(w, float), (T, n))
    wn = w / w.sum(axis=-1, keepdims=True)
    ms = np.einsum("tn,tnc->tc", wn, src)
    md = np.einsum("tn,tnc->tc", wn, dst)
    a = src - ms[:, None, :]
    b = dst - md[:, None, :]
    C = np.einsum("tn,tni,tnj->tij", wn, b, a)  # cross-covariance
    var = np.einsum("tn,tnc,tnc->t", wn, a, a)
    fin = np.isfinite(C).all(axis=(1, 2)) & np.isfinite(var) & np.isfinite(dst).all(axis=(1, 2))
    ok = fin & (var > 0)
    U, S, Vt = np.linalg.svd(np.where(ok[:, None, None], C, np.eye(d)))
    # degenerate when the cross-covariance has rank < 2 (collinear points): R undetermined
    ok &= S[:, 1] > 1e-12 * S[:, 0]
    sgn = np.sign(np.linalg.det(U @ Vt))
    D = np.ones((T, d))
    D[:, -1] = sgn
    R = U @ (D[:, :, None] * Vt)
    s = np.einsum("ti,ti->t", S, D) / np.where(ok, var, 1.0)
    t = md - s[:, None] * np.einsum("tij,tj->ti", R, ms)
    s, R, t = (np.where(ok.reshape((T,) + (1,) * (v.ndim - 1)), v, np.nan) for v in (s, R, t))
    res = dst - similarity_apply(s, R, t, src)
    dof = d * n - 7
    vtpv = np.einsum("tn,tnc,tnc->t", w, res, res)
    s0 = np.sqrt(vtpv / dof) if dof > 0 else np.full(T, np.nan)
    status = np.where(fin, np.where(ok, 0, 2), 3).astype(np.int8)
    return Similarity(s, R, t, res, s0, dof, status, None)


# ----------------------------------------------------------------------------- plane affines


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
    return np.stack(
        [sx * np.cos(tx), sy * np.cos(ty), cx, sx * np.sin(tx), sy * np.sin(ty), cy], -1
    )


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
        J[..., 0, 0], J[..., 0, 1] = -a1 / r1**3, -b1 / r1**3
        J[..., 1, 3], J[..., 1, 4] = -a2 / r2**3, -b2 / r2**3
        # eps = pi/2 - phi2 + phi
        J[..., 2, 0], J[..., 2, 1] = -b1 / r1**2, a1 / r1**2
        J[..., 2, 3], J[..., 2, 4] = b2 / r2**2, -a2 / r2**2
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
        J[..., 2, 0], J[..., 2, 3] = -D / sx**2, A / sx**2
        J[..., 2, 1], J[..., 2, 4] = E / sy**2, -B / sy**2
        out["cov"] = propagate(J, cov)
    return out


def invert_affine(params) -> np.ndarray:
    """Parameters (..., 6) of the inverse of the affine ``params`` (..., 6)."""
    p = np.asarray(params, float)
    a, b, c, d, e, f = (p[..., i] for i in range(6))
    det = a * e - b * d
    ia, ib, id_, ie = e / det, -b / det, -d / det, a / det
    return np.stack([ia, ib, -(ia * c + ib * f), id_, ie, -(id_ * c + ie * f)], -1)


def inverse_decomposition(params, cov) -> dict[str, np.ndarray]:
    """Seed 002's ``(SX, SY, E)`` of the *inverse* of a fitted affine, with covariance.

    Salsig's program fits the observed system ``X2`` as the function of the control ``X1``
    (residuals ``VX2``, ``VY2`` in ``X2`` units) and prints the parameters of
    ``X1 = A X2 + B Y2 + C``. ``params``/``cov`` (T, 6)/(T, 6, 6) are those of the fitted
    direction ``X2 = f(X1)``. The Jacobian of inversion and decomposition is analytic: with
    ``N = M^-1`` of the linear part ``M``, ``dN = -N dM N``, chained with the decomposition's
    own Jacobian (the translation does not enter ``SX, SY, E``). A central difference, as
    before, lost about seven digits to rounding in ``E``'s (issue 27: ``sd_E_arcsec`` moved by
    3e-7 relative with the BLAS kernel).
    """
    p = np.asarray(params, float)
    inv = invert_affine(p)
    base = decompose_columns(inv)
    A, B, D, E = inv[..., 0], inv[..., 1], inv[..., 3], inv[..., 4]
    sx, sy = base["SX"], base["SY"]
    # d(SX, SY, E) / d(A, B, D, E) of the inverse (as in decompose_columns)
    Jd = np.zeros(p.shape[:-1] + (3, 4))
    Jd[..., 0, 0], Jd[..., 0, 2] = A / sx, D / sx
    Jd[..., 1, 1], Jd[..., 1, 3] = B / sy, E / sy
    Jd[..., 2, 0], Jd[..., 2, 2] = -D / sx**2, A / sx**2
    Jd[..., 2, 1], Jd[..., 2, 3] = E / sy**2, -B / sy**2
    # d N_ij / d M_kl = -N_ik N_lj, with (A, B, D, E) = N_00, N_01, N_10, N_11 and the
    # fitted a, b, d, e = M_00, M_01, M_10, M_11 at params 0, 1, 3, 4
    N = np.stack([np.stack([A, B], -1), np.stack([D, E], -1)], -2)  # (..., 2, 2)
    dN = -np.einsum("...ik,...lj->...ijkl", N, N).reshape(p.shape[:-1] + (4, 4))
    J = np.zeros(p.shape[:-1] + (3, 6))
    J[..., [0, 1, 3, 4]] = Jd @ dN
    base["params"] = inv
    base["cov"] = propagate(J, cov)
    return base


def propagate(J, cov) -> np.ndarray:
    """First-order propagation ``J C J^T`` over a leading batch axis."""
    return np.einsum("...ia,...ab,...jb->...ij", J, cov, J)
