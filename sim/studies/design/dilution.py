"""The datum of Brown's dilution (seed ``004``, *The Concept*): analytic, no Monte Carlo.

Brown's 5-15 % dilution is the pooled sigma of the ``stations`` model over the ``known`` model
in *his* datum (x1 = x3 = 0, y4 = -y2), which the station estimates fix. Here the same
cofactors are also S-transformed to inner constraints over the measured points (a datum that
does not lean on the stations) and to a similarity onto the four corner points; the dilution is
compared datum by datum. The geometry is brown_dilution's; it is flagged ``feasible = False``
(idealised) when its ranges do not fit on the scale plus the micrometer.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm

__all__ = ["datum_analysis", "DATUMS"]

DATUMS = ("brown", "inner", "corners")


def datum_analysis(cfg: dict) -> tuple[dict, dict]:
    """Returns the per-point table and ``{(model, datum): (min %, max %)}`` (the corner datum
    excludes the four corner points, which fix the fit), with ``feasible`` and the longest
    range (mm)."""
    k, sp = cfg["datum.grid"], cfg["datum.spacing_mm"]
    pts = grid_points(k, sp)
    h = cfg["plate.format_mm"] / 2 + cfg["datum.offset_mm"]
    th = po.design_theta(4, h, cfg["comparator.alpha_mm"], cfg["datum.beta_mm"])
    n = len(pts)
    rmax = float(po.ranges(pts[None], th[None]).max())
    feasible = rmax <= cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    corners = dm.corner_indices(pts)
    Ss = {
        "brown": np.eye(2 * n),
        "inner": dm.inner(pts),
        "corners": dm.similarity_onto(pts, corners),
    }
    pooled = {}
    for m in ("known", "stations", "pivot"):
        Fm = po.full_point_covariance(pts[None], th[None], m, "brown")[0]
        for dn, S in Ss.items():
            pooled[(m, dn)] = np.sqrt((dm.point_sigmas(S @ Fm @ S.T) ** 2).mean(-1))
    cols = {
        c: []
        for c in (
            "model",
            "datum",
            "point",
            "x_mm",
            "y_mm",
            "pooled",
            "dilution_pct",
            "corner",
            "feasible",
        )
    }
    ranges = {"feasible": feasible, "max_range_mm": rmax}
    nc = ~np.isin(np.arange(n), corners)
    for m in ("known", "stations", "pivot"):
        for dn in DATUMS:
            p = pooled[(m, dn)]
            with np.errstate(divide="ignore", invalid="ignore"):
                dil = (p / pooled[("known", dn)] - 1) * 100
            cols["model"] += [m] * n
            cols["datum"] += [dn] * n
            cols["point"] += list(range(1, n + 1))
            cols["x_mm"] += list(pts[:, 0])
            cols["y_mm"] += list(pts[:, 1])
            cols["pooled"] += list(p)
            cols["dilution_pct"] += list(dil)
            cols["corner"] += [bool(j in corners) for j in range(n)]
            cols["feasible"] += [feasible] * n
            if m != "known":
                d = dil[nc] if dn == "corners" else dil
                ranges[(m, dn)] = (float(d.min()), float(d.max()))
    return cols, ranges
