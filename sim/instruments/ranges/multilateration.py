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

The observation model is :class:`sim.instruments.ranges.positions.RangeModel` with Brown's datum as a linear map
of the 7 globals (:data:`BROWN_LAYOUT`); the adjustment is the engine's Gauss-Newton
(:mod:`sim.lsq`: each point's 2x2 block eliminated, Brown's EMBET, so the largest solve per
trial is p x p, p <= 7). The compiled kernel :mod:`sim.instruments.ranges.multilateration_jit` is registered
as the engine's fast path for this layout.
"""

from __future__ import annotations

import numpy as np

from sim import lsq
from sim.instruments.ranges import multilateration_jit as jit
from sim.instruments.ranges import positions as po
from sim.instruments.ranges.multilateration_kernel import UNDECIDED

__all__ = [
    "MODELS",
    "PARAM_NAMES",
    "design_theta",
    "stations",
    "ranges",
    "simulate_ranges",
    "initial_points",
    "adjust",
    "covariance",
    "AdjustResult",
    "BROWN_LAYOUT",
]

PARAM_NAMES = ("y1_mm", "x2_mm", "y2_mm", "y3_mm", "x4_mm", "alpha_mm", "beta2_mm2")
#: number of free global parameters of each model (``alpha``: stations and alpha free, beta
#: known -- a diagnostic that separates the dilution due to alpha from that due to beta)
MODELS = {"known": 0, "stations": 5, "alpha": 6, "pivot": 7}


def design_theta(h_mm: float, alpha_mm: float = 0.0, beta_mm: float = 0.0) -> np.ndarray:
    """Global parameters of the ideal comparator: stations at distance ``h_mm`` from the plate
    centre on the axes (1 top, 2 right, 3 bottom, 4 left), shape ``(7,)``."""
    return np.array([h_mm, h_mm, 0.0, -h_mm, -h_mm, alpha_mm, beta_mm**2])


def stations(theta: np.ndarray) -> np.ndarray:
    """Station coordinates ``(..., 4, 2)`` from ``theta`` ``(..., 7)`` in Brown's datum."""
    y1, x2, y2, y3, x4 = (theta[..., i] for i in range(5))
    z = np.zeros_like(y1)
    return np.stack(
        [
            np.stack([z, y1], -1),
            np.stack([x2, y2], -1),
            np.stack([z, y3], -1),
            np.stack([x4, -y2], -1),
        ],
        axis=-2,
    )


#: Brown's datum as a linear map of the 7 globals onto the P = 4 station layout of
#: :class:`sim.instruments.ranges.positions.RangeModel` (``X_1, Y_1, ..., X_4, Y_4, alpha, b``):
#: x1 = x3 = 0, y4 = -y2
BROWN_LAYOUT = np.zeros((10, 7))
for _row, _col, _v in (
    (1, 0, 1),
    (2, 1, 1),
    (3, 2, 1),
    (5, 3, 1),
    (6, 4, 1),
    (7, 2, -1),
    (8, 5, 1),
    (9, 6, 1),
):
    BROWN_LAYOUT[_row, _col] = _v


def _model(r_obs: np.ndarray | None) -> po.RangeModel:
    # dense: Brown's studies keep the engine's reference route, bit for bit (the compiled
    # kernel is this model's fast adjustment; ties between symmetric points in their notes
    # are decided by the last bits of the cofactors)
    return po.RangeModel(r_obs, BROWN_LAYOUT, P=4, dense=True)


