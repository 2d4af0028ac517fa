"""The design trade-off of study ``brown_design`` (seed ``004``, Brown 1968), analytic.

Design cells: plate positions (P stations on a circle about the plate centre), station offset,
point grid and extent, settings per point, setting sigma and beta. Each cell's accuracy is the
datum-free cofactor sigma of the pivot model (inner constraints over the points) times the
range sigma ``sqrt(setting^2 / settings + comparator^2)`` (um); its cost the paper's measuring
time (min); it is *feasible* when every range fits on the scale plus the micrometer, the points
lie on the format and the pivot stays outside the plate in every position.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm
from sim.mc.sweep import expand

__all__ = [
    "time_model",
    "measuring_time",
    "range_sigma",
    "geometry_eval",
    "design_cells",
    "pareto_front",
    "within_front",
    "plate_setup",
]


def time_model(cfg: dict):
    """Minutes per point visit and per extra setting from the paper's two timings."""
    t_extra = (cfg["time.double_min"] - cfg["time.single_min"]) / (4 * cfg["time.images"])
    t_visit = (cfg["time.single_min"] - 4 * cfg["time.pass_min"]) / (4 * cfg["time.images"])
    return t_visit, t_extra


def measuring_time(cfg, P, n, L):
    t_visit, t_extra = time_model(cfg)
    return P * (cfg["time.pass_min"] + n * (t_visit + (L - 1) * t_extra))


def range_sigma(s_set, L, s_comp):
    return np.sqrt(np.asarray(s_set) ** 2 / np.asarray(L) + s_comp**2)


def geometry_eval(cfg: dict, P: int, k: int, ext: float, offsets, betas) -> dict:
    """Analytic cofactor sigmas (datum-free: inner constraints over the points) and the
    feasibility of one point grid for all offsets x betas (batched as the trial axis)."""
    half = cfg["plate.format_mm"] / 2
    O, B = (
        a.ravel()
        for a in np.meshgrid(np.asarray(offsets, float), np.asarray(betas, float), indexing="ij")
    )
    pts = grid_points(k, 2 * ext / (k - 1))
    G = len(O)
    TH = np.stack(
        [po.design_theta(P, half + o, cfg["comparator.alpha_mm"], b) for o, b in zip(O, B)]
    )
    Pb = np.broadcast_to(pts, (G,) + pts.shape).copy()
    S = dm.inner(pts)
    sig = {}
    for m in ("known", "pivot"):
        with np.errstate(invalid="ignore"):  # singular geometries give NaN (recorded as such)
            Fm = dm.s_transform(po.full_point_covariance(Pb, TH, m, "inner"), S)
        sig[m] = np.sqrt((dm.point_sigmas(Fm) ** 2).mean(-1))  # (G, n) pooled
    r = po.ranges(Pb, TH)
    rmax, rmin = r.max(axis=(1, 2)), r.min(axis=(1, 2))
    St = po.stations(TH)
    inside = ~np.all(np.abs(St).max(-1) > half, axis=1)
    dof = P * k * k - 2 * k * k - (2 * P + 2) + 3
    lim = cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    reasons = []
    for g in range(G):
        why = []
        if ext > half:
            why.append(f"points reach {ext:g} mm, outside the {cfg['plate.format_mm']:g} mm format")
        if rmax[g] > lim:
            why.append(f"longest range {rmax[g]:.1f} mm exceeds the {lim:g} mm scale + micrometer")
        if rmin[g] < 0:
            why.append("negative range")
        if inside[g]:
            why.append("pivot over the plate in some position (station inside the format)")
        if dof <= 0:
            why.append(f"no redundancy ({dof} degrees of freedom)")
        if not np.all(np.isfinite(sig["pivot"][g])):
            why.append("singular geometry")
        reasons.append("; ".join(why))
    return {
        "offset_mm": O,
        "beta_mm": B,
        "n": k * k,
        "known_worst": sig["known"].max(1),
        "known_mean": np.sqrt((sig["known"] ** 2).mean(1)),
        "pivot_worst": sig["pivot"].max(1),
        "pivot_mean": np.sqrt((sig["pivot"] ** 2).mean(1)),
        "rmax_mm": rmax,
        "rmin_mm": rmin,
        "reason": reasons,
        "dof": dof,
    }


#: the derived columns of ``design.parquet`` after the cell keys
DERIVED = (
    "n_points",
    "range_sigma_um",
    "worst_sigma_um",
    "mean_sigma_um",
    "known_worst_sigma_um",
    "dilution_mean_pct",
    "time_min",
    "max_range_mm",
    "dof",
    "feasible",
    "reason",
    "paper_design",
    "pareto",
)


