"""Configuration schema and load-time checks of study ``brown_design`` (seed
``004_f5bd9e86c308241f.txt``, Brown 1968).

Keys marked ``input`` were set to match a number the paper prints. Keys the paper does not
print (station offset, beta, the pass time, the screw pitch, the layout of the Zeiss grid's
33 calibrated points) are explored jointly over their hardware ranges (:mod:`.region`); the
claims that depend on them are decided over the consistent region
(``consistent_region.parquet``).
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import COMMON, ConfigError, Field

__all__ = ["SEED", "SCHEMA", "check", "MAX_CELLS"]

SEED = "004_f5bd9e86c308241f.txt"
F = Field
MAX_CELLS = 200_000  # design cells (each a batched analytic covariance)
MAX_POINTS = 900  # points of one plate (covariances are (2n)^2 per cell)

SCHEMA = {
    **COMMON,
    "trials": F(
        2000, "int", "Monte-Carlo trials of the check of the paper's design", lo=2, hi=10_000_000
    ),
    "chunk": F(500, "int", "trials per chunk", lo=1, hi=1_000_000),
    "plate.format_mm": F(
        245.0,
        "float",
        "side of the square format (paper: 245 x 245 mm)",
        lo=1.0,
        hi=2000.0,
        input=True,
        unit="mm",
    ),
    "scale.graduated_mm": F(
        261.0,
        "float",
        "graduated length of the scale (paper: 261 mm)",
        lo=1.0,
        hi=5000.0,
        input=True,
        unit="mm",
    ),
    "scale.micrometer_mm": F(
        1.0,
        "float",
        "largest micrometer translation (paper: 1 mm)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="mm",
    ),
    "comparator.alpha_mm": F(
        0.5,
        "float",
        "radial pivot offset alpha (not printed; it drops out of the coordinates)",
        lo=-50.0,
        hi=50.0,
        unit="mm",
    ),
    "comparator.sigma_um": F(
        1.1,
        "float",
        "random comparator error per reading (paper, Table 1: about 1.1 um)",
        lo=0.0,
        hi=1000.0,
        input=True,
        unit="um",
    ),
    # design grid
    "design.positions": F(
        [3, 4, 6, 8], "list[int]", "plate positions (stations)", lo=3, hi=24, min_len=1
    ),
    "design.offsets_mm": F(
        [5.0, 10.0, 17.0, 20.0, 30.0, 45.0, 60.0, 80.0],
        "list[float]",
        "station offsets outside the midsides",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        min_len=1,
        unit="mm",
    ),
    "design.grids": F(
        [3, 4, 5, 6, 7], "list[int]", "points per side of the square grid", lo=2, hi=30, min_len=1
    ),
    "design.extents_mm": F(
        [70.0, 90.0, 110.0],
        "list[float]",
        "half extent of the grid",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        min_len=1,
        unit="mm",
    ),
    "design.settings": F(
        [1, 2, 3], "list[int]", "settings per point and position", lo=1, hi=20, min_len=1
    ),
    "design.setting_sigma_um": F(
        [1.7, 0.5],
        "list[float]",
        "sigma of one setting (paper: 1.7 "
        "um by eye; better than 0.5 um expected from the semi-automatic "
        "setting device)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        min_len=1,
        input=True,
        unit="um",
    ),
    "design.beta_mm": F(
        [1.0, 5.0],
        "list[float]",
        "tangential pivot offset beta",
        lo=0.0,
        hi=50.0,
        min_len=1,
        unit="mm",
    ),
    # measuring time
    "time.images": F(
        30, "int", "images of the timed plate (paper: 30)", lo=1, hi=10_000, input=True
    ),
    "time.single_min": F(
        60.0,
        "float",
        "time for 30 images, 4 positions, single settings (paper: within one hour)",
        lo=0.0,
        lo_open=True,
        hi=1e5,
        input=True,
        unit="min",
    ),
    "time.double_min": F(
        90.0,
        "float",
        "the same with double settings (paper: about 90 min)",
        lo=0.0,
        lo_open=True,
        hi=1e5,
        input=True,
        unit="min",
    ),
    "time.pass_min": F(
        2.0,
        "float",
        "fixed cost of one plate position (turn the holder, swing "
        "the arm; not printed: a labelled example)",
        lo=0.0,
        hi=1e4,
        unit="min",
    ),
    # the paper's design
    "paper.positions": F(
        4, "int", "plate positions of the paper's comparator", lo=3, hi=24, input=True
    ),
    "paper.grid": F(5, "int", "Table 1: 5 x 5 array", lo=2, hi=30, input=True),
    "paper.extent_mm": F(
        90.0,
        "float",
        "Table 1: 45 mm spacing -> +-90 mm",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        input=True,
        unit="mm",
    ),
    "paper.settings": F(2, "int", "Table 1: double settings", lo=1, hi=20, input=True),
    "paper.setting_sigma_um": F(
        1.7,
        "float",
        "Table 1: one setting 1.7 um",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        input=True,
        unit="um",
    ),
    "paper.offset_mm": F(
        17.0,
        "float",
        "station offset of the paper's design (not printed: a labelled example, the "
        "claims that depend on it are decided over the region; must fit on the scale)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        unit="mm",
    ),
    "paper.beta_mm": F(
        1.0,
        "float",
        "beta of the paper's design (not printed: a labelled example; decided over the region)",
        lo=0.0,
        hi=50.0,
        unit="mm",
    ),
    # datum (brown_dilution's example geometry; must be buildable on the scale)
    "datum.grid": F(5, "int", "points per side (brown_dilution geometry)", lo=3, hi=30),
    "datum.spacing_mm": F(
        45.0, "float", "grid spacing (brown_dilution geometry)", lo=0.01, hi=1000.0, unit="mm"
    ),
    "datum.offset_mm": F(
        17.0,
        "float",
        "station offset (brown_dilution geometry)",
        lo=0.0,
        lo_open=True,
        hi=1000.0,
        unit="mm",
    ),
    "datum.beta_mm": F(1.0, "float", "beta", lo=0.0, hi=50.0, unit="mm"),
    # error budget
    "budget.graduation_um": F(
        0.54,
        "float",
        "residual graduation error after calibration (paper: sqrt(0.5^2 + 0.2^2) = 0.54 um)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.scale_spec_um": F(
        1.0,
        "float",
        "graduation error of an uncalibrated scale (paper's "
        "specification: cumulative nonlinearity at most 1 um)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.screw_um": F(
        0.3,
        "float",
        "residual screw error after calibration (paper: 0.3 um)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.screw_harmonics": F(
        3, "int", "Fourier terms of the residual screw error over 1 mm", lo=1, hi=50
    ),
    "budget.drum_periodic_um": F(
        0.5,
        "float",
        "uncorrected periodic error of the drum (paper: up to 0.5 um)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.pitch_mm": F(
        0.5,
        "float",
        "screw pitch (not printed: a labelled example; decided over the region)",
        lo=0.01,
        hi=1.0,
        unit="mm",
    ),
    "budget.wobble_um": F(
        2.0,
        "float",
        "radial pivot wobble at 3 kg thrust (paper: up to 2 um)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.wobble_harmonic": F(
        2, "int", "harmonic of the wobble over the arm's direction", lo=1, hi=20
    ),
    "budget.sphericity_um": F(
        0.25,
        "float",
        "sphericity of the pivot ball (paper: 0.25 um), modelled as a second-harmonic radial error",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "budget.target_se_um": F(
        0.005,
        "float",
        "adaptive: standard error target of each rms coordinate error",
        lo=1e-4,
        hi=100.0,
        unit="um",
    ),
    "budget.max_trials": F(20000, "int", "adaptive: trial limit per source", lo=10, hi=10_000_000),
    # the paper's external comparisons
    "zeiss.points": F(
        33,
        "int",
        "calibrated intersections of the Zeiss grid (paper: 33)",
        lo=3,
        hi=MAX_POINTS,
        input=True,
    ),
    "zeiss.grid_sigma_um": F(
        0.8,
        "float",
        "stated accuracy of the Zeiss grid (paper: 0.8 um rms)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "zeiss.half_extent_mm": F(
        90.0,
        "float",
        "half extent of the 33-point sample (layout not "
        "printed: a labelled example; decided over the region)",
        lo=1.0,
        hi=1000.0,
        unit="mm",
    ),
    "operation.lateral_offset_um": F(
        100.0,
        "float",
        "lateral offset of the image in the reticle (paper: as much as 100 um)",
        lo=0.0,
        hi=1e4,
        input=True,
        unit="um",
    ),
    "operation.gap_um": F(
        100.0,
        "float",
        "gap between plate and scale (paper: 75 to 100 um; the larger is the worst case)",
        lo=0.1,
        hi=1e4,
        input=True,
        unit="um",
    ),
    "calibration.accuracy_um": F(
        1.0,
        "float",
        "accuracy the tolerances are stated for (paper: one micron)",
        lo=0.001,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "calibration.drum_dividing_arcsec": F(
        15.0,
        "float",
        "dividing accuracy of the drum (paper: 15 seconds of arc)",
        lo=0.0,
        hi=3600.0,
        input=True,
    ),
    # the joint exploration of the unprinted inputs (sim.claims.inference; .region)
    "region.points": F(
        1024,
        "int",
        "Sobol design size of the analytic tolerance region (offset x beta x screw pitch)",
        lo=256,
        hi=16384,
    ),
    "region.rounds": F(3, "int", "refinement rounds of the tolerance region", lo=0, hi=8),
    "region.plate_points": F(
        32,
        "int",
        "Sobol design size of the plate region (offset x beta x Zeiss layout; each point "
        "draws unprinted.plates plates)",
        lo=8,
        hi=1024,
    ),
    "unprinted.plates": F(
        4000, "int", "Gaussian plates drawn per input vector (linearised)", lo=100, hi=1_000_000
    ),
    # coverage
    "coverage.trials": F(10000, "int", "trials of the nominal coverage runs", lo=10, hi=10_000_000),
    "coverage.sweep_trials": F(
        2000, "int", "trials per point of the coverage sweeps", lo=10, hi=10_000_000
    ),
    "coverage.sigma_um": F(
        1.0, "float", "range sigma of the nominal case", lo=1e-6, hi=1e5, unit="um"
    ),
    "coverage.noise_um": F(
        [1.0, 300.0, 1000.0, 3000.0, 10000.0],
        "list[float]",
        "range sigmas of the noise sweep",
        lo=1e-6,
        hi=1e5,
        min_len=1,
        unit="um",
    ),
    "coverage.grids": F(
        [2, 3, 4, 5], "list[int]", "grids of the point-count sweep", lo=2, hi=20, min_len=1
    ),
    "coverage.betas_mm": F(
        [0.0, 0.003, 0.01, 0.03, 0.1, 1.0],
        "list[float]",
        "betas of the beta sweep",
        lo=0.0,
        hi=50.0,
        min_len=1,
        unit="mm",
    ),
    "coverage.alpha": F(
        0.05, "float", "level of the global chi-square test", lo=0.0, lo_open=True, hi=0.5
    ),
    # bayes
    "bayes.walkers": F(32, "int", "emcee walkers", lo=16, hi=1000),
    "bayes.steps": F(500, "int", "emcee steps per walker and chain", lo=100, hi=1_000_000),
    "bayes.chains": F(
        4, "int", "independent emcee ensembles (run in parallel, one per chunk)", lo=2, hi=64
    ),
    "bayes.grid_prior_log_sd": F(
        0.1,
        "float",
        "sd of log sigma_g in the certificate prior of the two-plate ratio (10 %: assumed)",
        lo=0.001,
        hi=10.0,
    ),
}

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
    for key, lst in _PAPER_IN_GRID:
        if not any(np.isclose(cfg[key], v) for v in cfg[lst]):
            raise ConfigError(
                key,
                f"the paper's design must be a cell of the grid: "
                f"{cfg[key]!r} is not in {lst} {cfg[lst]}",
            )
    if cfg["time.double_min"] <= cfg["time.single_min"]:
        raise ConfigError("time.double_min", "must exceed time.single_min")
    for key in ("time.pass_min",):
        v = cfg[key]
        if 4 * v >= cfg["time.single_min"]:
            raise ConfigError(
                key, "four passes would take the whole single-setting time (time.single_min)"
            )
    half = cfg["plate.format_mm"] / 2
    if cfg["paper.extent_mm"] > half:
        raise ConfigError("paper.extent_mm", "outside the format")
    if cfg["zeiss.half_extent_mm"] > half:
        raise ConfigError(
            "zeiss.half_extent_mm",
            f"the Zeiss sample must lie on the format (half side {half:g} mm)",
        )
    if (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2 > half:
        raise ConfigError("datum.spacing_mm", "the datum grid leaves the format")
    hmax = max_offset_mm(cfg, cfg["paper.extent_mm"])
    if cfg["paper.offset_mm"] > hmax + 1e-9:
        raise ConfigError(
            "paper.offset_mm",
            f"the paper's design must fit its hardware: at "
            f"{cfg['paper.offset_mm']:g} mm the longest range exceeds the scale "
            f"plus micrometer (at most {hmax:.1f} mm fits a +-"
            f"{cfg['paper.extent_mm']:g} mm grid)",
        )
    dmax = max_offset_mm(cfg, (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2)
    if cfg["datum.offset_mm"] > dmax + 1e-9:
        raise ConfigError(
            "datum.offset_mm",
            f"the datum geometry must be buildable: at {cfg['datum.offset_mm']:g} mm its "
            f"longest range exceeds the scale plus micrometer (at most {dmax:.1f} mm fits)",
        )
    for e in [cfg["zeiss.half_extent_mm"], 40.0]:  # 40 mm: the region's smallest layout
        if (2 * int(e // 10) + 1) ** 2 < cfg["zeiss.points"]:
            raise ConfigError(
                "zeiss.points",
                f"+-{e:g} mm holds fewer 1 cm grid "
                f"intersections than zeiss.points = {cfg['zeiss.points']}",
            )
    n_cells = 1
    for lst in (
        "design.positions",
        "design.grids",
        "design.extents_mm",
        "design.offsets_mm",
        "design.beta_mm",
        "design.settings",
        "design.setting_sigma_um",
    ):
        n_cells *= len(cfg[lst])
    if n_cells > MAX_CELLS:
        raise ConfigError(
            "design.offsets_mm", f"{n_cells} design cells exceed the limit of {MAX_CELLS}"
        )
    if max(cfg["design.grids"]) ** 2 > MAX_POINTS or cfg["datum.grid"] ** 2 > MAX_POINTS:
        raise ConfigError("design.grids", f"more than {MAX_POINTS} points per plate")
    if cfg["budget.max_trials"] < 2 * cfg["chunk"]:
        raise ConfigError("budget.max_trials", "must allow at least two chunks (2 x chunk)")
