"""Brown's multilateration with P plate positions: batched adjustment in any station datum.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968). Measuring the plate in ``P`` positions
rotated about one pivot is geometrically the same as measuring it from ``P`` stations on a
circle of radius ``h`` about the plate centre (the pivot seen from the plate). Brown used
``P = 4``; :mod:`sim.multilateration` implements that case in Brown's datum. This module
generalises it to any ``P >= 3`` with the same observation equation

    (r_kj + alpha)^2 + beta^2 = (x_j - X_k)^2 + (y_j - Y_k)^2

and the same reduced-normal (EMBET) elimination of the 2x2 point blocks: the largest solve
per trial is ``(p + d) x (p + d)`` with ``p = 2P`` (+2 for ``alpha``, ``b = beta^2``) and
``d = 3`` datum constraints, and the cost grows linearly with the number of points.

Global vector ``theta`` ``(T, 2P + 2)``: ``X_1, Y_1, ..., X_P, Y_P, alpha, b`` (mm, mm^2).
Models: ``known`` (nothing free), ``stations`` (the 2P station coordinates free), ``pivot``
(also ``alpha`` and ``b``). The free network has a datum defect of 3 (two translations and a
rotation of stations and points together; the ranges fix the scale). The datum is imposed by
three linear constraints ``C^T d theta = 0`` on the corrections (bordered normal equations):

* ``brown`` (P = 4 only): ``X_1 = X_3 = 0``, ``Y_4 = -Y_2``, Brown's choice;
* ``inner``: inner constraints over the station coordinates (no mean translation or rotation
  of the stations with respect to their approximate values).

Any other datum, in particular one over the measured points, follows from
:mod:`sim.datum` (S-transformation). Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .multilateration import AdjustResult, GNState

__all__ = ["MODELS", "DATUMS", "circle_stations", "design_theta", "stations", "ranges",
           "n_free", "initial_points", "adjust", "covariance", "full_point_covariance",
           "from_brown_theta"]

MODELS = ("known", "stations", "pivot")
DATUMS = ("brown", "inner")


def n_free(P: int, model: str) -> int:
    """Number of free globals of ``model`` with ``P`` stations."""
    return {"known": 0, "stations": 2 * P, "pivot": 2 * P + 2}[model]


def circle_stations(P: int, h_mm: float) -> np.ndarray:
    """``P`` stations equally spaced on a circle of radius ``h_mm`` about the plate centre,
    station 1 on the +y axis, numbered clockwise (for P = 4: top, right, bottom, left as in
    Brown's Figure 1). Shape ``(P, 2)``."""
    ang = np.pi / 2 - 2 * np.pi * np.arange(P) / P
    return h_mm * np.column_stack([np.cos(ang), np.sin(ang)])


def design_theta(P: int, h_mm: float, alpha_mm: float = 0.0, beta_mm: float = 0.0) -> np.ndarray:
    """Global parameters of the ideal comparator with ``P`` positions, shape ``(2P + 2,)``."""
    S = circle_stations(P, h_mm)
    S[np.abs(S) < 1e-12 * h_mm] = 0.0
    return np.concatenate([S.ravel(), [alpha_mm, beta_mm ** 2]])


def from_brown_theta(theta7: np.ndarray) -> np.ndarray:
    """Convert :mod:`sim.multilateration`'s 7-vector (Brown's datum) to the P = 4 layout."""
    y1, x2, y2, y3, x4, a, b = (theta7[..., i] for i in range(7))
    z = np.zeros_like(y1)
    return np.stack([z, y1, x2, y2, z, y3, x4, -y2, a, b], -1)


def stations(theta: np.ndarray) -> np.ndarray:
    """Station coordinates ``(..., P, 2)`` from ``theta`` ``(..., 2P + 2)``."""
    P = (theta.shape[-1] - 2) // 2
    return theta[..., :2 * P].reshape(theta.shape[:-1] + (P, 2))


def ranges(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Scale readings ``r = sqrt(d^2 - b) - alpha`` (mm), shape ``(T, n, P)``."""
    d = points[:, :, None, :] - stations(theta)[:, None, :, :]
    q = np.sqrt(np.maximum(np.einsum("tnkc,tnkc->tnk", d, d) - theta[:, None, None, -1], 1e-300))
    return q - theta[:, None, None, -2]


def arm_angles(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Direction of the measuring arm (station -> point) in the *comparator* frame, radians,
    ``(T, n, P)``: the plate-frame direction minus the rotation of plate position ``k``
    (``2 pi k / P``, the plate turned so that station ``k`` comes to the pivot)."""
    d = points[:, :, None, :] - stations(theta)[:, None, :, :]
    P = d.shape[2]
    return np.arctan2(d[..., 1], d[..., 0]) + 2 * np.pi * np.arange(P) / P


def initial_points(r_obs: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Closed-form linear multilateration (differences of squared range equations)."""
    S = stations(theta)
    D2 = (r_obs + theta[:, None, None, -2]) ** 2 + theta[:, None, None, -1]
    A = -2.0 * (S[:, 1:, :] - S[:, :1, :])
    s2 = np.einsum("tkc,tkc->tk", S, S)
    rhs = D2[:, :, 1:] - D2[:, :, :1] - (s2[:, None, 1:] - s2[:, None, :1])
    N = np.einsum("tki,tkj->tij", A, A)
    u = np.einsum("tki,tnk->tni", A, rhs)
    return np.einsum("tij,tnj->tni", np.linalg.inv(N), u)


def datum_constraints(theta: np.ndarray, p: int, datum: str) -> np.ndarray:
    """Constraint matrix ``C`` ``(T, p, 3)`` of the station datum (``C^T d theta = 0``)."""
    T = theta.shape[0]
    P = (theta.shape[1] - 2) // 2
    C = np.zeros((T, p, 3))
    if datum == "brown":
        if P != 4:
            raise ValueError("the 'brown' datum needs exactly 4 stations")
        C[:, 0, 0] = 1.0            # X_1 = 0
        C[:, 4, 1] = 1.0            # X_3 = 0
        C[:, 3, 2] = 1.0            # Y_2 + Y_4 = 0
        C[:, 7, 2] = 1.0
    elif datum == "inner":
        S = stations(theta)
        c = S - S.mean(axis=1, keepdims=True)
        C[:, 0:2 * P:2, 0] = 1.0
        C[:, 1:2 * P:2, 1] = 1.0
        C[:, 0:2 * P:2, 2] = -c[..., 1]
        C[:, 1:2 * P:2, 2] = c[..., 0]
    else:
        raise ValueError(f"datum must be one of {', '.join(DATUMS)}, not {datum!r}")
    return C


@dataclass
class Reduced:
    """Reduced normal equations (unit weights); shapes as in :mod:`sim.multilateration`,
    with ``K`` ``(T, n, 2, p)``."""

    Ninv: np.ndarray
    K: np.ndarray
    Nbar: np.ndarray
    ubar: np.ndarray
    dp0: np.ndarray
    ok: np.ndarray


def _reduce(points, theta, p, r_obs=None, rcond=1e-13) -> Reduced:
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # diverged trials
        return _reduce_impl(points, theta, p, r_obs, rcond)


def _reduce_impl(points, theta, p, r_obs, rcond) -> Reduced:
    S = stations(theta)                                    # (T, P, 2)
    P = S.shape[1]
    dx = points[None, :, :, 0] - S[:, :, 0].T[:, :, None]  # (P, T, n)
    dy = points[None, :, :, 1] - S[:, :, 1].T[:, :, None]
    q = np.sqrt(np.maximum(dx * dx + dy * dy - theta[None, :, -1, None], 1e-300))
    ux, uy = dx / q, dy / q
    T, n = ux.shape[1:]
    a, b, c = (ux * ux).sum(0), (ux * uy).sum(0), (uy * uy).sum(0)
    det = a * c - b * b
    ok = np.all(det > rcond * (a + c) ** 2, axis=1)
    inv = 1.0 / np.where(det > 0, det, 1.0)
    i00, i01, i11 = c * inv, -b * inv, a * inv
    Ninv = np.stack([np.stack([i00, i01], -1), np.stack([i01, i11], -1)], -2)  # (T, n, 2, 2)
    if r_obs is None:
        e = np.zeros_like(q)
    else:
        e = r_obs.transpose(2, 0, 1) - (q - theta[None, :, -2, None])
    up = np.stack([(ux * e).sum(0), (uy * e).sum(0)], -1)  # (T, n, 2)
    dp0 = (Ninv @ up[..., None])[..., 0]
    if p == 0:
        return Reduced(Ninv, np.zeros((T, n, 2, 0)), np.zeros((T, 0, 0)), np.zeros((T, 0)), dp0, ok)
    # Jacobian of the ranges w.r.t. the globals, station axis first: (P, T, n, p)
    J = np.zeros((P, T, n, p))
    k = np.arange(P)
    J[k, :, :, 2 * k] = -ux
    J[k, :, :, 2 * k + 1] = -uy
    if p > 2 * P:
        J[..., 2 * P] = -1.0
        J[..., 2 * P + 1] = -0.5 / q
    Jt = J.transpose(1, 0, 2, 3).reshape(T, P * n, p)      # batched matrix products (BLAS)
    JtT = Jt.transpose(0, 2, 1)
    Ngg = JtT @ Jt
    ug = (JtT @ e.transpose(1, 0, 2).reshape(T, P * n, 1))[..., 0]
    Npg = np.stack([(ux[..., None] * J).sum(0), (uy[..., None] * J).sum(0)], 2)  # (T, n, 2, p)
    K = Ninv @ Npg                                         # (T, n, 2, p)
    Kf = K.reshape(T, 2 * n, p)
    KfT = Kf.transpose(0, 2, 1)
    Nbar = Ngg - KfT @ Npg.reshape(T, 2 * n, p)
    ubar = ug - (KfT @ up.reshape(T, 2 * n, 1))[..., 0]
    return Reduced(Ninv, K, Nbar, ubar, dp0, ok)


def _bordered(Nbar: np.ndarray, C: np.ndarray) -> np.ndarray:
    T, p, d = C.shape
    M = np.zeros((T, p + d, p + d))
    M[:, :p, :p] = Nbar
    M[:, :p, p:] = C
    M[:, p:, :p] = C.transpose(0, 2, 1)
    return M


def _scaled_ok(M: np.ndarray, rcond: float) -> np.ndarray:
    ds = np.sqrt(np.abs(np.einsum("tii->ti", M))) + 1e-300
    ds = np.where(ds > 1e-150, ds, 1.0)
    Mn = M / ds[:, :, None] / ds[:, None, :]
    fin = np.all(np.isfinite(Mn), axis=(1, 2))
    Mn = np.where(fin[:, None, None], Mn, np.eye(M.shape[-1]))
    return fin & (np.linalg.cond(Mn) < 1.0 / rcond)


def adjust(r_obs: np.ndarray, model: str, theta0: np.ndarray, datum: str = "inner",
           tol_mm: float = 1e-10, max_iter: int = 30, rcond: float = 1e-12) -> AdjustResult:
    """Batched Gauss-Newton adjustment with ``P`` stations.

    r_obs : (T, n, P) mm. theta0 : (T, 2P+2) or (2P+2,) -- fixed values and starting values;
    for ``brown`` the start must satisfy Brown's datum (it is kept exactly). Returns
    :class:`sim.multilateration.AdjustResult` (status 0 converged, 1 not converged,
    2 singular, 3 non-finite).
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, not {model!r}")
    r_obs = np.asarray(r_obs, float)
    T, n, P = r_obs.shape
    if P < 3:
        raise ValueError("at least 3 stations (plate positions) are needed")
    p = n_free(P, model)
    dof = P * n - 2 * n - p + (3 if p else 0)
    if dof < 0 or n < 3:
        raise ValueError(f"{n} points in {P} positions give {P * n} ranges for too many unknowns")
    theta = np.broadcast_to(np.asarray(theta0, float), (T, 2 * P + 2)).copy()
    pts = initial_points(r_obs, theta)
    gn = GNState(T)
    C = None
    for it in range(1, max_iter + 1):
        red = _reduce(pts, theta, p, r_obs)
        if p:
            if C is None:
                C = datum_constraints(theta, p, datum)
            M = _bordered(red.Nbar, C)
            if it == 1:
                red.ok &= _scaled_ok(M, rcond)
            M = np.where(red.ok[:, None, None], M, np.eye(p + 3))
            rhs = np.concatenate([red.ubar, np.zeros((T, 3))], 1)[..., None]
            try:
                sol = np.linalg.solve(M, rhs)
            except np.linalg.LinAlgError:  # a diverging trial went singular: flag it
                red.ok &= _scaled_ok(M, rcond)
                sol = np.linalg.solve(np.where(red.ok[:, None, None], M, np.eye(p + 3)), rhs)
            dg = sol[:, :p, 0]
            dp = red.dp0 - (red.K.reshape(T, 2 * n, p) @ dg[..., None]).reshape(T, n, 2)
        else:
            dg = np.zeros((T, 0))
            dp = red.dp0
        pts = gn.advance(it, red.ok, dp, dg, pts, theta, tol_mm)
        if gn.finished:
            break
    res = r_obs - ranges(pts, theta)
    s0 = np.sqrt(np.einsum("tnk,tnk->t", res, res) / dof) if dof > 0 else np.full(T, np.nan)
    return AdjustResult(pts, theta, res, s0, dof, gn.iters, gn.status == 0, gn.status)


def covariance(points: np.ndarray, theta: np.ndarray, model: str, datum: str = "inner"):
    """Cofactors (unit range variance) at ``points`` ``(T, n, 2)``, ``theta`` ``(T, 2P+2)``.

    Returns ``(Qpp (T,n,2,2), Qgg (T,p,p), K (T,n,2,p), Ninv (T,n,2,2))`` with
    ``Q(p_j, p_k) = delta_jk Ninv_j + K_j Qgg K_k^T`` and ``Q(p_j, g) = -K_j Qgg``, the
    station coordinates in the chosen ``datum`` (bordered inverse of the reduced normals).
    """
    P = (theta.shape[-1] - 2) // 2
    p = n_free(P, model)
    red = _reduce(points, theta, p)
    T = points.shape[0]
    if p:
        C = datum_constraints(theta, p, datum)
        M = _bordered(red.Nbar, C)
        ok = red.ok & _scaled_ok(M, 1e-13)
        M = np.where(ok[:, None, None], M, np.eye(p + 3))
        Qgg = np.linalg.inv(M)[:, :p, :p]
        Qgg[~ok] = np.nan
        KQ = (red.K.reshape(T, -1, p) @ Qgg).reshape(red.K.shape)
        Qpp = red.Ninv + KQ @ red.K.transpose(0, 1, 3, 2)
    else:
        Qgg = np.zeros((T, 0, 0))
        Qpp = red.Ninv
    return Qpp, Qgg, red.K, red.Ninv


def full_point_covariance(points: np.ndarray, theta: np.ndarray, model: str,
                          datum: str = "inner") -> np.ndarray:
    """The full ``(T, 2n, 2n)`` cofactor of all point coordinates (x1, y1, x2, ...)."""
    _, Qgg, K, Ninv = covariance(points, theta, model, datum)
    T, n = points.shape[:2]
    Kf = K.reshape(T, 2 * n, -1)
    Q = Kf @ Qgg @ Kf.transpose(0, 2, 1) if Qgg.shape[-1] else np.zeros((T, 2 * n, 2 * n))
    idx = np.arange(n)
    Qb = Q.reshape(T, n, 2, n, 2)
    Qb[:, idx, :, idx, :] += Ninv.transpose(1, 0, 2, 3)
    return Qb.reshape(T, 2 * n, 2 * n)
