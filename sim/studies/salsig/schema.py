"""Configuration of ``salsig_encoders`` (seed ``002_fb81c7b0481438c4.txt``).

Keys marked *input* carry a number the paper prints. The magnitudes the paper does not print
(B8 marking error, comparator error, control relief, vertical error, number of control
points, the glass-scale span and setting error, the grid spacing) are examples: the B8 and
comparator errors are set to reproduce the printed unit-weight errors (inputs), and the
vertical test's are explored in the consistent region (:mod:`sim.studies.salsig.region`).
"""

from __future__ import annotations

import math

from sim.mc.config import COMMON
from sim.mc.schema_helpers import (
    compared,
    count,
    counts,
    level,
    positive,
    printed,
    real,
    reals,
    region_seed,
    require,
)

UM = 1e-3

SCHEMA = {
    **COMMON,
    "trials": count(4000, "Monte-Carlo trials of the calibration chain", lo=2, hi=10_000_000),
    "chunk": count(1000, "trials per chunk", lo=1, hi=1_000_000),
    "b8.sx_mm_per_digit": positive(
        12.700082809, "true x scale SX of the B8 (FIG. 3)", unit="mm/digit", input=True
    ),
    "b8.sy_mm_per_digit": positive(
        12.702028129, "true y scale SY of the B8 (FIG. 3)", unit="mm/digit", input=True
    ),
    "b8.e_arcsec": real(
        -59.2,
        "true non-perpendicularity E of the B8 (FIG. 3)",
        lo=-3600.0,
        hi=3600.0,
        unit="arcsec",
        input=True,
    ),
    "b8.sigma_um": positive(
        25.0,
        "B8 marking error per coordinate (model space); not printed, set to reproduce "
        "FIG. 3's unit-weight error .002 digit (an input)",
        hi=1000.0,
        unit="um",
    ),
    "marks.grid": count(5, "marks per side (k x k array)", lo=2, hi=20),
    "marks.extent_mm": real(
        200.0, "side of the mark array (5 x 5 at 50 mm: 200)", lo=10.0, hi=600.0, unit="mm"
    ),
    "marks.placement_sd_mm": real(
        2.0, "scatter of the inked circles about the nominal array", lo=0.0, hi=20.0, unit="mm"
    ),
    "comparator.sigma_um": positive(
        3.0,
        "comparator error per coordinate for grid "
        "intersections and film marks; not printed, set to reproduce FIG. 2's "
        "unit-weight error .003 mm (an input)",
        hi=100.0,
        unit="um",
    ),
    "comparator.sx": positive(0.999993007, "comparator -> grid scale SX (FIG. 2)", input=True),
    "comparator.sy": positive(0.999978669, "comparator -> grid scale SY (FIG. 2)", input=True),
    "comparator.e_arcsec": real(
        -14.0,
        "comparator -> grid non-perpendicularity (FIG. 2)",
        lo=-3600.0,
        hi=3600.0,
        unit="arcsec",
        input=True,
    ),
    "grid.points": count(5, "grid intersections per side measured on the comparator", lo=2, hi=20),
    "grid.spacing_mm": real(50.0, "grid spacing (not printed)", lo=1.0, hi=100.0, unit="mm"),
    "analysis.alpha": level(0.05, "level of the detection tests"),
    "power.marks": compared(
        counts([3, 4, 5, 6, 7], "marks per side swept (same extent)", lo=2, hi=20)
    ),
    "power.sigma_um": compared(
        reals(
            [2.0, 5.0, 10.0, 25.0, 50.0],
            "B8 marking sigmas swept (um)",
            lo=0.0,
            lo_open=True,
            unit="um",
        )
    ),
    "power.trials": count(1000, "trials per sweep cell", lo=2, hi=1_000_000),
    "zscale.s_mm_per_digit": positive(
        12.5, "true z scale (paper's result 12.500)", 1000.0, unit="mm/digit", input=True
    ),
    "zscale.points": count(9, "elevations read on the glass scale", lo=3, hi=100),
    "zscale.range_mm": real(
        160.0, "span of the elevations (not printed)", lo=1.0, hi=1000.0, unit="mm"
    ),
    "zscale.sigma_um": positive(
        20.0, "setting error on a glass-scale graduation (not printed)", hi=1000.0, unit="um"
    ),
    "vertical.control": count(6, "control points per stereomodel", lo=3, hi=100),
    "vertical.extent_mm": real(
        180.0, "side of the model area holding the control", lo=10.0, hi=600.0, unit="mm"
    ),
    "vertical.relief_mm": real(
        4.0,
        "rms of control heights about their plane (model mm); not printed (region.toml)",
        lo=0.0,
        hi=100.0,
        unit="mm",
    ),
    "vertical.sigma_xy_um": real(
        15.0,
        "model x, y error of a control point (measurement and control)",
        lo=0.0,
        hi=1000.0,
        unit="um",
    ),
    "vertical.sigma_z_um": positive(
        40.0,
        "model z error of a control point (measurement and control); not printed (region.toml)",
        hi=1000.0,
        unit="um",
    ),
    "region.points": count(
        128, "input vectors of the space-filling design (region.toml)", lo=4, hi=65536
    ),
    "region.trials": count(
        200, "simulated models per input vector of the region", lo=20, hi=1_000_000
    ),
    "region.seed": region_seed(20261122),
}

