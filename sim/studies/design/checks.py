"""Cross-key checks of a ``brown_design`` config (seed ``004_f5bd9e86c308241f.txt``, Brown
1968), run on load after the keys of :mod:`.schema` are validated one by one: the paper's
design is a cell of the design grid, the measuring times are ordered, every geometry fits the
format and the scale plus micrometer (mm), every range the study simulates reads on the scale
(the pivot offsets alpha and beta below the shortest distance from a station to a point,
:func:`_check_readings`), the nominal coverage's noise leaves trials to compute, and the
sizes stay within the limits. Each raises :class:`sim.mc.config.ConfigError` naming the key.

The scale reads ``r = sqrt(d^2 - beta^2) - alpha`` for a point ``d`` mm from the station
(:func:`sim.instruments.ranges.positions.ranges`): beta (the ball's offset across the scale)
must be shorter than the distance to the nearest point, or the arm cannot reach it, and alpha
(the scale's zero behind the pivot) shorter than that point's ``sqrt(d^2 - beta^2)``, or the
scale would read a negative range.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import positions as po
from sim.mc.schema_helpers import require
from sim.studies.design.external import paper_points
from sim.studies.design.schema import BETA_MAX_MM, MAX_CELLS, MAX_POINTS

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

_BETA_KEYS = ("design.beta_mm", "paper.beta_mm", "datum.beta_mm", "coverage.betas_mm")


def max_offset_mm(cfg: dict, extent_mm: float) -> float:
    """Largest station offset outside the midsides at which the farthest point of a square
    grid of half extent ``extent_mm`` stays within the scale plus the micrometer (4 positions):
    ``sqrt(e^2 + (h + e)^2) = L``."""
    lim = cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    return float(np.sqrt(max(lim**2 - extent_mm**2, 0.0)) - extent_mm - cfg["plate.format_mm"] / 2)


def _check_beta(cfg: dict) -> None:
    """beta, the pivot ball's offset across the scale, at most :data:`.schema.BETA_MAX_MM`."""
    for key in _BETA_KEYS:
        for b in np.atleast_1d(cfg[key]):
            require(
                b <= BETA_MAX_MM,
                key,
                f"beta = {b:g} mm is more than half the 29 mm width of the scale "
                f"({BETA_MAX_MM:g} mm): the pivot ball lies under the scale",
            )


def check(cfg: dict) -> None:
    """Cross-key checks of a brown_design config (ConfigError naming the key)."""
    _check_beta(cfg)
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
    _check_readings(cfg)
    _check_coverage_noise(cfg)
    _check_paper_solvable(cfg)


