"""Configuration of ``salsig_encoders`` (seed ``002_fb81c7b0481438c4.txt``).

Keys marked *input* carry a number the paper prints. The magnitudes the paper does not print
(B8 marking error, comparator error, control relief, vertical error, number of control
points, the glass-scale span and setting error, the grid spacing) are examples: the B8 and
comparator errors are set to reproduce the printed unit-weight errors (inputs), and the
vertical test's are explored in the consistent region (:mod:`sim.studies.salsig.region`).
"""

from __future__ import annotations

from sim.mc.config import COMMON, ConfigError, Field

UM = 1e-3

SCHEMA = {
    **COMMON,
    "trials": Field(
        4000, "int", "Monte-Carlo trials of the calibration chain", lo=2, hi=10_000_000
    ),
    "chunk": Field(1000, "int", "trials per chunk", lo=1, hi=1_000_000),
    "b8.sx_mm_per_digit": Field(
        12.700082809,
        "float",
        "true x scale SX of the B8 (FIG. 3)",
        lo=0.0,
        lo_open=True,
        input=True,
        unit="mm/digit",
    ),
    "b8.sy_mm_per_digit": Field(
        12.702028129,
        "float",
        "true y scale SY of the B8 (FIG. 3)",
        lo=0.0,
        lo_open=True,
        input=True,
        unit="mm/digit",
    ),
    "b8.e_arcsec": Field(
        -59.2,
        "float",
        "true non-perpendicularity E of the B8 (FIG. 3)",
        lo=-3600.0,
        hi=3600.0,
        input=True,
        unit="arcsec",
    ),
    "b8.sigma_um": Field(
        25.0,
        "float",
        "B8 marking error per coordinate (model space); not printed, set to reproduce "
        "FIG. 3's unit-weight error .002 digit (an input)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        unit="um",
    ),
    "marks.grid": Field(5, "int", "marks per side (k x k array)", lo=2, hi=20),
    "marks.extent_mm": Field(
        200.0, "float", "side of the mark array (5 x 5 at 50 mm: 200)", lo=10.0, hi=600.0, unit="mm"
    ),
    "marks.placement_sd_mm": Field(
        2.0,
        "float",
        "scatter of the inked circles about the nominal array",
        lo=0.0,
        hi=20.0,
        unit="mm",
    ),
    "comparator.sigma_um": Field(
        3.0,
        "float",
        "comparator error per coordinate for grid "
        "intersections and film marks; not printed, set to reproduce FIG. 2's "
        "unit-weight error .003 mm (an input)",
        lo=0.0,
        lo_open=True,
        hi=100.0,
        unit="um",
    ),
    "comparator.sx": Field(
        0.999993007,
        "float",
        "comparator -> grid scale SX (FIG. 2)",
        lo=0.0,
        lo_open=True,
        input=True,
    ),
    "comparator.sy": Field(
        0.999978669,
        "float",
        "comparator -> grid scale SY (FIG. 2)",
        lo=0.0,
        lo_open=True,
        input=True,
    ),
    "comparator.e_arcsec": Field(
        -14.0,
        "float",
        "comparator -> grid non-perpendicularity (FIG. 2)",
        lo=-3600.0,
        hi=3600.0,
        input=True,
        unit="arcsec",
    ),
    "grid.points": Field(
        5, "int", "grid intersections per side measured on the comparator", lo=2, hi=20
    ),
    "grid.spacing_mm": Field(
        50.0, "float", "grid spacing (not printed)", lo=1.0, hi=100.0, unit="mm"
    ),
    "analysis.alpha": Field(
        0.05, "float", "level of the detection tests", lo=0.0, lo_open=True, hi=0.5
    ),
    "power.marks": Field(
        [3, 4, 5, 6, 7], "list[int]", "marks per side swept (same extent)", lo=2, hi=20, min_len=1
    ),
    "power.sigma_um": Field(
        [2.0, 5.0, 10.0, 25.0, 50.0],
        "list[float]",
        "B8 marking sigmas swept (um)",
        lo=0.0,
        lo_open=True,
        min_len=1,
        unit="um",
    ),
    "power.trials": Field(1000, "int", "trials per sweep cell", lo=2, hi=1_000_000),
    "zscale.s_mm_per_digit": Field(
        12.5,
        "float",
        "true z scale (paper's result 12.500)",
        lo=0.0,
        lo_open=True,
        input=True,
        unit="mm/digit",
    ),
    "zscale.points": Field(9, "int", "elevations read on the glass scale", lo=3, hi=100),
    "zscale.range_mm": Field(
        160.0, "float", "span of the elevations (not printed)", lo=1.0, hi=1000.0, unit="mm"
    ),
    "zscale.sigma_um": Field(
        20.0,
        "float",
        "setting error on a glass-scale graduation (not printed)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        unit="um",
    ),
    "vertical.control": Field(6, "int", "control points per stereomodel", lo=3, hi=100),
    "vertical.extent_mm": Field(
        180.0, "float", "side of the model area holding the control", lo=10.0, hi=600.0, unit="mm"
    ),
    "vertical.relief_mm": Field(
        4.0,
        "float",
        "rms of control heights about their plane (model mm); not printed (region.toml)",
        lo=0.0,
        hi=100.0,
        unit="mm",
    ),
    "vertical.sigma_xy_um": Field(
        15.0,
        "float",
        "model x, y error of a control point (measurement and control)",
        lo=0.0,
        hi=1000.0,
        unit="um",
    ),
    "vertical.sigma_z_um": Field(
        40.0,
        "float",
        "model z error of a control point (measurement and control); not printed (region.toml)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        unit="um",
    ),
    "region.points": Field(
        128, "int", "input vectors of the space-filling design (region.toml)", lo=4, hi=65536
    ),
    "region.trials": Field(
        200, "int", "simulated models per input vector of the region", lo=20, hi=1_000_000
    ),
}


