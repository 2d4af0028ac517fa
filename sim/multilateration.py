"""Brown's multilaterative comparator: observation model and batched adjustment.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968, *Computational Tradeoffs in the Design of a
Comparator*). Four tracking stations -- the geometric equivalent of one pivot and the plate
measured in four positions rotated by nominally 90 degrees -- read the range ``r_ij`` on a
scale from station ``i`` to point ``j``:

    (r_ij + alpha)^2 + beta^2 = (x_j - x_i)^2 + (y_j - y_i)^2

with the pivot offsets ``alpha`` (radial) and ``beta`` (tangential) common to all stations.
Brown's datum: station 1 = (0, y1), 2 = (x2, y2), 3 = (0, y3), 4 = (x4, -y2).

Units: millimetres for coordinates, ranges and offsets; ``b = beta^2`` in mm^2.

**beta near zero.** ``beta`` enters only squared, so ``d r / d beta = -beta / q`` vanishes at
``beta = 0`` and the normal matrix is singular there. The adjustment therefore estimates
``b = beta^2`` (``d r / d b = -1 / (2 q)``, never zero). ``b`` may come out negative when the
true ``beta`` is near zero; ``|beta| = sqrt(max(b, 0))`` is reported with the sign of ``b``
kept in the per-trial table.

Global parameter vector ``theta`` (length 7): ``y1, x2, y2, y3, x4, alpha, b``. The three
models free a leading part of it: ``known`` none (2n unknowns), ``stations`` the five
station coordinates (2n+5), ``pivot`` all seven (2n+7).

The solver is Gauss-Newton over a leading *trial* axis. Each point's 2x2 block is
eliminated (reduced normal equations, Brown's EMBET): the largest solve per trial is p x p
(p <= 7) and the cost grows linearly with the number of points.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MODELS", "PARAM_NAMES", "design_theta", "stations", "ranges", "simulate_ranges",
           "initial_points", "adjust", "covariance", "AdjustResult"]

PARAM_NAMES = ("y1_mm", "x2_mm", "y2_mm", "y3_mm", "x4_mm", "alpha_mm", "beta2_mm2")
#: number of free global parameters of each model (``alpha``: stations and alpha free, beta
#: known -- a diagnostic that separates the dilution due to alpha from that due to beta)
MODELS = {"known": 0, "stations": 5, "alpha": 6, "pivot": 7}


def design_theta(h_mm: float, alpha_mm: float = 0.0, beta_mm: float = 0.0) -> np.ndarray:
    """Global parameters of the ideal comparator: stations at distance ``h_mm`` from the plate
    centre on the axes (1 top, 2 right, 3 bottom, 4 left), shape ``(7,)``."""
    return np.array([h_mm, h_mm, 0.0, -h_mm, -h_mm, alpha_mm, beta_mm ** 2])


def stations(theta: np.ndarray) -> np.ndarray:
    """Station coordinates ``(..., 4, 2)`` from ``theta`` ``(..., 7)`` in Brown's datum."""
    y1, x2, y2, y3, x4 = (theta[..., i] for i in range(5))
    z = np.zeros_like(y1)
    return np.stack([np.stack([z, y1], -1), np.stack([x2, y2], -1), np.stack([z, y3], -1),
                     np.stack([x4, -y2], -1)], axis=-2)


def _geometry(points: np.ndarray, theta: np.ndarray):
    """Differences ``P - S`` ``(T, n, 4, 2)`` and ``q = sqrt(d^2 - b)`` ``(T, n, 4)``."""
    diff = points[:, :, None, :] - stations(theta)[:, None, :, :]
    d2 = np.einsum("tnkc,tnkc->tnk", diff, diff)
    q = np.sqrt(np.maximum(d2 - theta[:, None, None, 6], 1e-300))
    return diff, q


