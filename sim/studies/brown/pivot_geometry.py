"""The plate and comparator geometry of the two Brown studies (seed 004) and the checks that
the pivot model can be adjusted on it: the plate's points, the stations' design globals, no
point within the tangential offset beta of a station, and a reduced normal matrix the
engine's one singularity rule accepts (for the plate and for each grid of
``dilution.grids``).

Coordinates in mm.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import pattern_points
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po
from sim.lsq.normals import RCOND, reduced_normals, scaled_rcond
from sim.mc.config import ConfigError
from sim.mc.streams import chunk_rng
from sim.studies.brown.range_keys import moved_from_paper
from sim.studies.brown.values import thetas

__all__ = ["check_pivot", "pivot_rcond", "points_of", "setup", "within_beta"]


def points_of(cfg: dict) -> np.ndarray:
    """The plate's points (n, 2) mm; a random pattern is drawn once from stream part 99 of
    ``plate.layout_seed``, never of the run's ``seed``: a sweep's cells (validated at the
    study's seed, run at their own) and ``--seed`` each drew another plate, so a sweep over an
    error compared plates of other layouts."""
    return pattern_points(
        cfg["plate.pattern"],
        grid=cfg["plate.grid"],
        spacing_mm=cfg["plate.spacing_mm"],
        n_random=cfg["plate.n_random"],
        half_extent_mm=cfg["plate.random_half_extent_mm"],
        points=cfg["plate.points"],
        rng=chunk_rng(cfg["plate.layout_seed"], 99, 0),
    )


def setup(cfg: dict) -> tuple[np.ndarray, np.ndarray]:
    """The plate's points (n, 2) mm and the comparator's design globals (7,): the four
    stations half the format plus ``comparator.station_offset_mm`` from the centre, alpha
    and beta in mm."""
    pts = points_of(cfg)
    h = cfg["plate.format_mm"] / 2 + cfg["comparator.station_offset_mm"]
    theta = ml.design_theta(h, cfg["comparator.alpha_mm"], cfg["comparator.beta_mm"])
    return pts, theta


def within_beta(cfg: dict, key: str, pts: np.ndarray) -> None:
    """A point no farther from a station than the tangential offset beta has no range
    (r = sqrt(d^2 - beta^2) - alpha): it was accepted (or blamed on a singular normal matrix,
    or on the scale) and every trial failed at run time after a NumPy warning."""
    _, theta = setup(cfg)
    st = ml.stations(theta)  # (4, 2) mm
    with np.errstate(over="ignore"):  # inf: the range check names stations that far out
        d2 = ((pts[:, None, :] - st[None, :, :]) ** 2).sum(-1)  # (n, 4) mm^2
    beta = cfg["comparator.beta_mm"]
    bad = np.argwhere(d2 <= beta**2)
    if len(bad):
        i, j = bad[0]
        raise ConfigError(
            key,
            f"point {i + 1} ({pts[i, 0]:g}, {pts[i, 1]:g}) mm lies {np.sqrt(d2[i, j]):.3g} mm "
            f"from station {j + 1} ({st[j, 0]:g}, {st[j, 1]:g}), within the tangential pivot "
            f"offset beta = {beta:g} mm: its range is undefined (move the point, or the "
            "stations out: comparator.station_offset_mm)",
        )


def pivot_rcond(pts: np.ndarray, theta: np.ndarray) -> float:
    """The engine's singularity measure (:func:`sim.lsq.normals.scaled_rcond`, 0 for a
    singular point block) of the pivot model's reduced normals -- the widest model the
    studies adjust: stations, alpha and beta^2 free -- at the true points (n, 2) mm and
    globals (7,), where the noise-free ranges are exact."""
    r = ml.ranges(pts[None], theta[None])
    model = po.RangeModel(r, ml.BROWN_LAYOUT, P=4, dense=True)
    red = reduced_normals(model, pts[None], theta[None], np.arange(7))
    return float(scaled_rcond(red.Nbar)[0]) if red.ok[0] else 0.0


def check_pivot(cfg: dict, key: str, pts: np.ndarray, base: dict) -> None:
    """Every geometry the run adjusts with the pivot model can be solved by the engine's one
    rule (a 2 x 2 grid cannot: its symmetry leaves the reduced normals singular, and every
    trial failed at run time): the plate's points, and the grids of ``dilution.grids`` over
    the plate's extent. ``base``: the schema's defaults (the paper's values), by key."""
    _, theta = setup(cfg)
    if not np.all(np.isfinite(ml.ranges(pts[None], theta[None]))):
        return  # an overflow is named by the range check before this one
    rc = pivot_rcond(pts, theta)
    if not rc > RCOND:
        moved = moved_from_paper(cfg, key, base)
        blame = key  # the comparator's keys when the points are solved from the paper's
        # stations (stations 1e9 mm out blamed the plate's grid)
        if comp := [k for k in moved if k.startswith("comparator.")]:
            paper = {**cfg, **{k: base[k] for k in comp}}
            blame = comp[-1] if pivot_rcond(pts, setup(paper)[1]) > RCOND else key
        raise ConfigError(
            blame,
            f"the pivot model (stations, alpha and beta free) cannot be solved at these "
            f"{len(pts)} points: its reduced normal matrix is singular (scaled reciprocal "
            f"condition {rc:.2g}, the adjustment needs > {RCOND:g})"
            + (
                f"; changed from their paper or nominal values: {', '.join(moved)}" if moved else ""
            ),
        )
    ext = float(np.abs(pts).max())
    th = thetas(cfg["plate.format_mm"], cfg["comparator.station_offset_mm"], 0.0, 0.0)[0]
    for k in cfg.get("dilution.grids", ()):
        g = pattern_points("grid", grid=k, spacing_mm=2.0 * ext / (k - 1))
        rc = pivot_rcond(g, th)
        if not rc > RCOND:
            raise ConfigError(
                "dilution.grids",
                f"the pivot model cannot be solved on a {k} x {k} grid: its reduced normal "
                f"matrix is singular (scaled reciprocal condition {rc:.2g}, the adjustment "
                f"needs > {RCOND:g})",
            )
