"""Configuration schema and cross-key checks of the two Brown studies (seed 004).

Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

import math

import numpy as np

from sim.instruments.plates import pattern_points
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import multilateration as ml
from sim.mc.chunk_count import MIN_CHUNKS, require_chunks
from sim.mc.config import COMMON, ConfigError, Field
from sim.mc.read_when import when
from sim.mc.schema_helpers import compared, count, counts, positive, printed, real, region_seed
from sim.studies.brown.pivot_geometry import check_pivot, points_of, setup, within_beta
from sim.studies.brown.probe import check_noise, check_solver, check_start
from sim.studies.brown.range_keys import check_scale, moved_from_paper

SEED = "004_f5bd9e86c308241f.txt"
MODEL_NAMES = ("known", "stations", "pivot")
#: smallest sigma of one range (1 pm, 1e-6 of the paper's): the results are ratios to it
MIN_RANGE_SIGMA_UM = 1e-6

# ----------------------------------------------------------------------------- configuration


def _grid(f: Field) -> Field:
    """A key of the grid pattern: read only when ``plate.pattern = "grid"``."""
    return when(f, "plate.pattern", "grid")


def _random(f: Field) -> Field:
    """A key of the random pattern: read only when ``plate.pattern = "random"``."""
    return when(f, "plate.pattern", "random")


BASE = {
    **COMMON,
    "chunk": count(
        200,
        f"trials per chunk (the jackknife intervals are over chunks: >= {MIN_CHUNKS} chunks)",
        lo=1,
        hi=1_000_000,
    ),
    # printed(...): the paper's own number (seed 004: "245 X 245 mm", "graduated ... over a
    # length of 261 mm", the micrometer's "at most one millimeter"); another value is another
    # instrument, and the run is off the paper's setup (sim.claims.rules.printed_differs)
    # the bounds: brown_design's of the same instrument (m50: a 1 m micrometer passed)
    "plate.format_mm": printed(
        real(245.0, "side of the square plate format (paper: 245 mm)", lo=1.0, hi=2000.0, unit="mm")
    ),
    "plate.pattern": Field("grid", "str", "point pattern", choices=("grid", "random", "list")),
    "plate.grid": _grid(count(5, "points per side of the grid pattern", lo=2, hi=200)),
    "plate.spacing_mm": _grid(
        positive(
            45.0,
            "grid spacing (Table 1: 45 mm; the Concept section prints no layout, its extent is "
            "swept)",
            unit="mm",
        )
    ),
    "plate.n_random": _random(count(25, "number of points of the random pattern", lo=3, hi=100000)),
    "plate.random_half_extent_mm": _random(
        positive(100.0, "random points lie in |x|,|y| <= this", unit="mm")
    ),
    "plate.layout_seed": _random(
        count(
            1,
            "seed of the random pattern's points, apart from seed: --seed, replicates and a "
            "sweep's cells draw new noise on one plate (sweep this key to compare plates)",
            lo=0,
            hi=2**63 - 1,
        )
    ),
    "plate.points": when(
        Field([], "points", "explicit point list [[x, y], ...] for pattern 'list'"),
        "plate.pattern",
        "list",
    ),
    "comparator.station_offset_mm": positive(
        17.0,
        "distance of the stations outside the midsides of the format; the paper "
        "says only 'a short distance' (nominal value: the middle of the 0-34 mm that fit the "
        "261 mm scale for a +-90 mm grid; a labelled example: the claims are decided over "
        "the region of sim.instruments.ranges.brown)",
        unit="mm",
    ),
    "comparator.alpha_mm": real(
        0.5, "radial pivot offset alpha (true value)", lo=-50.0, hi=50.0, unit="mm"
    ),
    "comparator.beta_mm": real(
        1.0,
        "tangential pivot offset beta (true value; at most half the 29 mm scale's width: "
        "checked on load)",
        lo=0.0,
        unit="mm",
    ),
    "comparator.scale_length_mm": printed(
        real(
            261.0,
            "graduated length of the scale (paper: 261 mm); every range must fit on "
            "it plus the micrometer travel. 0 = not enforced (an idealised comparator)",
            lo=0.0,
            hi=5000.0,
            unit="mm",
        )
    ),
    "comparator.micrometer_mm": printed(
        real(
            1.0,
            "micrometer travel added to the scale (paper: at most 1 mm)",
            lo=0.0,
            hi=100.0,
            unit="mm",
        )
    ),
    "errors.setting_sigma_um": positive(
        1.0, "standard deviation of one setting", hi=1e4, unit="um"
    ),
    "errors.settings": count(1, "settings per point and position, averaged", lo=1, hi=100),
    "errors.comparator_sigma_um": real(
        0.0, "comparator random error per reading", lo=0.0, hi=1e4, unit="um"
    ),
    "errors.bias_um": real(
        0.0, "constant personal bias added to every range", lo=-1e4, hi=1e4, unit="um"
    ),
    "solver.tol_mm": real(
        1e-10,
        "convergence: largest correction below this (at least 1e-15 mm: a smaller one is "
        "never met in double precision and every trial failed)",
        lo=1e-15,
        hi=1e-3,
        unit="mm",
    ),
    "solver.max_iter": count(30, "Gauss-Newton iteration limit", lo=1, hi=1000),
    "region.points": count(
        1024,
        "size of the space-filling (Sobol) design of the joint exploration of the unprinted "
        "inputs (sim.claims.inference), rounded up to a power of 2",
        lo=256,
        hi=16384,
    ),
    "region.rounds": count(
        3, "refinement rounds at the region's boundaries (each halves the spacing)", lo=0, hi=8
    ),
}

DILUTION = {
    **BASE,
    "region.seed": region_seed(1968),
    "trials": count(4000, "Monte-Carlo trials", lo=2, hi=100_000_000),
    "dilution.grids": compared(
        counts(
            [3, 4, 5, 7, 10, 14, 20],
            "grid sizes (points per side, same extent) for dilution vs point count",
            lo=2,
            hi=200,
            min_len=2,
        )
    ),
    "idealised.half_extent_mm": positive(
        110.0,
        "half extent of the idealised four-station "
        "layout (no scale): the offset giving 0.85 at the edges",
        unit="mm",
    ),
    "checks.bias_shift_um": real(
        100.0,
        "constant added to all ranges in the bias invariance check, of either sign (at least "
        "1 um in size, a million times its claims' zone of 1e-9 mm: at 0 it compared an "
        "adjustment with itself)",
        lo=-1e5,
        hi=1e5,
        unit="um",
    ),
}

#: Table 1's plate and settings as printed (seed 004, Results: "a 5 X 5 array of PUG points
#: evenly spaced at 45 mm", "double settings", "an individual setting ... 1.7 microns", the
#: comparator's "1.1 microns"): a run with another plate (another grid, spacing or pattern,
#: 25 random points included) or other settings is off the paper's setup (printed)
TABLE1 = {
    **BASE,
    "region.seed": region_seed(1967),
    "trials": count(4000, "Monte-Carlo trials", lo=2, hi=100_000_000),
    "plate.pattern": printed(BASE["plate.pattern"]),
    "plate.grid": printed(BASE["plate.grid"]),
    "plate.spacing_mm": printed(
        _grid(positive(45.0, "grid spacing (paper: 45 mm)", unit="mm", input=True))
    ),
    "errors.setting_sigma_um": printed(
        positive(1.7, "one setting (paper: 1.7 um)", hi=1e4, unit="um", input=True)
    ),
    "errors.settings": printed(count(2, "double settings (paper)", lo=1, hi=100, input=True)),
    "errors.comparator_sigma_um": printed(
        real(
            1.1,
            "comparator contribution (paper: about 1.1 um)",
            lo=0.0,
            hi=1e4,
            unit="um",
            input=True,
        )
    ),
}


#: how far (mm, in x and in y) a listed point may lie from a point of Table 1's plate and
#: still be it: a nanometre, far below the paper's whole-millimetre coordinates and its
#: micron-level sigmas, so only the floating-point spelling of the same point passes
PAPER_PLATE_TOL_MM = 1e-6


def as_printed(cfg: dict) -> dict:
    """``cfg`` with a ``plate.pattern = "list"`` of exactly Table 1's 25 points (in any order,
    each within :data:`PAPER_PLATE_TOL_MM`) spelled as the paper's grid (pattern, grid and
    spacing of :data:`TABLE1`): the points the run uses, not the key's spelling, decide
    whether its plate is the paper's (:func:`sim.claims.rules.printed_differs`). Any other
    config comes back as it is."""
    if cfg.get("plate.pattern") != "list":
        return cfg
    paper = {k: TABLE1[k].default for k in ("plate.pattern", "plate.grid", "plate.spacing_mm")}
    ref = pattern_points("grid", grid=paper["plate.grid"], spacing_mm=paper["plate.spacing_mm"])
    pts = np.asarray(cfg.get("plate.points") or [], float).reshape(-1, 2)
    if pts.shape != ref.shape:
        return cfg
    near = np.abs(pts[:, None, :] - ref[None, :, :]).max(axis=2) <= PAPER_PLATE_TOL_MM
    if (near.sum(axis=0) == 1).all() and (near.sum(axis=1) == 1).all():  # one to one
        return {**cfg, **paper}
    return cfg


def range_sigma_um(cfg: dict) -> float:
    """sigma of one (averaged) range: sqrt(setting^2 / settings + comparator^2), um."""
    return float(
        np.sqrt(
            cfg["errors.setting_sigma_um"] ** 2 / cfg["errors.settings"]
            + cfg["errors.comparator_sigma_um"] ** 2
        )
    )


def max_offset_mm(cfg: dict, half_extent_mm: float) -> float:
    """Largest station offset at which every range of a grid reaching +-half_extent_mm fits
    the scale plus the micrometer (inf when the scale is not enforced). The farthest point
    from station 1 (0, h) is (+-e, -e): r = sqrt(e^2 + (h + e)^2 - beta^2) - alpha."""
    if cfg["comparator.scale_length_mm"] <= 0:
        return float("inf")
    reach = (
        cfg["comparator.scale_length_mm"]
        + cfg["comparator.micrometer_mm"]
        + cfg["comparator.alpha_mm"]
    )
    e = half_extent_mm
    d2 = reach**2 + cfg["comparator.beta_mm"] ** 2 - e**2
    return float(np.sqrt(d2) - e - cfg["plate.format_mm"] / 2) if d2 > 0 else -float("inf")


def check_extents(cfg: dict) -> None:
    """The idealised layout lies inside the format."""
    half = cfg["plate.format_mm"] / 2
    v = cfg.get("idealised.half_extent_mm")
    if v is not None and v > half:
        raise ConfigError(
            "idealised.half_extent_mm", f"half extents must lie inside the format (<= {half:g} mm)"
        )


#: smallest size of the bias invariance check's constant (um, either sign): a million times
#: its claims' zone of 1e-9 mm
MIN_BIAS_SHIFT_UM = 1.0


def check_shift(cfg: dict, r: np.ndarray) -> None:
    """The bias check's constant is at least :data:`MIN_BIAS_SHIFT_UM` in size: a negative
    additive constant (ranges read short) is as valid as a positive one (it was refused as
    "must be >= 1"), but one of 0 compared an adjustment with itself; a negative one keeps
    the shortest of the true ranges ``r`` (mm), with ``errors.bias_um``, at or above 0 (no
    comparator reads a negative range: at -100 mm no shifted adjustment converged, and the
    claims held "over 0 Monte-Carlo plates")."""
    v = cfg.get("checks.bias_shift_um")
    if v is None:
        return
    if abs(v) < MIN_BIAS_SHIFT_UM:
        raise ConfigError(
            "checks.bias_shift_um",
            f"must be >= {MIN_BIAS_SHIFT_UM:g} or <= -{MIN_BIAS_SHIFT_UM:g} um (got {v:g}): a "
            "smaller constant moves the pivot adjustment by less than its claims' zone of "
            "1e-9 mm, and 0 compares it with itself",
        )
    low = r.min() + (cfg["errors.bias_um"] + v) * 1e-3
    if low < 0:
        raise ConfigError(
            "checks.bias_shift_um",
            f"{v:g} um reads the shortest range, {r.min():.1f} mm (plus errors.bias_um = "
            f"{cfg['errors.bias_um']:g} um), as {low:.1f} mm: a comparator reads no negative "
            f"range (give a constant no lower than "
            f"{math.ceil(-(r.min() * 1e3 + cfg['errors.bias_um'])):d} um)",
        )


def check(cfg: dict) -> None:
    """Cross-key rules: a range sigma the model can divide by, beta under the scale, points
    inside the format, enough points, no duplicates/collinearity, every range on the scale, and
    the chunks the Monte-Carlo agreement rows' jackknife intervals need (at least
    :data:`sim.mc.runner.MIN_CHUNKS`: :func:`sim.studies.brown.core.MC.jack`)."""
    if range_sigma_um(cfg) < MIN_RANGE_SIGMA_UM:
        # (tenth sweep) errors.setting_sigma_um = 5e-324 without a comparator error passed
        # check; the run's ratios to the range sigma were NaN, its claims not finite
        raise ConfigError(
            "errors.setting_sigma_um",
            f"the range sigma sqrt(setting^2 / settings + comparator^2) is "
            f"{range_sigma_um(cfg):g} um, below {MIN_RANGE_SIGMA_UM:g} um (the results are "
            "ratios to it): give a larger setting or comparator sigma",
        )
    check_extents(cfg)
    if cfg["comparator.beta_mm"] > B.SCALE_WIDTH_MM / 2:  # (P41) 30 mm ran as Brown's comparator;
        raise ConfigError(  # at 50 mm no pivot adjustment converged, refused after the run
            "comparator.beta_mm",
            f"beta = {cfg['comparator.beta_mm']:g} mm is more than half the "
            f"{B.SCALE_WIDTH_MM:g} mm width of the scale ({B.SCALE_WIDTH_MM / 2:g} mm): the "
            "pivot ball lies under the scale",
        )
    key = {"grid": "plate.grid", "random": "plate.n_random", "list": "plate.points"}[
        cfg["plate.pattern"]
    ]
    half = cfg["plate.format_mm"] / 2
    if cfg["plate.pattern"] == "grid":
        ext = (cfg["plate.grid"] - 1) / 2 * cfg["plate.spacing_mm"]
        if ext > half:
            raise ConfigError(
                "plate.spacing_mm",
                f"grid of {cfg['plate.grid']} at "
                f"{cfg['plate.spacing_mm']:g} mm reaches {ext:g} mm from the centre, "
                f"outside the {cfg['plate.format_mm']:g} mm format",
            )
    if cfg["plate.pattern"] == "random" and cfg["plate.random_half_extent_mm"] > half:
        raise ConfigError(
            "plate.random_half_extent_mm", "random points would lie outside the format"
        )
    pts = points_of(cfg)
    n = len(pts)
    if n < 3:
        raise ConfigError(key, f"needs at least 3 points (got {n})")
    if n < 4:
        raise ConfigError(
            key,
            f"{n} points give {4 * n} ranges for {2 * n + 7} unknowns of the "
            "pivot model: at least 4 points are needed",
        )
    if np.any(np.abs(pts) > half):
        raise ConfigError(key, f"points outside the {cfg['plate.format_mm']:g} mm format")
    if len(np.unique(np.round(pts, 9), axis=0)) < n:
        if cfg["plate.pattern"] == "grid":  # only a spacing below 1e-9 mm makes them (it was
            raise ConfigError(  # "plate.grid: duplicate points", the key not changed)
                "plate.spacing_mm",
                f"{cfg['plate.spacing_mm']:g} mm puts points of the grid within 1e-09 mm of "
                "each other: duplicate points",
            )
        raise ConfigError(key, "duplicate points")
    c = pts - pts.mean(0)
    sv = np.linalg.svd(c, compute_uv=False)
    if sv[-1] <= 1e-9 * max(sv[0], 1e-300):
        raise ConfigError(
            key, "all points are collinear: the station coordinates cannot be recovered"
        )
    within_beta(cfg, key, pts)
    _, theta = setup(cfg)
    with np.errstate(over="ignore", invalid="ignore"):  # named below, not warned
        r = ml.ranges(pts[None], theta[None])
    if not np.all(np.isfinite(r)):  # the stations so far out that a range overflows (also
        # with no scale length enforced: passed sim check, then every trial failed)
        half, off = cfg["plate.format_mm"] / 2, cfg["comparator.station_offset_mm"]
        raise ConfigError(  # the key of the larger part of the stations' distance
            "plate.format_mm" if half >= off else "comparator.station_offset_mm",
            f"stations {half + off:g} mm from the centre (half the {2 * half:g} mm format "
            f"plus the {off:g} mm offset) are so far out that the ranges overflow",
        )
    check_scale(cfg, key, r, {k: f.default for k, f in BASE.items()})
    check_shift(cfg, r)
    check_pivot(cfg, key, pts, {k: f.default for k, f in BASE.items()})
    base = {k: f.default for k, f in BASE.items()}
    check_start(cfg, key, setup, MODEL_NAMES, moved_from_paper(cfg, key, base), base)
    check_solver(cfg, pts, setup(cfg)[1], MODEL_NAMES, BASE["solver.max_iter"].default)
    check_noise(cfg, key, pts, setup(cfg)[1], MODEL_NAMES, moved_from_paper(cfg, key, base), base)
    require_chunks(cfg)