def ranges(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Scale readings ``r = sqrt(d^2 - beta^2) - alpha`` (mm), shape ``(T, n, 4)``.

    points : ``(T, n, 2)`` mm; theta : ``(T, 7)``.
    """
    _, q = _geometry(points, theta)
    return q - theta[:, None, None, 5]


def simulate_ranges(points: np.ndarray, theta: np.ndarray, rng: np.random.Generator, *,
                    setting_sigma_um: float, settings: int, comparator_sigma_um: float = 0.0,
                    bias_um: float = 0.0, return_settings: bool = False):
    """Observed ranges (mm) ``(T, n, 4)``: truth + mean of ``settings`` Gaussian settings +
    a comparator random error per reading + a constant personal bias.

    With ``return_settings`` also returns the individual settings' errors ``(T, n, 4, L)`` in µm.
    """
    r = ranges(points, theta)
    sett = rng.normal(0.0, setting_sigma_um, size=r.shape + (settings,))
    err = sett.mean(axis=-1) + bias_um
    if comparator_sigma_um > 0:
        err = err + rng.normal(0.0, comparator_sigma_um, size=r.shape)
    obs = r + err * 1e-3
    return (obs, sett) if return_settings else obs


def initial_points(r_obs: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Closed-form linear trilateration (differences of squared range equations), ``(T, n, 2)``."""
    S = stations(theta)                                    # (T, 4, 2)
    D2 = (r_obs + theta[:, None, None, 5]) ** 2 + theta[:, None, None, 6]
    A = -2.0 * (S[:, 1:, :] - S[:, :1, :])                 # (T, 3, 2)
    s2 = np.einsum("tkc,tkc->tk", S, S)
    rhs = D2[:, :, 1:] - D2[:, :, :1] - (s2[:, None, 1:] - s2[:, None, :1])  # (T, n, 3)
    N = np.einsum("tki,tkj->tij", A, A)
    u = np.einsum("tki,tnk->tni", A, rhs)
    return np.einsum("tij,tnj->tni", np.linalg.inv(N), u)


def _jacobians(points: np.ndarray, theta: np.ndarray, p: int):
    """Jacobians of the ranges: ``Jp`` ``(T, n, 4, 2)`` and ``Jg`` ``(T, n, 4, p)`` (or None)."""
    diff, q = _geometry(points, theta)
    u = diff / q[..., None]
    return u, (_jg(u[..., 0], u[..., 1], q, p) if p else None), q


def _jg(ux: np.ndarray, uy: np.ndarray, q: np.ndarray, p: int) -> np.ndarray:
    """Jacobian of the ranges with respect to the first ``p`` globals, ``(T, n, 4, p)``.

    Each station coordinate touches only its own station's readings (sparse columns).
    """
    T, n, _ = ux.shape
    Jg = np.zeros((T, n, 4, p))
    Jg[:, :, 0, 0] = -uy[:, :, 0]                          # y1
    Jg[:, :, 1, 1] = -ux[:, :, 1]                          # x2
    Jg[:, :, 1, 2] = -uy[:, :, 1]                          # y2 through station 2 ...
    Jg[:, :, 3, 2] = uy[:, :, 3]                           # ... and station 4 (y4 = -y2)
    Jg[:, :, 2, 3] = -uy[:, :, 2]                          # y3
    Jg[:, :, 3, 4] = -ux[:, :, 3]                          # x4
    if p > 5:
        Jg[:, :, :, 5] = -1.0                              # alpha
    if p > 6:
        Jg[:, :, :, 6] = -0.5 / q                          # b = beta^2
    return Jg


#: nonzero Jacobian columns of each station's readings: (global index, sign, component);
#: alpha (-1) and b (-1/(2q)) touch every station and are added in :func:`_station_blocks`
STATION_COLS = (((0, -1.0, 1),),                 # station 1 (0, y1): y1
                ((1, -1.0, 0), (2, -1.0, 1)),    # station 2 (x2, y2): x2, y2
                ((3, -1.0, 1),),                 # station 3 (0, y3): y3
                ((2, 1.0, 1), (4, -1.0, 0)))     # station 4 (x4, -y2): y2, x4


def _station_blocks(u: tuple, q: np.ndarray, p: int):
    """Per station ``k``: the global indices it touches and their Jacobian columns (T, n, m)."""
    out = []
    for k, spec in enumerate(STATION_COLS):
        idx = [g for g, _, _ in spec if g < p]
        vec = [sgn * u[c][k] for g, sgn, c in spec if g < p]
        if p > 5:
            idx.append(5)
            vec.append(np.full_like(q[k], -1.0))
        if p > 6:
            idx.append(6)
            vec.append(-0.5 / q[k])
        out.append((np.array(idx), np.stack(vec, -1)))
    return out


@dataclass
class Reduced:
    """Normal-equation pieces at one linearisation point (unit weights).

    Npp_inv : (T, n, 2, 2) inverse point blocks; K : (T, 2, n, p) = Npp^-1 Npg (component
    first); Nbar : (T, p, p) reduced normal matrix of the globals; ubar : (T, p) reduced
    right-hand side; up : (T, 2, n) point right-hand sides; ok : (T,) non-singular.
    """

    i00: np.ndarray
    i01: np.ndarray
    i11: np.ndarray
    K: np.ndarray
    Nbar: np.ndarray
    ubar: np.ndarray
    up: np.ndarray
    ok: np.ndarray

    @property
    def Npp_inv(self) -> np.ndarray:
        return np.stack([np.stack([self.i00, self.i01], -1), np.stack([self.i01, self.i11], -1)], -2)


def _reduce(points, theta, p, r_obs=None, check=True, rcond: float = 1e-13, S=None) -> Reduced:
    """Form the normal equations and eliminate the 2x2 point blocks (Schur complement).

    Everything per point is elementwise over (trials, points); sums over points are matrix
    products batched over trials, so the cost is linear in the number of points. The station
    axis comes first internally so that each station's readings are contiguous.
    """
    S = stations(theta) if S is None else S                # (T, 4, 2)
    dx = points[None, :, :, 0] - S[:, :, 0].T[:, :, None]  # (4, T, n)
    dy = points[None, :, :, 1] - S[:, :, 1].T[:, :, None]
    q = np.sqrt(np.maximum(dx * dx + dy * dy - theta[None, :, 6, None], 1e-300))
    ux, uy = dx / q, dy / q
    T, n = ux.shape[1:]
    a, b, c = (ux * ux).sum(0), (ux * uy).sum(0), (uy * uy).sum(0)
    det = a * c - b * b
    ok = np.all(det > rcond * (a + c) ** 2, axis=1)
    inv = 1.0 / np.where(det > 0, det, 1.0)
    i00, i01, i11 = c * inv, -b * inv, a * inv             # symmetric inverse of the blocks
    if r_obs is None:
        e = np.zeros_like(q)
        up = np.zeros((T, 2, n))
    else:
        e = r_obs.transpose(2, 0, 1) - (q - theta[None, :, 5, None])
        up = np.stack([(ux * e).sum(0), (uy * e).sum(0)], 1)
    if p == 0:
        return Reduced(i00, i01, i11, np.zeros((T, 2, n, 0)), np.zeros((T, 0, 0)),
                       np.zeros((T, 0)), up, ok)
    Ngg = np.zeros((T, p, p))
    ug = np.zeros((T, p))
    cols: list[list] = [[0.0] * p, [0.0] * p]              # Npg columns, summed per global
    for k, (idx, V) in enumerate(_station_blocks((ux, uy), q, p)):
        Vt = V.transpose(0, 2, 1)                          # (T, m, n)
        Ngg[:, idx[:, None], idx[None, :]] += Vt @ V
        ug[:, idx] += (Vt @ e[k][:, :, None])[..., 0]
        for i, g in enumerate(idx):
            cols[0][g] = cols[0][g] + ux[k] * V[..., i]
            cols[1][g] = cols[1][g] + uy[k] * V[..., i]
    Npg = np.stack([np.stack(cols[0], -1), np.stack(cols[1], -1)], 1)  # (T, 2, n, p)
    K = np.stack([i00[..., None] * Npg[:, 0] + i01[..., None] * Npg[:, 1],
                  i01[..., None] * Npg[:, 0] + i11[..., None] * Npg[:, 1]], 1)
    Kf = K.reshape(T, 2 * n, p)
    Kft = Kf.transpose(0, 2, 1)
    Nbar = Ngg - Kft @ Npg.reshape(T, 2 * n, p)
    ubar = ug - (Kft @ up.reshape(T, 2 * n, 1))[..., 0]
    if check:  # scale-aware singularity test of the reduced normals
        dscale = np.sqrt(np.abs(np.einsum("tii->ti", Nbar))) + 1e-300
        C = Nbar / dscale[:, :, None] / dscale[:, None, :]
        ok &= np.linalg.cond(C) < 1.0 / rcond
    return Reduced(i00, i01, i11, K, Nbar, ubar, up, ok)


def _solve_reduced(red: Reduced):
    """Corrections ``(dp (T,n,2), dg (T,p))`` of one Gauss-Newton step."""
    p = red.Nbar.shape[-1]
    u0, u1 = red.up[:, 0], red.up[:, 1]
    dp = np.stack([red.i00 * u0 + red.i01 * u1, red.i01 * u0 + red.i11 * u1], 1)  # (T, 2, n)
    if p:
        Nb = np.where(red.ok[:, None, None], red.Nbar, np.eye(p))
        dg = np.linalg.solve(Nb, red.ubar[..., None])[..., 0]
        T, _, n = dp.shape
        dp = dp - (red.K.reshape(T, 2 * n, p) @ dg[:, :, None]).reshape(T, 2, n)
    else:
        dg = red.ubar
    return dp.transpose(0, 2, 1), dg


@dataclass
class AdjustResult:
    """Result of :func:`adjust` (leading axis: trials).

    points : (T, n, 2) mm; theta : (T, 7) (fixed entries unchanged);
    residuals : (T, n, 4) mm (observed minus adjusted); sigma0 : (T,) a-posteriori
    standard error of unit weight in mm (= rms closure); dof : int;
    iterations : (T,) int; converged : (T,) bool; status : (T,) int
    (0 converged, 1 not converged in ``max_iter``, 2 singular normals, 3 non-finite).
    """

    points: np.ndarray
    theta: np.ndarray
    residuals: np.ndarray
    sigma0: np.ndarray
    dof: int
    iterations: np.ndarray
    converged: np.ndarray
    status: np.ndarray


def adjust(r_obs: np.ndarray, model: str, theta0: np.ndarray, points0: np.ndarray | None = None,
           tol_mm: float = 1e-10, max_iter: int = 30) -> AdjustResult:
    """Batched Gauss-Newton adjustment of Brown's multilateration.

    r_obs : (T, n, 4) observed ranges, mm. model : ``known``, ``stations`` or ``pivot``.
    theta0 : (T, 7) or (7,): the fixed parameters (for ``known``, the true stations, alpha,
    beta^2) and the initial values of the free ones. points0 : initial points (default:
    linear trilateration from ``theta0``). Convergence: the largest correction of any unknown
    (mm; mm^2 for ``b``) falls below ``tol_mm``.
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, not {model!r}")
    r_obs = np.asarray(r_obs, float)
    if r_obs.ndim != 3 or r_obs.shape[2] != 4:
        raise ValueError(f"r_obs must have shape (trials, points, 4), not {r_obs.shape}")
    T, n, _ = r_obs.shape
    p = MODELS[model]
    dof = 4 * n - (2 * n + p)
    if dof < 0 or n < 3:
        raise ValueError(f"{n} points give {4 * n} observations for {2 * n + p} unknowns")
    theta = np.broadcast_to(np.asarray(theta0, float), (T, 7)).copy()
    pts = initial_points(r_obs, theta) if points0 is None else np.array(points0, float)
    active = np.ones(T, bool)
    status = np.ones(T, np.int8)
    iters = np.zeros(T, np.int32)
    for it in range(1, max_iter + 1):
        red = _reduce(pts, theta, p, r_obs, check=(it == 1))
        dp, dg = _solve_reduced(red)
        bad = ~red.ok & active
        status[bad] = 2
        active &= red.ok
        step = np.maximum(np.abs(dp).max(axis=(1, 2)), np.abs(dg).max(axis=1, initial=0.0))
        finite = np.isfinite(step)
        status[active & ~finite] = 3
        active &= finite
        upd = active[:, None]
        pts = pts + np.where(upd[:, :, None], dp, 0.0)
        theta[:, :p] += np.where(upd, dg, 0.0)
        iters[active] = it
        done = active & (step < tol_mm)
        status[done] = 0
        active &= ~done
        if not active.any():
            break
    res = r_obs - ranges(pts, theta)
    s0 = np.sqrt(np.einsum("tnk,tnk->t", res, res) / dof) if dof > 0 else np.full(T, np.nan)
    return AdjustResult(pts, theta, res, s0, dof, iters, status == 0, status)


def covariance(points: np.ndarray, theta: np.ndarray, model: str,
               station_xy: np.ndarray | None = None):
    """Cofactor matrices (unit range variance) of the adjusted unknowns.

    points : (T, n, 2); theta : (T, 7). Returns ``(Qpp, Qgg, K, Npp_inv)``: the per-point
    2x2 cofactors ``(T, n, 2, 2)``, the globals' ``(T, p, p)``, and the pieces from which any
    cross covariance follows: ``Q(p_j, p_k) = delta_jk Npp_inv_j + K_j Qgg K_k^T`` and
    ``Q(p_j, g) = -K_j Qgg``. Multiply by sigma_range^2 for covariances.
    ``station_xy`` (T, 4, 2): arbitrary known stations (``known`` model only), e.g. for
    testing translation and rotation invariance outside Brown's datum.
    """
    p = MODELS[model]
    if station_xy is not None and p:
        raise ValueError("station_xy is only meaningful for the 'known' model")
    red = _reduce(points, theta, p, S=station_xy)
    if p:
        Nb = np.where(red.ok[:, None, None], red.Nbar, np.eye(p))
        Qgg = np.linalg.inv(Nb)
        Qgg[~red.ok] = np.nan
        KQ = red.K @ Qgg[:, None]                          # (T, 2, n, p)
        Qpp = red.Npp_inv + np.einsum("tanp,tbnp->tnab", KQ, red.K)
    else:
        Qgg = np.zeros((points.shape[0], 0, 0))
        Qpp = red.Npp_inv
    return Qpp, Qgg, red.K.transpose(0, 2, 1, 3), red.Npp_inv
