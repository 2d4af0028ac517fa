"""Configuration of ``wolf_polynomial``: the schema (keys, types, ranges, units, inputs). The
grid geometry is :mod:`.grid`, the cross-key rules :mod:`.checks`.

Seed paper ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976). Coordinates in mm,
discrepancies in um. Keys marked ``input`` were set to match the paper; those the paper does
not print (pointing sigma, field amplitudes, monocomparator sigma) are explored jointly over
their possible ranges (``region.toml``, sized by ``region.*``); the configured values are an
example.
"""

from __future__ import annotations

from sim.mc.config import COMMON, Field

__all__ = ["SCHEMA", "SEED"]

SEED = "000_668e60e68f004f98.txt"

_amp = dict(lo=0.0, hi=1000.0, unit="um", input=True)

SCHEMA = {
    **COMMON,
    "trials": Field(
        2000,
        "int",
        "Monte-Carlo trials (simulated instruments) of the main experiment",
        lo=2,
        hi=100_000_000,
    ),
    "chunk": Field(
        500, "int", "trials per chunk (each chunk has its own spawned stream)", lo=1, hi=1_000_000
    ),
    "plate.area_mm": Field(
        [-100.0, 100.0, -40.0, 60.0],
        "list[float]",
        "calibrated area [xmin, xmax, ymin, ymax] on the carrier, grid centre a "
        "at the origin (paper: 100 x 200 mm; a is an intersection, so the six "
        "rows cannot be symmetric about it)",
        min_len=4,
        hi=1000.0,
        lo=-1000.0,
        input=True,
        unit="mm",
    ),
    "plate.spacing_mm": Field(
        20.0,
        "float",
        "grid spacing (paper: 20 mm quadrille, 66 points)",
        lo=0.0,
        lo_open=True,
        input=True,
        unit="mm",
    ),
    "plate.grid_sigma_um": Field(
        1.0,
        "float",
        "error of the known grid coordinates (paper: about +-1 um)",
        lo=0.0,
        input=True,
        unit="um",
    ),
    "plate.rotation_sigma_deg": Field(
        0.1,
        "float",
        "placement of a plate: rotation sigma (axes 'very nearly parallel')",
        lo=0.0,
        hi=10.0,
        unit="deg",
    ),
    "plate.shift_sigma_mm": Field(
        0.5,
        "float",
        "placement of a plate: shift sigma per axis (a 'very near the centercross')",
        lo=0.0,
        hi=50.0,
        unit="mm",
    ),
    "reduce.ab_mm": Field(
        100.0,
        "float",
        "length of line ab, b on the grid x axis (paper: 100 mm)",
        lo=0.0,
        lo_open=True,
        input=True,
        unit="mm",
    ),
    "reading.count_um": Field(
        4.0,
        "float",
        "size of one count on the plate (paper: roughly 4 um)",
        lo=0.0,
        lo_open=True,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "reading.n": Field(
        3, "int", "readings per point, averaged (paper: three)", lo=1, hi=100, input=True
    ),
    "reading.pointing_sigma_um": Field(
        7.0,
        "float",
        "pointing error of one reading (not printed; an example: the "
        "predictions are decided over the region region.toml declares)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "reading.backlash_um": Field(
        4.0,
        "float",
        "backlash: a reading approached from one side is "
        "offset by +b/2 per axis, from the other by -b/2",
        lo=0.0,
        hi=100.0,
        unit="um",
    ),
    "reading.approach": Field(
        "one_side",
        "str",
        "approach of the pointings (paper: always from the lower right)",
        choices=("one_side", "random"),
        input=True,
    ),
    "field.plane_tilt_um": Field(
        30.0, "float", "non-parallel measurement and carrier planes, displacement at 100 mm", **_amp
    ),
    "field.xy_scale_um": Field(
        45.0, "float", "different X and Y scales, difference over 100 mm", **_amp
    ),
    "field.ways_nonorthogonal_um": Field(
        45.0, "float", "non-orthogonal ways, shear at 100 mm", **_amp
    ),
    "field.ways_curvature_um": Field(35.0, "float", "curved ways, bow at 100 mm", **_amp),
    "field.encoder_periodic_um": Field(
        2.5, "float", "periodic encoder non-linearity, amplitude", **_amp
    ),
    "field.encoder_period_mm": Field(
        50.0,
        "float",
        "period of the encoder non-linearity",
        lo=1.0,
        hi=10000.0,
        unit="mm",
        input=True,
    ),
    "field.gimbal_eccentricity_um": Field(
        300.0,
        "float",
        "gimbal eccentricity along the space rod (most of it is a scale change)",
        **_amp,
    ),
    "field.gimbal_height_mm": Field(
        200.0,
        "float",
        "height of the projection centre above the model plane",
        lo=10.0,
        hi=5000.0,
        unit="mm",
    ),
    "field.stress_um": Field(8.0, "float", "position-dependent stress field, rms per axis", **_amp),
    "field.stress_length_mm": Field(
        70.0, "float", "correlation length of the stress field", lo=1.0, hi=10000.0, unit="mm"
    ),
    "field.spread": Field(
        [0.5, 1.5],
        "list[float]",
        "each drawn amplitude is the set amplitude times U(lo, hi)",
        lo=0.0,
        hi=10.0,
        min_len=2,
    ),
    "field.restitution_um": Field(
        2.0,
        "float",
        "inconsistent mechanical restitution: a fresh "
        "smooth field at every placement, rms per axis",
        lo=0.0,
        hi=100.0,
        unit="um",
    ),
    "field.restitution_length_mm": Field(
        80.0, "float", "correlation length of the restitution field", lo=1.0, hi=10000.0, unit="mm"
    ),
    "field.drift_fraction": Field(
        0.25,
        "float",
        "share of the field's variance that drifts with time (AR(1))",
        lo=0.0,
        hi=1.0,
        unit="",
    ),
    "field.drift_tau_weeks": Field(
        52.0, "float", "time constant of the drift", lo=0.0, lo_open=True, unit="weeks"
    ),
    "calib.n_sets": Field(
        3, "int", "independent sets pooled in the fit (paper: three dates)", lo=1, hi=50, input=True
    ),
    "calib.span_weeks": Field(
        4.0,
        "float",
        "the sets are spread over this period (paper: about a month)",
        lo=0.0,
        hi=520.0,
        input=True,
        unit="weeks",
    ),
    "calib.degree": Field(
        3,
        "int",
        "degree of the correction polynomial (3 = the paper's ten terms A1...A10)",
        lo=1,
        hi=8,
        input=True,
    ),
    "check.age_weeks": Field(
        1.0,
        "float",
        "the independent plate is read this long after the last calibration set",
        lo=0.0,
        hi=520.0,
        unit="weeks",
    ),
    "check.n_points": Field(60, "int", "random points on the independent plate", lo=4, hi=10000),
    "check.shift_sigma_mm": Field(
        2.0,
        "float",
        "independent plate: placement shift sigma per axis",
        lo=0.0,
        hi=100.0,
        unit="mm",
    ),
    "check.rotation_sigma_deg": Field(
        0.5, "float", "independent plate: placement rotation sigma", lo=0.0, hi=45.0, unit="deg"
    ),
    "repeat.n_points": Field(
        10, "int", "points per photograph (paper, Table 1: 10 PUG marks)", lo=2, hi=1000, input=True
    ),
    "repeat.format_mm": Field(
        [150.0, 100.0],
        "list[float]",
        "photograph format (paper: P-30, 100 x 150 mm), fiducials at the midsides",
        lo=1.0,
        hi=1000.0,
        min_len=2,
        input=True,
        unit="mm",
    ),
    "repeat.centre_mm": Field(
        [0.0, 10.0],
        "list[float]",
        "centre of the photograph on the carrier (middle of the calibrated area)",
        lo=-1000.0,
        hi=1000.0,
        min_len=2,
        unit="mm",
    ),
    "repeat.gap_weeks": Field(
        1.0,
        "float",
        "time between the two sets of Table 1 (not stated)",
        lo=0.0,
        hi=520.0,
        unit="weeks",
    ),
    "table1.file": Field(
        "studies/data/wolf_table1.csv",
        "str",
        "transcription of Tables 1 and 2 (relative to the repository root)",
    ),
    "table3.file": Field(
        "studies/data/wolf_table3.csv",
        "str",
        "transcription of Table 3 (relative to the repository root)",
    ),
    "mono.sigma_um": Field(
        1.5,
        "float",
        "error of one monocomparator coordinate (H. Dell Foster, "
        "Table 2; not printed: 'accurate enough'; an example, region.toml)",
        lo=0.0,
        hi=100.0,
        input=True,
        unit="um",
    ),
    "unprinted.trials": Field(
        400,
        "int",
        "instruments per cell of the readings trade-off and of the region's input vectors "
        "(common random numbers: the same instruments for every cell)",
        lo=2,
        hi=10_000_000,
    ),
    "region.points": Field(
        32,
        "int",
        "input vectors of the joint exploration's space-filling design (region.toml); each "
        "one cell on unprinted.trials instruments",
        lo=4,
        hi=4096,
    ),
    "region.rounds": Field(1, "int", "refinement rounds at the region's boundary", lo=0, hi=4),
    "trade.trials": Field(
        400, "int", "trials per cell of the design trade-offs", lo=2, hi=10_000_000
    ),
    "trade.degrees": Field(
        [1, 2, 3, 4, 5], "list[int]", "polynomial degrees compared", lo=1, hi=8, min_len=1
    ),
    "trade.spacings_mm": Field(
        [10.0, 20.0, 25.0, 50.0],
        "list[float]",
        "grid spacings compared (each must divide ab)",
        lo=0.0,
        lo_open=True,
        min_len=1,
        unit="mm",
    ),
    "trade.n_sets": Field(
        [1, 2, 3, 6], "list[int]", "numbers of pooled independent sets", lo=1, hi=50, min_len=1
    ),
    "trade.check_points": Field(
        100, "int", "random independent points read in the same sets", lo=4, hi=10000
    ),
    "trade.readings": Field(
        [1, 2, 3, 5, 10], "list[int]", "readings per point compared", lo=1, hi=100, min_len=1
    ),
    "trade.pointing_sigmas_um": Field(
        [2.0, 4.0, 7.0],
        "list[float]",
        "pointing sigmas compared",
        lo=0.0,
        hi=100.0,
        min_len=1,
        unit="um",
    ),
    "trade.ages_weeks": Field(
        [0.0, 2.0, 4.0, 8.0, 13.0, 26.0, 52.0, 104.0, 208.0],
        "list[float]",
        "ages of the calibration compared",
        lo=0.0,
        hi=5200.0,
        min_len=1,
        unit="weeks",
    ),
    "trade.drift_fractions": Field(
        [0.25, 0.5, 0.75, 1.0],
        "list[float]",
        "drifting shares of the field compared",
        lo=0.0,
        hi=1.0,
        min_len=1,
    ),
}
