"""Report section of ``salsig_encoders``: from the study's Parquet files and claim book only."""

from __future__ import annotations

from pathlib import Path

from sim.mc.storage import read_provenance, read_table
from sim.report.markdown import (
    claims_markdown,
    fmt,
    inputs_markdown,
    md_table,
)
from sim.report.region import region_markdown
from sim.studies.salsig.schema import SCHEMA


def report(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    c = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}
    sw = read_table(out / "power.parquet").to_pydict()
    errata = [r for r in c.values() if r["verdict"] == "erratum"]
    txt = [
        region_markdown(out, list(c.values())),
        "",
        f"![consistent region]({name}/consistent_region.png)",
        f"![vertical]({name}/vertical.png)",
        "",
        "**Conventions.** Salsig's program prints the affine `X1 = A X2 + B Y2 + C`, "
        "`Y1 = D X2 + E Y2 + F` from the observed system X2 (comparator, or B8 digits) to the "
        "control X1 (grid plate). The scales are the lengths of the columns, "
        "`SX = sqrt(A^2 + D^2)`, `SY = sqrt(B^2 + E^2)`, and the non-perpendicularity is "
        "`E = pi/2 - (theta_y - theta_x)` with `theta_x = atan2(D, A)`, `theta_y = atan2(E, B)`. "
        "D must be negative (its sign is lost in the OCR) for the printed angles. The fits put "
        "the residuals on X2, as the program's `VX2, VY2` columns do; the unit-weight error is "
        "therefore in X2 units: mm of the comparator in FIG. 2, *digits* of the B8 in FIG. 3.",
        "",
        "**Errata** (the paper against its own printed data): "
        + ("; ".join(f"`{r['claim']}`: {r['note']}" for r in errata) or "none")
        + ".",
        "",
        "**The calibration chain.** Marks: a "
        f"{cfg['marks.grid']} x {cfg['marks.grid']} array over {cfg['marks.extent_mm']:g} mm, "
        f"scattered {cfg['marks.placement_sd_mm']:g} mm about nominal, tapped with a B8 error of "
        f"{cfg['b8.sigma_um']:g} um per coordinate; B8 readings = inverse of the true B8 affine "
        "(SX, SY, E as printed in FIG. 3). Film on the comparator stage under the grid plate; "
        f"comparator readings of the {cfg['grid.points'] ** 2} intersections and the marks "
        f"through a FIG. 2-like affine, {cfg['comparator.sigma_um']:g} um per coordinate. Then "
        "the paper's two affines. The vertical test: stereomodels digitised with z at the z "
        "scale and x, y at the x scale, fitted to control by a 7-parameter conformal "
        "transformation before and after the 12.500/12.700 correction.",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, SCHEMA),
        "",
        f"![residuals]({name}/residuals.png)",
        f"![recovery]({name}/recovery.png)",
        "",
        "**Detection power against the design** (share of calibrations in which E, resp. "
        "SX - SY, differs from zero at the 95 % level):",
        "",
        md_table(
            ["marks", "B8 sigma (um)", "power E", "power SX-SY", 'sd E (")', "sd SX-SY (ppm)"],
            [
                [n, fmt(s), fmt(a), fmt(b), fmt(e), fmt(d)]
                for n, s, a, b, e, d in zip(
                    sw["n_marks"],
                    sw["sigma_um"],
                    sw["power_E"],
                    sw["power_scale"],
                    sw["sd_E_arcsec"],
                    sw["sd_scale_diff_ppm"],
                )
            ],
        ),
        "",
        f"![power]({name}/power.png)",
    ]
    return "\n".join(txt)
