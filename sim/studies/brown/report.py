"""Report sections of the Brown studies, built from their Parquet files alone."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...report import claims_markdown, fmt, inputs_markdown, md_table
from ...storage import read_provenance, read_table
from .schema import DILUTION, TABLE1

def report_dilution(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    pts = read_table(out / "points.parquet").to_pydict()
    e85 = read_table(out / "edge_085.parquet").to_pydict()
    dvp = read_table(out / "dilution_vs_points.parquet").to_pydict()
    name = out.name
    txt = [
        f"Design simulation of the paper's *Concept* section. Plate {cfg['plate.format_mm']:g} mm, "
        f"{cfg['plate.pattern']} pattern ({len(set(pts['point']))} points), stations "
        f"{cfg['comparator.station_offset_mm']:g} mm outside the midsides, range sigma "
        f"{prov['range_sigma_um']:.3f} um, {cfg['trials']} trials (seed {cfg['seed']}). "
        "Three adjustments of the same simulated ranges: `known` (stations known), `stations` "
        "(Brown's datum x1 = x3 = 0, y4 = -y2), `pivot` (plus alpha and beta).",
        "",
        "**beta near zero.** beta enters the observation equation only squared, so its partial "
        "derivative vanishes at beta = 0 and the normal equations become singular. The solver "
        "estimates b = beta^2 instead (partial -1/(2q), never zero); the point covariances are "
        "the same as with beta whenever beta != 0, because it is a reparameterisation of one "
        "global.",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, DILUTION),
        "",
        "**Two caveats, from the `brown_design` study.** The dilution above is stated in "
        "Brown's datum, which the station estimates define; in datums that do not lean on the "
        "stations (inner constraints over the points, a similarity onto the corners) most of it "
        "disappears -- see the `brown.datum_invariant_dilution` rows there. And this geometry "
        "(points to the edges, stations well outside the midsides) is the idealised four-station "
        "system of the paper's Figure 1: the built comparator reads ranges on a 261 mm scale, "
        "which `brown_design` shows cannot reach such a layout.",
        "",
        "**Where 0.71-0.85 holds.** The centre ratio is 1/sqrt(2) = 0.7071 for any station "
        "offset. The largest ratio depends on how far the points reach and how far out the "
        "stations are; the station offset giving 0.85 for a 5 x 5 grid:",
        "",
        md_table(["half extent of points (mm)", "offset for 0.85 (mm)"],
                 [[fmt(e), fmt(f) if f is not None and np.isfinite(f) else "none in 1-200 mm"]
                  for e, f in zip(e85["half_extent_mm"], e85["offset_for_085_mm"])]),
        "",
        "**Dilution against the number of points** (analytic, k x k grid over the same extent):",
        "",
        md_table(["points", "min %", "mean %", "max %", "pivot extra, max %"],
                 [[n, fmt(a), fmt(b), fmt(c), fmt(d)] for n, a, b, c, d in
                  zip(dvp["n_points"], dvp["dil_min_pct"], dvp["dil_mean_pct"], dvp["dil_max_pct"],
                      dvp["pivot_extra_max_pct"])]),
        "",
        f"![sigma maps]({name}/sigma_maps.png)",
        f"![dilution per point]({name}/dilution_points.png)",
        f"![dilution vs points]({name}/dilution_vs_points.png)",
        f"![sigma vs offset]({name}/sigma_vs_offset.png)",
        f"![edge 0.85]({name}/edge_085.png)",
        f"![MC vs analytic]({name}/mc_vs_analytic.png)",
    ]
    return "\n".join(txt)


def report_table1(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    return "\n".join([
        f"The paper's production test: a 5 x 5 array at {cfg['plate.spacing_mm']:g} mm, "
        f"{cfg['errors.settings']} settings of {cfg['errors.setting_sigma_um']:g} um each and "
        f"{cfg['errors.comparator_sigma_um']:g} um from the comparator (range sigma "
        f"{prov['range_sigma_um']:.2f} um), reduced with the `pivot` model (2n + 7 unknowns). "
        "The paper's listing of the residuals is lost; its summary line survives. The paper's "
        "numbers describe one plate, so the simulated values are medians with the 95 % range "
        "over simulated plates. The paper reports the standard deviations of the plate "
        "coordinates from one reduction, i.e. a-posteriori values, sigma0 times the root of "
        "the cofactor; the simulation does the same.",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, TABLE1),
        "",
        f"![table 1]({name}/table1.png)",
    ])

