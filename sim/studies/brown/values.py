"""What the Brown model predicts for each claim, batched over geometries (analytic).

Cofactor sigmas of a batch of geometries (stations at different offsets, points at
different extents; the geometries play the trial axis of
:func:`sim.instruments.ranges.multilateration.covariance`), the dilution and the one-plate
statistics of Table 1's printed sigmas. The region of the unprinted inputs (:mod:`.region`)
and the nominal example call the same functions.

Sigmas are per unit range sigma (dimensionless ratios) unless a name says ``_um``.
Seed paper 004 (Brown 1968).
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import pattern_points
from sim.instruments.ranges import multilateration as ml


def pooled(a: np.ndarray) -> np.ndarray:
    """sigma of a point: rms of its sigma_x and sigma_y (last axis)."""
    return np.sqrt((a**2).mean(axis=-1))


def sigmas(P: np.ndarray, TH: np.ndarray, model: str) -> np.ndarray:
    """Cofactor sigmas sqrt(Q_xx), sqrt(Q_yy) ``(G, n, 2)`` of ``G`` geometries."""
    with np.errstate(invalid="ignore"):
        Q = ml.covariance(P, TH, model)[0]
        return np.sqrt(np.stack([Q[..., 0, 0], Q[..., 1, 1]], -1))


def thetas(format_mm: float, offsets, alpha_mm: float, beta_mm: float) -> np.ndarray:
    return np.stack(
        [ml.design_theta(format_mm / 2 + o, alpha_mm, beta_mm) for o in np.atleast_1d(offsets)]
    )


def start_theta(theta: np.ndarray, model: str) -> np.ndarray:
    """Initial globals: the design (true) stations; alpha and beta^2 start at 0 when free."""
    t0 = theta.copy()
    t0[5 + (model == "alpha") : ml.MODELS[model]] = 0.0
    return t0


def dilution_curve(
    format_mm: float, grids, half_extent, offsets, alpha_mm=0.0, beta_mm=0.0, pivot: bool = True
):
    """Per-point dilution of ``stations`` over ``known`` (%) of k x k grids at each
    (half extent, offset) pair: dict grid -> ``(G, k*k)``, plus the pivot's extra (%) (empty
    without ``pivot``)."""
    E = np.atleast_1d(np.asarray(half_extent, float))
    TH = thetas(format_mm, offsets, alpha_mm, beta_mm)
    out, extra = {}, {}
    for k in grids:
        g = pattern_points("grid", grid=k, spacing_mm=2.0 / (k - 1))  # unit half extent
        P = g[None] * E[:, None, None]
        kn, st = (pooled(sigmas(P, TH, m)) for m in ("known", "stations"))
        out[k] = (st / kn - 1) * 100
        if pivot:
            extra[k] = (pooled(sigmas(P, TH, "pivot")) / st - 1) * 100
    return out, extra


def monotone(curve: dict) -> np.ndarray:
    """True where both the mean and the largest per-point dilution fall with every step to
    more points, ``(G,)``."""
    ks = sorted(curve)
    mean = np.stack([curve[k].mean(1) for k in ks], 1)
    mx = np.stack([curve[k].max(1) for k in ks], 1)
    return np.all(np.diff(mean, axis=1) < 0, axis=1) & np.all(np.diff(mx, axis=1) < 0, axis=1)
