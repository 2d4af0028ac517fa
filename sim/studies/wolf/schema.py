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
from sim.mc.schema_helpers import (
    compared,
    count,
    counts,
    positive,
    printed,
    real,
    reals,
    region_seed,
)

__all__ = ["SCHEMA", "SEED"]

SEED = "000_668e60e68f004f98.txt"


def _amp(default: float, doc: str) -> Field:
    """A field amplitude (um at 100 mm from the centre), in [0, 1000], set to match the paper."""
    return real(default, doc, lo=0.0, hi=1000.0, unit="um", input=True)


SCHEMA = {
    **COMMON,
    "trials": count(
        2000,
        "Monte-Carlo trials (simulated instruments) of the main experiment",
        lo=2,
        hi=100_000_000,
    ),
    "chunk": count(
        500, "trials per chunk (each chunk has its own spawned stream)", lo=1, hi=1_000_000
    ),
    "plate.area_mm": reals(
        [-100.0, 100.0, -40.0, 60.0],
        "calibrated area [xmin, xmax, ymin, ymax] on the carrier, grid centre a "
        "at the origin (paper: 100 x 200 mm; a is an intersection, so the six "
        "rows cannot be symmetric about it)",
        lo=-1000.0,
        hi=1000.0,
        min_len=4,
        unit="mm",
        input=True,
    ),
    "plate.spacing_mm": positive(
        20.0, "grid spacing (paper: 20 mm quadrille, 66 points)", unit="mm", input=True
    ),
    "plate.grid_sigma_um": real(
        1.0,
        "error of the known grid coordinates (paper: about +-1 um)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "plate.rotation_sigma_deg": real(
        0.1,
        "placement of a plate: rotation sigma (axes 'very nearly parallel')",
        lo=0.0,
        hi=10.0,
        unit="deg",
    ),
    "plate.shift_sigma_mm": real(
        0.5,
        "placement of a plate: shift sigma per axis (a 'very near the centercross')",
        lo=0.0,
        hi=50.0,
        unit="mm",
    ),
    # (tenth sweep) a line or count of the smallest double (5e-324) passed check and overflowed
    # the reduction (1 / length) at run time: at least 1e-6 of the paper's value
    "reduce.ab_mm": real(
        100.0,
        "length of line ab, b on the grid x axis (paper: 100 mm; at least 1e-6 of it)",
        lo=1e-4,
        unit="mm",
        input=True,
    ),
    "reading.count_um": real(
        4.0,
        "size of one count on the plate (paper: roughly 4 um; at least 1e-6 of it)",
        lo=4e-6,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "reading.n": count(3, "readings per point, averaged (paper: three)", lo=1, hi=100, input=True),
    "reading.pointing_sigma_um": real(
        7.0,
        "pointing error of one reading (not printed; an example: the "
        "predictions are decided over the region region.toml declares)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "reading.backlash_um": real(
        4.0,
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
    "field.plane_tilt_um": _amp(
        30.0, "non-parallel measurement and carrier planes, displacement at 100 mm"
    ),
    "field.xy_scale_um": _amp(45.0, "different X and Y scales, difference over 100 mm"),
    "field.ways_nonorthogonal_um": _amp(45.0, "non-orthogonal ways, shear at 100 mm"),
    "field.ways_curvature_um": _amp(35.0, "curved ways, bow at 100 mm"),
    "field.encoder_periodic_um": _amp(2.5, "periodic encoder non-linearity, amplitude"),
    "field.encoder_period_mm": real(
        50.0,
        "period of the encoder non-linearity",
        lo=1.0,
        hi=10000.0,
        unit="mm",
        input=True,
    ),
    "field.gimbal_eccentricity_um": _amp(
        300.0, "gimbal eccentricity along the space rod (most of it is a scale change)"
    ),
    "field.gimbal_height_mm": real(
        200.0,
        "height of the projection centre above the model plane",
        lo=10.0,
        hi=5000.0,
        unit="mm",
    ),
    "field.stress_um": _amp(8.0, "position-dependent stress field, rms per axis"),
    "field.stress_length_mm": real(
        70.0, "correlation length of the stress field", lo=1.0, hi=10000.0, unit="mm"
    ),
    "field.spread": reals(
        [0.5, 1.5],
        "each drawn amplitude is the set amplitude times U(lo, hi)",
        lo=0.0,
        hi=10.0,
        min_len=2,
    ),
    "field.restitution_um": real(
        2.0,
        "inconsistent mechanical restitution: a fresh "
        "smooth field at every placement, rms per axis",
        lo=0.0,
        hi=100.0,
        unit="um",
    ),
    "field.restitution_length_mm": real(
        80.0, "correlation length of the restitution field", lo=1.0, hi=10000.0, unit="mm"
    ),
    "field.drift_fraction": real(
        0.25, "share of the field's variance that drifts with time (AR(1))", lo=0.0, hi=1.0
    ),
    "field.drift_tau_weeks": real(
        52.0, "time constant of the drift (at least 1e-6 of a year)", lo=52e-6, unit="weeks"
    ),
    "calib.n_sets": count(
        3, "independent sets pooled in the fit (paper: three dates)", lo=1, hi=50, input=True
    ),
    "calib.span_weeks": real(
        4.0,
        "the sets are spread over this period (paper: about a month)",
        lo=0.0,
        hi=520.0,
        unit="weeks",
        input=True,
    ),
    "calib.degree": count(
        3,
        "degree of the correction polynomial (3 = the paper's ten terms A1...A10)",
        lo=1,
        hi=8,
        input=True,
    ),
    "check.age_weeks": real(
        1.0,
        "the independent plate is read this long after the last calibration set",
        lo=0.0,
        hi=520.0,
        unit="weeks",
    ),
    "check.n_points": count(60, "random points on the independent plate", lo=4, hi=10000),
    "check.shift_sigma_mm": real(
        2.0,
        "independent plate: placement shift sigma per axis",
        lo=0.0,
        hi=100.0,
        unit="mm",
    ),
    "check.rotation_sigma_deg": real(
        0.5, "independent plate: placement rotation sigma", lo=0.0, hi=45.0, unit="deg"
    ),
    "repeat.n_points": count(
        10, "points per photograph (paper, Table 1: 10 PUG marks)", lo=2, hi=1000, input=True
    ),
    "repeat.format_mm": reals(
        [150.0, 100.0],
        "photograph format (paper: P-30, 100 x 150 mm), fiducials at the midsides",
        lo=1.0,
        hi=1000.0,
        min_len=2,
        unit="mm",
        input=True,
    ),
    "repeat.centre_mm": reals(
        [0.0, 10.0],
        "centre of the photograph on the carrier (middle of the calibrated area)",
        lo=-1000.0,
        hi=1000.0,
        min_len=2,
        unit="mm",
    ),
    "repeat.gap_weeks": real(
        1.0,
        "time between the two sets of Table 1 (not stated)",
        lo=0.0,
        hi=520.0,
        unit="weeks",
    ),
    "table1.file": Field(
        "studies/data/wolf_table1.csv",
        "str",
        "transcription of Tables 1 and 2 (relative to the repository root)",
        sweep="its contents are recorded in table1.sha256: write one study file per table",
    ),
    "table3.file": Field(
        "studies/data/wolf_table3.csv",
        "str",
        "transcription of Table 3 (relative to the repository root)",
        sweep="its contents are recorded in table3.sha256: write one study file per table",
    ),
    **{
        f"{t}.sha256": Field(
            "",
            "str",
            f"sha256 of the {t}.file's contents, filled in on load so that an edited table "
            "makes the results stale (if given, the file must still have it)",
            sweep=f"it is the sha256 of the one {t}.file",
        )
        for t in ("table1", "table3")
    },
    "mono.sigma_um": real(
        1.5,
        "error of one monocomparator coordinate (H. Dell Foster, "
        "Table 2; not printed: 'accurate enough'; an example, region.toml)",
        lo=0.0,
        hi=100.0,
        unit="um",
        input=True,
    ),
    "unprinted.trials": count(
        400,
        "instruments per cell of the readings trade-off and of the region's input vectors "
        "(common random numbers: the same instruments for every cell)",
        lo=2,
        hi=10_000_000,
    ),
    "region.points": count(
        48,
        "input vectors of the joint exploration's space-filling design (region.toml); each "
        "one cell on unprinted.trials instruments",
        lo=4,
        hi=4096,
    ),
    "region.rounds": count(1, "refinement rounds at the region's boundary", lo=0, hi=4),
    "region.seed": region_seed(20261122),
    "trade.trials": count(400, "trials per cell of the design trade-offs", lo=2, hi=10_000_000),
    "trade.degrees": compared(counts([1, 2, 3, 4, 5], "polynomial degrees compared", lo=1, hi=8)),
    "trade.spacings_mm": compared(
        reals(
            [10.0, 20.0, 25.0, 50.0],
            "grid spacings compared (each must divide ab)",
            lo=0.0,
            lo_open=True,
            unit="mm",
        )
    ),
    "trade.n_sets": compared(
        counts([1, 2, 3, 6], "numbers of pooled independent sets", lo=1, hi=50)
    ),
    "trade.check_points": count(
        100, "random independent points read in the same sets", lo=4, hi=10000
    ),
    "trade.readings": compared(
        counts([1, 2, 3, 5, 10], "readings per point compared", lo=1, hi=100)
    ),
    "trade.pointing_sigmas_um": compared(
        reals([2.0, 4.0, 7.0], "pointing sigmas compared", lo=0.0, hi=100.0, unit="um")
    ),
    "trade.ages_weeks": compared(
        reals(
            [0.0, 2.0, 4.0, 8.0, 13.0, 26.0, 52.0, 104.0, 208.0],
            "ages of the calibration compared",
            lo=0.0,
            hi=5200.0,
            unit="weeks",
        )
    ),
    "trade.drift_fractions": compared(
        reals([0.25, 0.5, 0.75, 1.0], "drifting shares of the field compared", lo=0.0, hi=1.0)
    ),
}

#: the keys whose default is a number the paper prints for its own setup (seed 000: "66
#: points in a quadrille pattern having a 20mm spacing over an area 100mm by 200mm", grid
#: intersections "accurate to approximately plus or minus one micrometre", line ab "100
#: millimetres", a count "roughly equivalent to four micrometres", "three readings", "three
#: independent sets ... over ... approximately a month", the "third-degree" polynomial A1-A10,
#: Table 1's ten PUG marks): a run with another value is off the paper's setup, its
#: predictions findings (sim.claims.rules.printed_differs). Not marked: the field amplitudes
#: (set so that the simulated "before" discrepancies match the printed ones: Monte-Carlo
#: inputs), the unprinted inputs the region explores (region.toml) and the trade-offs' lists.
#: The approach side ("always ... from the lower right side") and the P-30 photos' "100-by-150-
#: mm format" are printed (they were said "not in the text" here and left unmarked: S33)
PRINTED = (
    "plate.area_mm",
    "plate.spacing_mm",
    "plate.grid_sigma_um",
    "reduce.ab_mm",
    "reading.count_um",
    "reading.n",
    "calib.n_sets",
    "calib.span_weeks",
    "calib.degree",
    "repeat.n_points",
    "reading.approach",
    "repeat.format_mm",
)
SCHEMA.update({k: printed(SCHEMA[k]) for k in PRINTED})