#: the keys whose default is a number the paper prints for its own setup (seed 002: the B8's
#: scales and non-perpendicularity of FIG. 3, the comparator's of FIG. 2, the z scale's
#: 12.500, "25 small circles ... at approximately 50-millimetre intervals in a 5 by 5
#: array"): a run with another value is off the paper's setup, its predictions findings
#: (sim.claims.rules.printed_differs). Not marked: the error sigmas set to reproduce the
#: printed unit-weight errors (Monte-Carlo inputs), the unprinted inputs the region explores
#: (region.toml), the grid intersections and the glass scale's readings (not printed), the
#: sweeps
PRINTED = (
    "b8.sx_mm_per_digit",
    "b8.sy_mm_per_digit",
    "b8.e_arcsec",
    "marks.grid",
    "marks.extent_mm",
    "comparator.sx",
    "comparator.sy",
    "comparator.e_arcsec",
    "zscale.s_mm_per_digit",
)
SCHEMA.update({k: printed(SCHEMA[k]) for k in PRINTED})


#: the most the comparator-to-grid affine (FIG. 2) may add to the recovered SX, SY and E, as a
#: share of the standard deviations FIG. 3's fit states (which leave it out): at 1 the true
#: spread is sqrt(2) times theirs and a stated 95 % interval covers about 83 % (the paper's
#: 5 x 5 grid under its 5 x 5 marks: 0.12; its errors with the power sweep's 2 um: 0.83)
TRANSFER_SHARE = 1.0
#: the keys of that share, the one named first whose default brings it within the limit
TRANSFER_KEYS = (
    "grid.spacing_mm",
    "grid.points",
    "comparator.sigma_um",
    "b8.sigma_um",
    "marks.extent_mm",
    "marks.grid",
)


def _moment(k: int, spacing: float) -> float:
    """Sum of squared offsets (mm^2) from the centre along one axis of a ``k x k`` array."""
    return k * k * (k * k - 1) / 12 * spacing**2


def transfer_share(cfg: dict) -> float:
    """The error the FIG. 2 affine, fitted on the grid, carries into the marks' scale and
    shear terms (``comparator.sigma_um`` over the grid's moment), as a share of the standard
    deviation FIG. 3's fit states for them (the marks' error, B8 and comparator, over the mark
    array's moment). The FIG. 2 transformation is systematic for all marks of a film, so
    this share does not average out; FIG. 3's covariance leaves it out. The marks' error is
    ``hypot(sb, sc)``: ``sqrt(sb**2 + sc**2)`` was 0 for sigmas of 1e-200 um (within their
    bounds, their squares underflow), a ZeroDivisionError at ``sim check`` naming no key."""
    sc, sb = cfg["comparator.sigma_um"], cfg["b8.sigma_um"]
    km, ext = cfg["marks.grid"], cfg["marks.extent_mm"]
    grid = _moment(cfg["grid.points"], cfg["grid.spacing_mm"])
    marks = _moment(km, ext / (km - 1))
    return math.sqrt(marks / grid) * (sc / math.hypot(sb, sc))


def _check_transfer(cfg: dict) -> None:
    """The grid determines the FIG. 2 affine well enough for the marks: a 2 x 2 grid at 1 mm
    under the 200 mm mark array (each key within its bounds) ran, recovered E with a spread
    of 850 arcsec where FIG. 3 stated 20, and reported E "detected" in 97 % of the trials
    (power) on the transformation's error alone (P48)."""
    share = transfer_share(cfg)
    if share <= TRANSFER_SHARE:
        return
    moved = [k for k in TRANSFER_KEYS if cfg[k] != SCHEMA[k].default]
    fixes = [k for k in moved if transfer_share({**cfg, k: SCHEMA[k].default}) <= TRANSFER_SHARE]
    k = cfg["grid.points"]
    require(
        False,
        (fixes or moved or TRANSFER_KEYS)[0],
        f"the comparator-to-grid affine (FIG. 2), fitted on a {k} x {k} grid at "
        f"{cfg['grid.spacing_mm']:g} mm and applied to the {cfg['marks.extent_mm']:g} mm mark "
        f"array, adds an error to the recovered SX, SY and E of {share:.2g} times the "
        "standard deviations FIG. 3's fit states (which leave it out; at most "
        f"{TRANSFER_SHARE:g}): their intervals and detection tests would be decided on the "
        "transformation's error; measure a wider or denser grid (grid.points, "
        "grid.spacing_mm) or use a smaller comparator.sigma_um",
    )


