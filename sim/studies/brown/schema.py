"""Configuration schema and cross-key checks of the two Brown studies (seed 004).

Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import pattern_points
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import multilateration as ml
from sim.instruments.ranges import positions as po
from sim.lsq.normals import RCOND, reduced_normals, scaled_rcond
from sim.mc.chunk_count import MIN_CHUNKS, require_chunks
from sim.mc.config import COMMON, ConfigError, Field
from sim.mc.read_when import when
from sim.mc.schema_helpers import compared, count, counts, positive, printed, real, region_seed
from sim.mc.streams import chunk_rng
from sim.studies.brown.probe import check_noise, check_solver, check_start
from sim.studies.brown.range_keys import check_scale, moved_from_paper
from sim.studies.brown.values import thetas

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
        "constant added to all ranges in the bias invariance check (at least 1 um, a million "
        "times its claims' zone of 1e-9 mm: at 0 it compared an adjustment with itself)",
        lo=1.0,
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
    _within_beta(cfg, key, pts)
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
    check_pivot(cfg, key, pts)
    base = {k: f.default for k, f in BASE.items()}
    check_start(cfg, key, setup, MODEL_NAMES, moved_from_paper(cfg, key, base), base)
    check_solver(cfg, pts, setup(cfg)[1], MODEL_NAMES, BASE["solver.max_iter"].default)
    check_noise(cfg, key, pts, setup(cfg)[1], MODEL_NAMES, moved_from_paper(cfg, key, base), base)
    require_chunks(cfg)


def _within_beta(cfg: dict, key: str, pts: np.ndarray) -> None:
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


def check_pivot(cfg: dict, key: str, pts: np.ndarray) -> None:
    """Every geometry the run adjusts with the pivot model can be solved by the engine's one
    rule (a 2 x 2 grid cannot: its symmetry leaves the reduced normals singular, and every
    trial failed at run time): the plate's points, and the grids of ``dilution.grids`` over
    the plate's extent."""
    _, theta = setup(cfg)
    if not np.all(np.isfinite(ml.ranges(pts[None], theta[None]))):
        return  # an overflow is named by the range check before this one
    rc = pivot_rcond(pts, theta)
    if not rc > RCOND:
        moved = moved_from_paper(cfg, key, {k: f.default for k, f in BASE.items()})
        blame = key  # the comparator's keys when the points are solved from the paper's
        # stations (stations 1e9 mm out blamed the plate's grid)
        if comp := [k for k in moved if k.startswith("comparator.")]:
            paper = {**cfg, **{k: BASE[k].default for k in comp}}
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


def setup(cfg: dict):
    pts = points_of(cfg)
    h = cfg["plate.format_mm"] / 2 + cfg["comparator.station_offset_mm"]
    theta = ml.design_theta(h, cfg["comparator.alpha_mm"], cfg["comparator.beta_mm"])
    return pts, theta
