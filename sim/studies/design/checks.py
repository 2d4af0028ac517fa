"""Cross-key checks of a ``brown_design`` config (seed ``004_f5bd9e86c308241f.txt``, Brown
1968), run on load after the keys of :mod:`.schema` are validated one by one: the paper's
design is a cell of the design grid, the measuring times are ordered, every geometry fits the
format and the scale plus micrometer (mm), and the sizes stay within the limits. Each raises
:class:`sim.mc.config.ConfigError` naming the key.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import positions as po
from sim.mc.schema_helpers import require
from sim.studies.design.external import paper_points
from sim.studies.design.schema import MAX_CELLS, MAX_POINTS

__all__ = ["check", "max_offset_mm"]

_PAPER_IN_GRID = (
    ("paper.positions", "design.positions"),
    ("paper.grid", "design.grids"),
    ("paper.extent_mm", "design.extents_mm"),
    ("paper.settings", "design.settings"),
    ("paper.setting_sigma_um", "design.setting_sigma_um"),
    ("paper.offset_mm", "design.offsets_mm"),
    ("paper.beta_mm", "design.beta_mm"),
)


def max_offset_mm(cfg: dict, extent_mm: float) -> float:
    """Largest station offset outside the midsides at which the farthest point of a square
    grid of half extent ``extent_mm`` stays within the scale plus the micrometer (4 positions):
    ``sqrt(e^2 + (h + e)^2) = L``."""
    lim = cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    return float(np.sqrt(max(lim**2 - extent_mm**2, 0.0)) - extent_mm - cfg["plate.format_mm"] / 2)


def check(cfg: dict) -> None:
    """Cross-key checks of a brown_design config (ConfigError naming the key)."""
    for key, lst in _PAPER_IN_GRID:
        require(
            any(np.isclose(cfg[key], v) for v in cfg[lst]),
            key,
            f"the paper's design must be a cell of the grid: {cfg[key]!r} is not in {lst} "
            f"{cfg[lst]}",
        )
    require(
        cfg["time.double_min"] > cfg["time.single_min"],
        "time.double_min",
        "must exceed time.single_min",
    )
    require(
        4 * cfg["time.pass_min"] < cfg["time.single_min"],
        "time.pass_min",
        "four passes would take the whole single-setting time (time.single_min)",
    )
    _check_geometry(cfg)
    _check_sizes(cfg)
    _check_paper_solvable(cfg)


def _check_geometry(cfg: dict) -> None:
    """The paper's, the datum's and the Zeiss geometry fit the format and the hardware."""
    half = cfg["plate.format_mm"] / 2
    datum_ext = (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2
    require(cfg["paper.extent_mm"] <= half, "paper.extent_mm", "outside the format")
    require(
        cfg["zeiss.half_extent_mm"] <= half,
        "zeiss.half_extent_mm",
        f"the Zeiss sample must lie on the format (half side {half:g} mm)",
    )
    require(datum_ext <= half, "datum.spacing_mm", "the datum grid leaves the format")
    hmax = max_offset_mm(cfg, cfg["paper.extent_mm"])
    require(
        cfg["paper.offset_mm"] <= hmax + 1e-9,
        "paper.offset_mm",
        f"the paper's design must fit its hardware: at {cfg['paper.offset_mm']:g} mm the "
        f"longest range exceeds the scale plus micrometer (at most {hmax:.1f} mm fits a +-"
        f"{cfg['paper.extent_mm']:g} mm grid)",
    )
    dmax = max_offset_mm(cfg, datum_ext)
    require(
        cfg["datum.offset_mm"] <= dmax + 1e-9,
        "datum.offset_mm",
        f"the datum geometry must be buildable: at {cfg['datum.offset_mm']:g} mm its "
        f"longest range exceeds the scale plus micrometer (at most {dmax:.1f} mm fits)",
    )
    for e in [cfg["zeiss.half_extent_mm"], 40.0]:  # 40 mm: the region's smallest layout
        require(
            (2 * int(e // 10) + 1) ** 2 >= cfg["zeiss.points"],
            "zeiss.points",
            f"+-{e:g} mm holds fewer 1 cm grid intersections than zeiss.points = "
            f"{cfg['zeiss.points']}",
        )


def _check_paper_solvable(cfg: dict) -> None:
    """The pivot model (stations, alpha and beta free) can be solved on the paper's design by
    the engine's one singularity rule (its cofactors are not finite where it is singular):
    a 2 x 2 grid cannot, in any number of positions, and its run failed in an eigenvalue
    solver naming no key."""
    th = po.design_theta(
        cfg["paper.positions"],
        cfg["plate.format_mm"] / 2 + cfg["paper.offset_mm"],
        cfg["comparator.alpha_mm"],
        cfg["paper.beta_mm"],
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        Qgg = po.covariance(paper_points(cfg)[None], th[None], "pivot")[1]
    require(
        bool(np.isfinite(Qgg).all()),
        "paper.grid",
        f"the pivot model (stations, alpha and beta free) cannot be solved on the paper's "
        f"{cfg['paper.grid']} x {cfg['paper.grid']} grid in {cfg['paper.positions']} "
        "positions: its reduced normal matrix is singular",
    )


_GRID_LISTS = (
    "design.positions",
    "design.grids",
    "design.extents_mm",
    "design.offsets_mm",
    "design.beta_mm",
    "design.settings",
    "design.setting_sigma_um",
)


def _check_sizes(cfg: dict) -> None:
    """The design grid, the plates and the budget's trials stay within the limits."""
    n_cells = int(np.prod([len(cfg[lst]) for lst in _GRID_LISTS]))
    require(
        n_cells <= MAX_CELLS,
        "design.offsets_mm",
        f"{n_cells} design cells exceed the limit of {MAX_CELLS}",
    )
    require(
        max(cfg["design.grids"]) ** 2 <= MAX_POINTS and cfg["datum.grid"] ** 2 <= MAX_POINTS,
        "design.grids",
        f"more than {MAX_POINTS} points per plate",
    )
    require(
        cfg["budget.max_trials"] >= 2 * cfg["chunk"],
        "budget.max_trials",
        "must allow at least two chunks (2 x chunk)",
    )
