"""Report section of ``salsig_encoders`` (seed 002): from the study's Parquet files and claim
book only, on the shared skeleton :mod:`sim.report.section`. Scales in mm/digit, angles in
arcsec, errors in um."""

from __future__ import annotations

from pathlib import Path

from sim.report.section import config, errata, figure, region_lead, rows, section, table
from sim.report.tables import fmt, md_table
from sim.studies.salsig.schema import SCHEMA
from sim.studies.salsig.wording import b8_printed, correction, level_text

_CONVENTIONS = (
    "**Conventions.** Salsig's program prints the affine `X1 = A X2 + B Y2 + C`, "
    "`Y1 = D X2 + E Y2 + F` from the observed system X2 (comparator, or B8 digits) to the "
    "control X1 (grid plate). The scales are the lengths of the columns, "
    "`SX = sqrt(A^2 + D^2)`, `SY = sqrt(B^2 + E^2)`, and the non-perpendicularity is "
    "`E = pi/2 - (theta_y - theta_x)` with `theta_x = atan2(D, A)`, `theta_y = atan2(E, B)`. "
    "D must be negative (its sign is lost in the OCR) for the printed angles. The fits put "
    "the residuals on X2, as the program's `VX2, VY2` columns do; the unit-weight error is "
    "therefore in X2 units: mm of the comparator in FIG. 2, *digits* of the B8 in FIG. 3."
)


def _chain(cfg: dict) -> str:
    return (
        "**The calibration chain.** Marks: a "
        f"{cfg['marks.grid']} x {cfg['marks.grid']} array over {cfg['marks.extent_mm']:g} mm, "
        f"scattered {cfg['marks.placement_sd_mm']:g} mm about nominal, tapped with a B8 error of "
        f"{cfg['b8.sigma_um']:g} um per coordinate; B8 readings = inverse of the true B8 affine "
        f"(SX {cfg['b8.sx_mm_per_digit']:.12g}, SY {cfg['b8.sy_mm_per_digit']:.12g} mm/digit, "
        f'E {cfg["b8.e_arcsec"]:g}"{_as_printed(cfg)}). Film on the comparator stage under the grid plate; '
        f"comparator readings of the {cfg['grid.points'] ** 2} intersections and the marks "
        f"through a FIG. 2-like affine, {cfg['comparator.sigma_um']:g} um per coordinate. Then "
        "the paper's two affines. The vertical test: stereomodels digitised with z at the z "
        "scale and x, y at the x scale, fitted to control by a 7-parameter conformal "
        f"transformation before and after the {correction(cfg)} correction."
    )


def _as_printed(cfg: dict) -> str:
    """The words ", as printed in FIG. 3" where the run's B8 affine is the paper's."""
    return ", as printed in FIG. 3" if b8_printed(cfg) else ""


def _power(out: Path, cfg: dict) -> list[str]:
    sw = table(out, "power.parquet")
    cols = ("n_marks", "sigma_um", "power_E", "power_scale", "sd_E_arcsec", "sd_scale_diff_ppm")
    return [
        "**Detection power against the design** (share of calibrations in which E, resp. "
        f"SX - SY, differs from zero at the {level_text(cfg)} level):",
        md_table(
            ["marks", "B8 sigma (um)", "power E", "power SX-SY", 'sd E (")', "sd SX-SY (ppm)"],
            [[n, *(fmt(x) for x in rest)] for n, *rest in zip(*(sw[c] for c in cols))],
        ),
        figure(out, "power.png", "power"),
    ]


def report(out: Path) -> str:
    """The section of ``salsig_encoders``: the vertical test over its region, the paper's
    conventions and printed numbers, the calibration chain and its detection power."""
    out = Path(out)
    cfg = config(out)["config"]
    claims = rows(out, "claims.parquet")
    return section(
        out,
        lead=[
            region_lead(
                out,
                "The vertical test's predictions",
                values=f"{cfg['region.trials']} simulated stereomodels per input vector, whose "
                "noise enters the decision",
                design=f"a Sobol design of {cfg['region.points']} input vectors, not refined (no "
                "printed statement bounds the region)",
            ),
            figure(out, "consistent_region.png", "consistent region")
            + "\n"
            + figure(out, "vertical.png", "vertical"),
        ],
        intro=[_CONVENTIONS, errata(claims), _chain(cfg)],
        schema=SCHEMA,
        body=_power(out, cfg),
        figures=[
            ("residuals", "residuals.png"),
            ("recovery", "recovery.png"),
        ],
    )