def _fits(hmax: float, what: str = "") -> str:
    """Which station offsets fit ``what``: "at most 32.8 mm fits", or, when none does (a
    scale too short for the grid: it read "at most -32.8 mm fits"), that none fits and what
    to change."""
    if hmax < 0:
        return f"no offset fits{what}: lengthen scale.graduated_mm or shrink the grid"
    return f"at most {hmax:.1f} mm fits{what}"


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
    grid = f" a +-{cfg['paper.extent_mm']:g} mm grid"
    require(
        cfg["paper.offset_mm"] <= hmax + 1e-9,
        "paper.offset_mm",
        f"the paper's design must fit its hardware: at {cfg['paper.offset_mm']:g} mm the "
        f"longest range exceeds the scale plus micrometer ({_fits(hmax, grid)})",
    )
    dmax = max_offset_mm(cfg, datum_ext)
    require(
        cfg["datum.offset_mm"] <= dmax + 1e-9,
        "datum.offset_mm",
        f"the datum geometry must be buildable: at {cfg['datum.offset_mm']:g} mm its "
        f"longest range exceeds the scale plus micrometer ({_fits(dmax)})",
    )
    P, n = cfg["paper.positions"], cfg["zeiss.points"]
    dof = P * n - 2 * n - (2 * P + 2) + 3  # readings - unknowns (the rigid fit fixes 3)
    need = int(np.floor((2 * P - 1) / (P - 2))) + 1
    require(
        dof > 0,
        "zeiss.points",
        f"{n} points in {P} positions give {P * n} readings for {2 * n} coordinates and "
        f"{2 * P + 2} comparator parameters less the rigid fit's 3: no redundancy, the pivot "
        f"model cannot be solved on the Zeiss sample (at least {need} points)",
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


#: the nominal coverage run (seed 004's formal precision) is a small-error statement: its
#: range sigma at most this share of the datum plate's spacing and of its shortest distance
#: from a station, sqrt(d^2 - beta^2) (alpha only shifts the readings). At
#: 2 % no trial of 400 failed to converge on any of six plates tried; at 20 %, up to 58 %
#: did, and at 100 mm on Brown's plate none converged (the claims had nothing to score).
NOISE_SHARE = 0.01


def _distances(P: int, h: float, pts: np.ndarray) -> np.ndarray:
    """Distances (mm) from the ``P`` stations ``h`` mm from the centre to the points."""
    return po.ranges(pts[None], po.design_theta(P, h)[None])[0]


def _reach(cfg: dict, what: str, beta_key: str, beta: float, d: np.ndarray) -> None:
    """beta below the nearest point's distance, alpha below that point's reading length."""
    dmin = float(d.min())
    require(
        beta < dmin,
        beta_key,
        f"beta = {beta:g} mm reaches the {dmin:.4g} mm from a station to the nearest point of "
        f"{what}: the arm cannot measure a point nearer than its offset across the scale",
    )
    alpha = cfg["comparator.alpha_mm"]
    rmin = float(np.sqrt(d**2 - beta**2).min())
    require(
        alpha < rmin,
        "comparator.alpha_mm",
        f"alpha = {alpha:g} mm must be below the shortest distance the scale reads on {what} "
        f"(sqrt(d^2 - beta^2) = {rmin:.4g} mm at beta = {beta:g} mm): its nearest point "
        "would read a negative range",
    )


def _check_readings(cfg: dict) -> None:
    """Every range the study simulates reads on the scale: the paper's design cell (all of
    them within the scale plus micrometer, its pivot beside the plate, as the design grid
    asks of a feasible cell), and the datum plate of the dilution and the coverage runs at
    every beta and grid they take (its longest ranges may exceed the scale: idealised)."""
    half = cfg["plate.format_mm"] / 2
    P, h = cfg["paper.positions"], half + cfg["paper.offset_mm"]
    what = f"the paper's design ({P} positions, stations {cfg['paper.offset_mm']:g} mm out)"
    d = _distances(P, h, paper_points(cfg))
    _reach(cfg, what, "paper.beta_mm", cfg["paper.beta_mm"], d)
    rmax = float((np.sqrt(d**2 - cfg["paper.beta_mm"] ** 2) - cfg["comparator.alpha_mm"]).max())
    lim = cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    require(
        rmax <= lim + 1e-9,
        # alpha < 0 lengthens every reading; off the axes (P != 4) the far corners are
        # farther than the 4-position rule of paper.offset_mm allows for
        "comparator.alpha_mm"
        if cfg["comparator.alpha_mm"] < 0
        else ("paper.offset_mm" if P == 4 else "paper.positions"),
        f"the longest range of {what} reads {rmax:.1f} mm at alpha = "
        f"{cfg['comparator.alpha_mm']:g} mm, beyond the {lim:g} mm scale plus micrometer",
    )
    S = po.circle_stations(P, h)
    over = np.abs(S).max(-1) <= half
    need = float((half / (np.abs(po.circle_stations(P, 1.0)).max(-1))).max() - half)
    require(
        not over.any(),
        "paper.offset_mm",
        f"in {P} positions a station {cfg['paper.offset_mm']:g} mm out stands over the "
        f"{cfg['plate.format_mm']:g} mm format: the pivot must stand beside the plate in every "
        f"position (more than {need:.1f} mm out)",
    )
    _check_region_alpha(cfg)
    ext = (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2
    hd = half + cfg["datum.offset_mm"]
    for k in dict.fromkeys([cfg["datum.grid"], *cfg["coverage.grids"]]):
        d = _distances(4, hd, grid_points(k, 2 * ext / (k - 1)))
        what = f"the datum plate ({k} x {k} points, stations {cfg['datum.offset_mm']:g} mm out)"
        _reach(cfg, what, "datum.beta_mm", cfg["datum.beta_mm"], d)
        for b in cfg["coverage.betas_mm"]:
            _reach(cfg, what, "coverage.betas_mm", b, d)


def region_alpha_max_mm() -> float:
    """The shortest reading (alpha = 0) of Table 1's plate over the region of the unprinted
    inputs (:mod:`.region`: stations from the lowest offset out, beta up to its highest;
    :data:`sim.instruments.ranges.brown.INPUTS`): alpha must stay below it (mm)."""
    ins = B.INPUTS["inputs"]
    o, b = ins["station_offset_mm"]["low"], ins["beta_mm"]["high"]
    return float(B.min_range_mm(B.table1_points()[None], B.thetas(o, b, 0.0))[0])


def _check_region_alpha(cfg: dict) -> None:
    """Every plate the region explores (Table 1's, the comparator that measured it) reads."""
    top = region_alpha_max_mm()
    ins = B.INPUTS["inputs"]
    require(
        cfg["comparator.alpha_mm"] < top,
        "comparator.alpha_mm",
        f"alpha = {cfg['comparator.alpha_mm']:g} mm must be below {top:.4g} mm, the shortest "
        f"distance the scale reads on Table 1's plate over the region the study explores "
        f"(stations from {ins['station_offset_mm']['low']:g} mm out, beta up to "
        f"{ins['beta_mm']['high']:g} mm): its nearest point would read a negative range",
    )


def _check_coverage_noise(cfg: dict) -> None:
    """The nominal coverage's range sigma leaves converged trials (:data:`NOISE_SHARE`)."""
    pts = grid_points(cfg["datum.grid"], cfg["datum.spacing_mm"])
    d = _distances(4, cfg["plate.format_mm"] / 2 + cfg["datum.offset_mm"], pts)
    qmin = float(np.sqrt(d**2 - cfg["datum.beta_mm"] ** 2).min())
    top = NOISE_SHARE * min(cfg["datum.spacing_mm"], qmin) * 1e3
    require(
        cfg["coverage.sigma_um"] <= top,
        "coverage.sigma_um",
        f"{cfg['coverage.sigma_um']:g} um is more than {NOISE_SHARE:.0%} of the datum plate's "
        f"{cfg['datum.spacing_mm']:g} mm spacing or of its {qmin:.4g} mm shortest distance "
        f"from a station (at most {top:.4g} um): the nominal coverage is a small-error "
        "statement, and ranges this noisy leave its adjustment without converged trials to "
        "compute it from",
    )
