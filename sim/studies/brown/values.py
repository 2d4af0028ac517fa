"""What the Brown model predicts for each claim, batched over geometries (analytic).

One function per study maps the cofactor sigmas of a batch of geometries (stations at
different offsets, points at different extents; the geometries play the trial axis of
:func:`sim.instruments.ranges.multilateration.covariance`) to the arguments of
:meth:`sim.claims.book.ClaimBook.score` for every claim that depends on the geometry. The nominal
run and the sweep of the unprinted inputs (:mod:`.consistency`) call the same functions, so a
nominal row equals the sweep at the nominal offset.

Sigmas are per unit range sigma (dimensionless ratios) unless a name says ``_um``.
Seed paper 004 (Brown 1968).
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import pattern_points
from sim.instruments.ranges import multilateration as ml
from sim.lsq import distributions as D

#: sigma0 values spanning the paper's printed closure 1.6 um (1.55-1.65 um)
S0_PAPER_UM = np.linspace(1.55, 1.65, 21)
#: quantile levels of the closure sigma0 over plates (semi-analytic one-plate statistics)
N_QUANT = 1000


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


def centre_index(pts: np.ndarray) -> int:
    return int(np.argmin(np.hypot(pts[:, 0], pts[:, 1])))


def dilution_values(pts: np.ndarray, sig: dict, mono: np.ndarray) -> list[dict]:
    """Per geometry, the score arguments of the Concept claims that depend on the geometry.

    pts : (G, n, 2) points; sig : model -> (G, n, 2) unit sigmas; mono : (G,) bools.
    """
    kn, st, pv = sig["known"], sig["stations"], sig["pivot"]
    c = centre_index(pts[0])
    centre = pooled(kn[:, c])
    edge = kn.max(axis=(1, 2))
    dil = (pooled(st) / pooled(kn) - 1) * 100
    extra = (pooled(pv) / pooled(st) - 1) * 100
    out = []
    for g in range(len(kn)):
        out.append(
            {
                "brown.known_center.ratio": dict(value=float(centre[g]), interval="exact"),
                "brown.known_edge.ratio": dict(value=float(edge[g]), interval="exact"),
                "brown.dilution.range_pct": dict(elems=(dil[g], dil[g]), interval="exact"),
                "brown.dilution_falls_with_points.monotone": dict(
                    value=float(mono[g]), interval="exact"
                ),
                "brown.pivot_extra_dilution.range_pct": dict(
                    elems=(extra[g], extra[g]), interval="exact"
                ),
            }
        )
    return out


def closure_quantiles(range_sigma_um: float, dof: int, n: int = N_QUANT) -> np.ndarray:
    """sigma0 of one plate at ``n`` evenly spaced quantile levels: sigma0^2 dof / sigma^2 is
    chi-square with ``dof`` degrees of freedom (a deterministic sample of the plates)."""
    q = (np.arange(n) + 0.5) / n
    return range_sigma_um * np.sqrt(D.chi2_ppf(q, dof) / dof)


def point_sigma_stats(sig_um: np.ndarray) -> dict[str, np.ndarray]:
    """One-plate statistics of the point sigmas ``(..., n, 2)`` (um) as the paper prints them
    (one decimal): share in 1.1-1.3, points whose larger sigma prints >= 1.5, the largest."""
    return {
        "share": ((sig_um >= 1.05) & (sig_um < 1.35)).mean(axis=(-1, -2)),
        "count": (sig_um.max(-1) >= 1.45).sum(-1).astype(float),
        "max": sig_um.max(axis=(-1, -2)),
    }


def table1_values(cof: np.ndarray, s0_plates_um: np.ndarray) -> list[dict]:
    """Per geometry, the score arguments of the Table-1 claims that depend on the geometry.

    cof : (G, n, 2) cofactor sigmas of the pivot model (sigma / sigma0).
    s0_plates_um : sigma0 of simulated plates (quantiles): the one-plate distributions.
    The ``*_at_paper_closure`` claims take sigma0 as printed (1.6 um, i.e. 1.55-1.65): their
    interval is the range over that rounding.
    """
    at = point_sigma_stats(S0_PAPER_UM[None, :, None, None] * cof[:, None])  # (G, S)
    mid = len(S0_PAPER_UM) // 2
    out = []
    for g in range(len(cof)):
        pl = point_sigma_stats(s0_plates_um[:, None, None] * cof[g][None])  # (Q,)
        c = cof[g].ravel()
        row = {
            "brown.table1_point_sigma.below_closure": dict(elems=(c, c), interval="exact"),
            "brown.table1_point_sigma.share_1p1_1p3": dict(samples=pl["share"]),
            "brown.table1_point_sigma.points_ge_1p45": dict(samples=pl["count"]),
            "brown.table1_point_sigma.max_um": dict(samples=pl["max"]),
        }
        for key, cid in (
            ("share", "share_at_paper_closure"),
            ("count", "count_at_paper_closure"),
            ("max", "max_at_paper_closure_um"),
        ):
            v = at[key][g]
            row[f"brown.table1_point_sigma.{cid}"] = dict(
                value=float(v[mid]), ci=(float(v.min()), float(v.max())), interval="ci"
            )
        out.append(row)
    return out