def check(cfg: dict) -> None:
    """Bounds that follow from what the model can compute; one line naming the key."""
    require(
        cfg["marks.grid"] ** 2 >= 4,
        "marks.grid",
        "needs at least 4 marks for an affine with redundancy",
    )
    require(cfg["grid.points"] ** 2 >= 4, "grid.points", "needs at least 4 intersections")
    require(cfg["zscale.points"] >= 3, "zscale.points", "needs at least 3 elevations")
    spacing = cfg["marks.extent_mm"] / (cfg["marks.grid"] - 1)
    require(
        cfg["marks.placement_sd_mm"] <= spacing / 4,
        "marks.placement_sd_mm",
        f"{cfg['marks.placement_sd_mm']:g} mm is more than a quarter of the mark spacing "
        f"{spacing:g} mm: marks would coincide and the affine would be singular",
    )
    # the detection-power sweep lays its arrays over the same extent with the same scatter: a
    # 20 x 20 array at 10.5 mm with marks.placement_sd_mm = 12 ran as an "array" (P44)
    k, sd, ext = max(cfg["power.marks"]), cfg["marks.placement_sd_mm"], cfg["marks.extent_mm"]
    require(
        sd <= ext / (k - 1) / 4,
        "power.marks",
        f"its {k} x {k} array over marks.extent_mm {ext:g} mm has its marks "
        f"{ext / (k - 1):g} mm apart, less than four times marks.placement_sd_mm {sd:g} mm: "
        f"its marks would coincide (compare at most {int(ext / (4 * sd)) + 1 if sd else k} "
        "marks per side)",
    )
    require(
        cfg["b8.sigma_um"] * UM <= 0.01 * cfg["marks.extent_mm"],
        "b8.sigma_um",
        "exceeds 1 % of the mark array: the affine's geometry is meaningless",
    )
    require(  # 1e300 ran and filled the power table with NaN after a page of NumPy warnings
        max(cfg["power.sigma_um"]) * UM <= 0.01 * cfg["marks.extent_mm"],
        "power.sigma_um",
        "exceeds 1 % of the mark array: the affine's geometry is meaningless",
    )
    require(
        cfg["comparator.sigma_um"] * UM <= 0.01 * cfg["grid.spacing_mm"] * (cfg["grid.points"] - 1),
        "comparator.sigma_um",
        "exceeds 1 % of the grid extent",
    )
    require(
        cfg["zscale.sigma_um"] * UM <= 0.1 * cfg["zscale.range_mm"],
        "zscale.sigma_um",
        "exceeds 10 % of zscale.range_mm: the line fit cannot find a scale",
    )
    sxy, sz = cfg["vertical.sigma_xy_um"], cfg["vertical.sigma_z_um"]
    require(  # named by the larger error (vertical.sigma_xy_um = 1000 named sigma_z: P44)
        max(sxy, sz) * UM <= 0.01 * cfg["vertical.extent_mm"],
        "vertical.sigma_xy_um" if sxy > sz else "vertical.sigma_z_um",
        "the control error exceeds 1 % of the model area: the conformal fit is meaningless",
    )
    for key in ("b8.sx_mm_per_digit", "b8.sy_mm_per_digit"):
        require(
            0.5 < cfg[key] / cfg["zscale.s_mm_per_digit"] < 2.0,
            key,
            "differs from the z scale by more than a factor 2 (the digitiser model assumes "
            "nearly equal scales)",
        )
    for key in ("comparator.sx", "comparator.sy"):
        require(  # 1e308 ran, overflowed the grid coordinates and recovered nonsense
            0.5 < cfg[key] < 2.0,
            key,
            f"must lie between 0.5 and 2 (got {cfg[key]:g}): a scale between comparator and "
            "grid lengths, near 1",
        )
    _check_transfer(cfg)
    require(
        cfg["power.trials"] >= 2 and max(cfg["power.marks"]) ** 2 * cfg["power.trials"] <= 5e7,
        "power.trials",
        "the detection-power sweep asks for more than 5e7 simulated marks per cell",
    )