def ranges(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Scale readings ``r = sqrt(d^2 - beta^2) - alpha`` (mm), shape ``(T, n, 4)``.

    points : ``(T, n, 2)`` mm; theta : ``(T, 7)``.
    """
    return po.ranges(points, po.from_brown_theta(theta))


def simulate_ranges(
    points: np.ndarray,
    theta: np.ndarray,
    rng: np.random.Generator,
    *,
    setting_sigma_um: float,
    settings: int,
    comparator_sigma_um: float = 0.0,
    bias_um: float = 0.0,
    return_settings: bool = False,
):
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
    return po.initial_points(r_obs, po.from_brown_theta(theta))


#: the engine's result object (kept under its former name)
AdjustResult = lsq.Result


def adjust(
    r_obs: np.ndarray,
    model: str,
    theta0: np.ndarray,
    points0: np.ndarray | None = None,
    tol_mm: float = 1e-10,
    max_iter: int = 30,
    engine: str = "auto",
) -> lsq.Result:
    """Batched Gauss-Newton adjustment of Brown's multilateration.

    r_obs : (T, n, 4) observed ranges, mm. model : ``known``, ``stations``, ``alpha`` or
    ``pivot``. theta0 : (T, 7) or (7,): the fixed parameters (for ``known``, the true
    stations, alpha, beta^2) and the initial values of the free ones. points0 : initial
    points (default: linear trilateration from ``theta0``). Solved by the engine
    :func:`sim.lsq.gauss_newton` (convergence: the largest correction of any unknown, mm;
    mm^2 for ``b``, or the remaining error estimated from the observed contraction, below
    ``tol_mm``). engine : ``numpy`` (the engine's loop), ``numba`` (the compiled kernel of
    :mod:`sim.instruments.ranges.multilateration_jit`, registered as the engine's fast path for this model) or
    ``auto`` (numba when installed). Returns :class:`sim.lsq.Result`.
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, not {model!r}")
    r_obs = np.asarray(r_obs, float)
    if r_obs.ndim != 3 or r_obs.shape[2] != 4:
        raise ValueError(f"r_obs must have shape (trials, points, 4), not {r_obs.shape}")
    T, n, _ = r_obs.shape
    p = MODELS[model]
    if 4 * n - (2 * n + p) < 0 or n < 3:
        raise ValueError(f"{n} points give {4 * n} observations for {2 * n + p} unknowns")
    if engine not in ("auto", "numpy", "numba"):
        raise ValueError(f"engine must be auto, numpy or numba, not {engine!r}")
    if engine == "numba" and not jit.available():
        raise ValueError("engine 'numba' needs numba installed")
    theta = np.broadcast_to(np.asarray(theta0, float), (T, 7)).copy()
    eng = {"auto": "auto", "numpy": "numpy", "numba": "fast"}[engine]
    p0 = None if points0 is None else np.array(points0, float)
    if p0 is not None and eng != "numpy":  # the engine's fast path starts from its own points
        res = _kernel_path(_model(r_obs), theta, lsq.Datum(np.arange(p)), tol_mm, max_iter, p0)
        if res is not None:
            return res
    return lsq.gauss_newton(
        _model(r_obs), theta, p0, lsq.Datum(np.arange(p)), tol_mm, max_iter, engine=eng
    )


def _kernel_path(model: po.RangeModel, theta, datum: lsq.Datum, tol, max_iter, points0=None):
    """Fast path of the engine for Brown's layout (the compiled kernel), or None. Trials the
    kernel leaves undecided (it could not prove their reduced normals regular) are adjusted
    again by the NumPy engine, whose exact rule decides them. ``points0``: the start of the
    points (None: linear trilateration)."""
    free = datum.free_index(model.n_global)
    if (
        not jit.available()
        or model.layout is not BROWN_LAYOUT
        or model.r_obs is None
        or datum.constraints is not None
        or not np.array_equal(free, np.arange(len(free)))
    ):
        return None
    r_obs = model.r_obs
    T, n, _ = r_obs.shape
    p = len(free)
    theta0 = theta.copy()
    start = None if points0 is None else np.array(points0, float)  # the kernel works in place
    pts, status, iters, res, ssq = jit.gauss_newton(r_obs, theta, start, p, tol, max_iter)
    dof = 4 * n - (2 * n + p)
    s0 = np.sqrt(ssq / dof) if dof > 0 else np.full(T, np.nan)
    rest = np.flatnonzero(status == UNDECIDED)
    if rest.size:  # the engine's exact rule on the NumPy path
        p0 = None if points0 is None else np.array(points0, float)[rest]
        g = lsq.gauss_newton(
            _model(r_obs[rest]), theta0[rest], p0, datum, tol, max_iter, engine="numpy"
        )
        pts[rest], theta[rest], res[rest] = g.points, g.theta, g.residuals
        s0[rest], iters[rest], status[rest] = g.sigma0, g.iterations, g.status
    return lsq.Result(pts, theta, res, s0, dof, iters, status, model, datum)


lsq.register_fast_path(po.RangeModel, _kernel_path)


def covariance(
    points: np.ndarray, theta: np.ndarray, model: str, station_xy: np.ndarray | None = None
):
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
    if station_xy is None:
        cof = lsq.cofactors(_model(None), points, theta, lsq.Datum(np.arange(p)))
    else:
        th = np.concatenate([np.reshape(station_xy, (-1, 8)), theta[:, 5:7]], 1)
        cof = lsq.cofactors(
            po.RangeModel(None, P=4, dense=True), points, th, lsq.Datum(np.arange(0))
        )
    return cof.points, cof.Qgg, cof.K, cof.Ninv