def check(cfg: dict) -> None:
    """Bounds that follow from what the model can compute; one line naming the key."""
    if cfg["marks.grid"] ** 2 < 4:
        raise ConfigError("marks.grid", "needs at least 4 marks for an affine with redundancy")
    if cfg["grid.points"] ** 2 < 4:
        raise ConfigError("grid.points", "needs at least 4 intersections")
    if cfg["zscale.points"] < 3:
        raise ConfigError("zscale.points", "needs at least 3 elevations")
    spacing = cfg["marks.extent_mm"] / (cfg["marks.grid"] - 1)
    if cfg["marks.placement_sd_mm"] > spacing / 4:
        raise ConfigError(
            "marks.placement_sd_mm",
            f"{cfg['marks.placement_sd_mm']:g} mm is more "
            f"than a quarter of the mark spacing {spacing:g} mm: marks would "
            "coincide and the affine would be singular",
        )
    if cfg["b8.sigma_um"] * UM > 0.01 * cfg["marks.extent_mm"]:
        raise ConfigError(
            "b8.sigma_um", "exceeds 1 % of the mark array: the affine's geometry is meaningless"
        )
    if cfg["comparator.sigma_um"] * UM > 0.01 * cfg["grid.spacing_mm"] * (cfg["grid.points"] - 1):
        raise ConfigError("comparator.sigma_um", "exceeds 1 % of the grid extent")
    if cfg["zscale.sigma_um"] * UM > 0.1 * cfg["zscale.range_mm"]:
        raise ConfigError(
            "zscale.sigma_um", "exceeds 10 % of zscale.range_mm: the line fit cannot find a scale"
        )
    if (
        max(cfg["vertical.sigma_xy_um"], cfg["vertical.sigma_z_um"]) * UM
        > 0.01 * cfg["vertical.extent_mm"]
    ):
        raise ConfigError(
            "vertical.sigma_z_um",
            "the control error exceeds 1 % of the model area: the conformal fit is meaningless",
        )
    for key in ("b8.sx_mm_per_digit", "b8.sy_mm_per_digit"):
        if not 0.5 < cfg[key] / cfg["zscale.s_mm_per_digit"] < 2.0:
            raise ConfigError(
                key,
                "differs from the z scale by more than a factor 2 (the "
                "digitiser model assumes nearly equal scales)",
            )
    if cfg["power.trials"] < 2 or max(cfg["power.marks"]) ** 2 * cfg["power.trials"] > 5e7:
        raise ConfigError(
            "power.trials",
            "the detection-power sweep asks for more than 5e7 simulated marks per cell",
        )
