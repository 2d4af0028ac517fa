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

from . import multilateration_jit as jit

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


def _global_blocks(ux, uy, q, e, products, p):
    """Npg (T, 2, n, p), Ngg (T, p, p) and ug (T, p) in closed form.

    The Jacobian of station ``k``'s readings with respect to the globals is sparse (the same
    columns as :func:`_jg`): y1 -> -uy0; x2 -> -ux1; y2 -> -uy1 and +uy3; y3 -> -uy2;
    x4 -> -ux3; alpha -> -1; b -> -h_k with h = 1/(2q). Every entry is written out with
    the products ux*ux, ux*uy, uy*uy, ux*e, uy*e shared; arrays are (4, T, n), station first.
    """
    T, n = ux.shape[1:]
    h = 0.5 / q
    xx, xy, yy, xe, ye = products
    uxh, uyh = ux * h, uy * h
    # Npg: per point, component c (x, y) against each global
    Npg = np.empty((T, 2, n, 7))
    for c, (Jc, cc, cx) in enumerate(((ux, xx, xy), (uy, xy, yy))):
        # cc = Jc*ux, cx = Jc*uy for each station
        Npg[:, c, :, 0] = -cx[0]
        Npg[:, c, :, 1] = -cc[1]
        Npg[:, c, :, 2] = cx[3] - cx[1]
        Npg[:, c, :, 3] = -cx[2]
        Npg[:, c, :, 4] = -cc[3]
        Npg[:, c, :, 5] = -Jc.sum(0)
        Npg[:, c, :, 6] = -(uxh if c == 0 else uyh).sum(0)
    S = lambda a: a.sum(-1)  # noqa: E731  sum over points -> (4, T) or (T,)
    sxx, sxy, syy, sx, sy = S(xx), S(xy), S(yy), S(ux), S(uy)
    sxh, syh, sh, shh = S(uxh), S(uyh), S(h), S(h * h)
    sxe, sye = S(xe), S(ye)
    N = np.zeros((T, 7, 7))
    N[:, 0, 0], N[:, 0, 5], N[:, 0, 6] = syy[0], sy[0], syh[0]
    N[:, 1, 1], N[:, 1, 2], N[:, 1, 5], N[:, 1, 6] = sxx[1], sxy[1], sx[1], sxh[1]
    N[:, 2, 2], N[:, 2, 4] = syy[1] + syy[3], -sxy[3]
    N[:, 2, 5], N[:, 2, 6] = sy[1] - sy[3], syh[1] - syh[3]
    N[:, 3, 3], N[:, 3, 5], N[:, 3, 6] = syy[2], sy[2], syh[2]
    N[:, 4, 4], N[:, 4, 5], N[:, 4, 6] = sxx[3], sx[3], sxh[3]
    N[:, 5, 5], N[:, 5, 6], N[:, 6, 6] = 4.0 * n, sh.sum(0), shh.sum(0)
    iu = np.triu_indices(7, 1)
    N[:, iu[1], iu[0]] = N[:, iu[0], iu[1]]
    ug = np.stack([-sye[0], -sxe[1], sye[3] - sye[1], -sye[2], -sxe[3], -e.sum((0, 2)),
                   -(h * e).sum((0, 2))], -1)
    return Npg[..., :p], N[:, :p, :p], ug[:, :p]


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
    xx, xy, yy = ux * ux, ux * uy, uy * uy
    a, b, c = xx.sum(0), xy.sum(0), yy.sum(0)
    det = a * c - b * b
    ok = np.all(det > rcond * (a + c) ** 2, axis=1)
    inv = 1.0 / np.where(det > 0, det, 1.0)
    i00, i01, i11 = c * inv, -b * inv, a * inv             # symmetric inverse of the blocks
    if r_obs is None:
        e = np.zeros_like(q)
        xe = ye = e
    else:
        e = r_obs.transpose(2, 0, 1) - (q - theta[None, :, 5, None])
        xe, ye = ux * e, uy * e
    up = np.stack([xe.sum(0), ye.sum(0)], 1)
    if p == 0:
        return Reduced(i00, i01, i11, np.zeros((T, 2, n, 0)), np.zeros((T, 0, 0)),
                       np.zeros((T, 0)), up, ok)
    Npg, Ngg, ug = _global_blocks(ux, uy, q, e, (xx, xy, yy, xe, ye), p)
    K = np.stack([i00[..., None] * Npg[:, 0] + i01[..., None] * Npg[:, 1],
                  i01[..., None] * Npg[:, 0] + i11[..., None] * Npg[:, 1]], 1)
    Kf = K.reshape(T, 2 * n, p)
    Kft = Kf.transpose(0, 2, 1)
    Nbar = Ngg - Kft @ Npg.reshape(T, 2 * n, p)
    ubar = ug - (Kft @ up.reshape(T, 2 * n, 1))[..., 0]
    if check:  # scale-aware singularity test of the reduced normals
        dscale = np.sqrt(np.abs(np.einsum("tii->ti", Nbar))) + 1e-300
        C = Nbar / dscale[:, :, None] / dscale[:, None, :]
        ok &= np.linalg.cond(C) < 1e10  # ten digits lost: numerically singular (as the kernel)
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
           tol_mm: float = 1e-10, max_iter: int = 30, engine: str = "auto") -> AdjustResult:
    """Batched Gauss-Newton adjustment of Brown's multilateration.

    r_obs : (T, n, 4) observed ranges, mm. model : ``known``, ``stations`` or ``pivot``.
    theta0 : (T, 7) or (7,): the fixed parameters (for ``known``, the true stations, alpha,
    beta^2) and the initial values of the free ones. points0 : initial points (default:
    linear trilateration from ``theta0``). Convergence: the largest correction of any unknown
    (mm; mm^2 for ``b``), or the remaining error estimated from the observed contraction
    (rho / (1 - rho) times the correction, rho the ratio of the last two corrections), falls
    below ``tol_mm``. engine : ``numpy`` (vectorised over
    trials), ``numba`` (the compiled kernel of :mod:`sim.multilateration_jit`, same math) or
    ``auto`` (numba when installed).
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
    if engine not in ("auto", "numpy", "numba"):
        raise ValueError(f"engine must be auto, numpy or numba, not {engine!r}")
    if engine == "numba" or (engine == "auto" and jit.AVAILABLE):
        p0 = None if points0 is None else np.array(points0, float)
        pts, status, iters, res, ssq = jit.gauss_newton(r_obs, theta, p0, p, tol_mm, max_iter)
        s0 = np.sqrt(ssq / dof) if dof > 0 else np.full(T, np.nan)
        return AdjustResult(pts, theta, res, s0, dof, iters, status == 0, status)
    pts = initial_points(r_obs, theta) if points0 is None else np.array(points0, float)
    gn = GNState(T)
    for it in range(1, max_iter + 1):
        red = _reduce(pts, theta, p, r_obs, check=(it == 1))
        dp, dg = _solve_reduced(red)
        pts = gn.advance(it, red.ok, dp, dg, pts, theta, tol_mm)
        if gn.finished:
            break
    return _finish(r_obs, pts, theta, dof, gn.iters, gn.status)


class GNState:
    """Per-trial bookkeeping of a batched Gauss-Newton run (shared with
    :mod:`sim.positions`). Status codes as in :class:`AdjustResult`; a trial stops when its
    largest correction, or the remaining error estimated from the observed contraction
    (rho / (1 - rho) x correction, rho the ratio of the last two corrections), is below the
    tolerance."""

    def __init__(self, T: int):
        self.active = np.ones(T, bool)
        self.status = np.ones(T, np.int8)
        self.iters = np.zeros(T, np.int32)
        self.prev = np.full(T, np.nan)  # no contraction estimate before two corrections

    @property
    def finished(self) -> bool:
        return not self.active.any()

    def advance(self, it: int, ok, dp, dg, pts, theta, tol: float):
        """Flag singular (``~ok``) and non-finite trials, apply the corrections ``dp`` (T, n, 2)
        and ``dg`` (T, p) to the active ones (``theta`` in place), test convergence; returns
        the updated points."""
        self.status[~ok & self.active] = 2
        self.active &= ok
        step = np.maximum(np.abs(dp).max(axis=(1, 2)), np.abs(dg).max(axis=1, initial=0.0))
        finite = np.isfinite(step)
        self.status[self.active & ~finite] = 3
        self.active &= finite
        upd = self.active
        pts = pts + np.where(upd[:, None, None], dp, 0.0)
        theta[:, :dg.shape[1]] += np.where(upd[:, None], dg, 0.0)
        self.iters[upd] = it
        with np.errstate(invalid="ignore", divide="ignore"):
            rho = step / self.prev
            est = np.where(rho < 0.5, rho / (1.0 - rho) * step, np.inf)
        done = upd & ((step < tol) | (est < tol))
        self.status[done] = 0
        self.active &= ~done
        self.prev = step
        return pts


def _finish(r_obs, pts, theta, dof, iters, status) -> AdjustResult:
    res = r_obs - ranges(pts, theta)
    s0 = (np.sqrt(np.einsum("tnk,tnk->t", res, res) / dof) if dof > 0
          else np.full(len(res), np.nan))
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