def _geometries(cfg: dict) -> dict[tuple, dict]:
    """The analytic geometry of every (positions, grid, extent, offset, beta) cell."""
    geo = {}
    for P in cfg["design.positions"]:
        for k in cfg["design.grids"]:
            for e in cfg["design.extents_mm"]:
                g = geometry_eval(cfg, P, k, e, cfg["design.offsets_mm"], cfg["design.beta_mm"])
                for i, (o, b) in enumerate(zip(g["offset_mm"], g["beta_mm"])):
                    geo[(P, k, e, o, b)] = {
                        kk: (v[i] if isinstance(v, (np.ndarray, list)) else v)
                        for kk, v in g.items()
                    }
    return geo


def _is_paper_design(cfg: dict, cell: dict) -> bool:
    return bool(
        cell["positions"] == cfg["paper.positions"]
        and cell["grid"] == cfg["paper.grid"]
        and np.isclose(cell["extent_mm"], cfg["paper.extent_mm"])
        and np.isclose(cell["offset_mm"], cfg["paper.offset_mm"])
        and np.isclose(cell["beta_mm"], cfg["paper.beta_mm"])
        and cell["settings"] == cfg["paper.settings"]
        and np.isclose(cell["setting_sigma_um"], cfg["paper.setting_sigma_um"])
    )


def _cell_row(cfg: dict, cell: dict, g: dict) -> dict:
    """The derived columns of one cell (all but ``pareto``) from its geometry ``g``."""
    sr = float(range_sigma(cell["setting_sigma_um"], cell["settings"], cfg["comparator.sigma_um"]))
    n = cell["grid"] ** 2
    return {
        "n_points": n,
        "range_sigma_um": sr,
        "worst_sigma_um": g["pivot_worst"] * sr,
        "mean_sigma_um": g["pivot_mean"] * sr,
        "known_worst_sigma_um": g["known_worst"] * sr,
        "dilution_mean_pct": (g["pivot_mean"] / g["known_mean"] - 1) * 100,
        "time_min": measuring_time(cfg, cell["positions"], n, cell["settings"]),
        "max_range_mm": g["rmax_mm"],
        "dof": g["dof"],
        "feasible": g["reason"] == "",
        "reason": g["reason"],
        "paper_design": _is_paper_design(cfg, cell),
    }


def design_cells(cfg: dict) -> dict:
    """One row per design cell (the grid of :func:`sim.mc.sweep.expand`)."""
    table = {
        "positions": cfg["design.positions"],
        "grid": cfg["design.grids"],
        "extent_mm": cfg["design.extents_mm"],
        "offset_mm": cfg["design.offsets_mm"],
        "beta_mm": cfg["design.beta_mm"],
        "settings": cfg["design.settings"],
        "setting_sigma_um": cfg["design.setting_sigma_um"],
    }
    keys, cells, _, _ = expand(table)
    geo = _geometries(cfg)
    cols: dict[str, list] = {c: [] for c in keys + list(DERIVED)}
    for cell in cells:
        key = ("positions", "grid", "extent_mm", "offset_mm", "beta_mm")
        row = _cell_row(cfg, cell, geo[tuple(cell[k] for k in key)])
        for kk in keys:
            cols[kk].append(cell[kk])
        for kk, v in row.items():
            cols[kk].append(v)
    cols["pareto"] = list(
        pareto_front(
            np.array(cols["time_min"]), np.array(cols["worst_sigma_um"]), np.array(cols["feasible"])
        )
    )
    return cols


#: accuracies within this relative difference are a tie in the Pareto front: designs that are
#: equal but for rounding (symmetric layouts) must not dominate each other by their last bits
TIE_RTOL = 1e-9


def pareto_front(cost: np.ndarray, acc: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Feasible cells not dominated in (cost, acc), both to be minimised; costs within 1e-9
    min and accuracies within :data:`TIE_RTOL` relative count as equal."""
    c, a = np.where(ok, cost, np.inf), np.where(ok, acc, np.inf)
    ci, cj, ai, aj = c[:, None], c[None, :], a[:, None], a[None, :]
    with np.errstate(invalid="ignore"):  # inf - inf of two infeasible cells: not a tie
        same_a = np.abs(aj - ai) <= TIE_RTOL * np.maximum(np.abs(ai), np.abs(aj))
        same_c = np.abs(cj - ci) <= 1e-9
    dom = (
        ((cj <= ci) | same_c)
        & ((aj <= ai) | same_a)
        & (((cj < ci) & ~same_c) | ((aj < ai) & ~same_a))
    )
    return ok & ~dom.any(axis=1)


def within_front(cost, acc, ok, j):
    """How much worse (ratio of accuracy) cell ``j`` is than the best feasible accuracy
    available at no more cost."""
    sel = ok & (cost <= cost[j] + 1e-9)
    return float(acc[j] / acc[sel].min())


def plate_setup(cfg, P, k, ext, offset, beta):
    """Points (mm) of a k x k grid of half extent ``ext`` and the P-position parameters."""
    pts = grid_points(k, 2 * ext / (k - 1))
    th = po.design_theta(P, cfg["plate.format_mm"] / 2 + offset, cfg["comparator.alpha_mm"], beta)
    return pts, th
