"""Report sections of the Brown studies, built from their Parquet files alone (and the
schema's key descriptions). Every number and verdict in the prose is read from a file."""

from __future__ import annotations

import math
from pathlib import Path

from sim.mc.storage import read_provenance, read_table
from sim.report.markdown import claims_markdown, fmt, inputs_markdown, md_table
from sim.studies.brown.schema import DILUTION, TABLE1


def _span(lo, hi, unit="") -> str:
    if lo is None or (isinstance(lo, float) and math.isnan(lo)):
        return "nowhere"
    return (f"{fmt(lo)}" if lo == hi else f"{fmt(lo)}–{fmt(hi)}") + unit


def region_markdown(out: Path, what: str) -> str:
    """The section's lead: what the paper's statements imply for the unprinted inputs (the
    projection of the points where every prediction holds), the region, and the verdicts over
    it (read from region_inputs.parquet and claims.parquet)."""
    ins = read_table(out / "region_inputs.parquet").to_pylist()
    cl = [r for r in read_table(out / "claims.parquet").to_pylist() if r["interval"] == "region"]
    r0 = ins[0]
    imp = ", ".join(
        f"{r['input']} {_span(r['together_low'], r['together_high'])}"
        for r in ins
        if r["declared_low"] != r["declared_high"]
    )
    lead = (
        f"**Consistent region.** {what} hold together for {imp} "
        f"({r0['n_together']} of the {r0['n_region']} input vectors of the region; "
        f"{r0['n_points']} explored)."
        if r0["n_together"]
        else f"**Consistent region.** {what} hold together for no input of the region "
        f"({r0['n_region']} input vectors of {r0['n_points']} explored)."
    )
    rows = [
        [
            f"`{r['input']}`",
            f"{fmt(r['declared_low'])}–{fmt(r['declared_high'])}: {r['why']}",
            _span(r["region_low"], r["region_high"]),
            _span(r["together_low"], r["together_high"]),
            f"{fmt(r['resolution_interior'])} / {fmt(r['resolution_boundary'])}",
        ]
        for r in ins
    ]
    verdicts = [
        f"- `{r['claim']}`{' (headline)' if r['headline'] else ''}: **{r['verdict']}** — "
        f"{r['note']}"
        for r in cl
    ]
    return "\n".join(
        [
            lead,
            "",
            "The unprinted inputs are explored jointly (`sim.claims.inference`: a Sobol design "
            "plus refinement at the boundaries; every value analytic). The region holds the input "
            "vectors that the hardware and the printed inputs allow; a prediction *holds* or "
            "*fails* over all of it, else *depends* (where it holds is given) "
            "(`consistent_region.parquet`, `region_inputs.parquet`).",
            "",
            md_table(
                [
                    "input",
                    "possible (hardware)",
                    "region",
                    "every prediction holds",
                    "resolution (interior / boundary)",
                ],
                rows,
            ),
            "",
            "Verdicts over the region:",
            "",
            *verdicts,
        ]
    )


def report_dilution(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    pts = read_table(out / "points.parquet").to_pydict()
    dvp = read_table(out / "dilution_vs_points.parquet").to_pydict()
    n = len(set(pts["point"]))
    name = out.name
    scale = (
        f"every range on the {cfg['comparator.scale_length_mm']:g} mm scale plus "
        f"{cfg['comparator.micrometer_mm']:g} mm of micrometer"
        if cfg["comparator.scale_length_mm"] > 0
        else "scale length not enforced (idealised comparator)"
    )
    txt = [
        region_markdown(out, "The Concept's predictions"),
        "",
        f"Design simulation of the paper's *Concept* section. Plate {cfg['plate.format_mm']:g} mm, "
        f"{cfg['plate.pattern']} pattern ({n} points), stations "
        f"{cfg['comparator.station_offset_mm']:g} mm outside the midsides (a labelled example), {scale}; "
        f"range sigma {prov['range_sigma_um']:.3f} um, {cfg['trials']} Monte-Carlo trials (seed "
        f"{cfg['seed']}). Three adjustments of the same simulated ranges: `known` (stations "
        "known), `stations` (Brown's datum x1 = x3 = 0, y4 = -y2), `pivot` (plus alpha and "
        "beta). The structure and bias rows use the analytic (rigorous) covariances of the example "
        "geometry; the Monte Carlo checks them (self-checks) and the bias invariance.",
        "",
        "**Unprinted inputs.** The paper prints neither the station offset ('a short "
        "distance from the midsides'), nor beta, nor the layout of its '25 well-distributed "
        "points'; the geometry above is a labelled example only, and the predictions are "
        "decided over the region (first paragraph).",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, DILUTION),
        "",
        "**beta near zero.** beta enters the observation equation only squared, so its partial "
        "derivative vanishes at beta = 0 and the normal equations become singular. The solver "
        "estimates b = beta^2 instead (partial -1/(2q), never zero); the point covariances are "
        "the same as with beta whenever beta != 0, because it is a reparameterisation of one "
        "global.",
        "",
        "**The datum of the dilution.** The dilution is stated in Brown's datum, which the "
        "station estimates define; the `brown_design` study gives it in datums that do not "
        "lean on the stations (its `brown.datum_*` rows).",
        "",
        "**Dilution against the number of points** (analytic, k x k grid over the same extent, "
        "example geometry):",
        "",
        md_table(
            ["points", "min %", "mean %", "max %", "pivot extra, max %"],
            [
                [k, fmt(a), fmt(b), fmt(c), fmt(d)]
                for k, a, b, c, d in zip(
                    dvp["n_points"],
                    dvp["dil_min_pct"],
                    dvp["dil_mean_pct"],
                    dvp["dil_max_pct"],
                    dvp["pivot_extra_max_pct"],
                )
            ],
        ),
        "",
        f"![consistent region]({name}/consistent_region.png)",
        f"![sigma maps]({name}/sigma_maps.png)",
        f"![dilution per point]({name}/dilution_points.png)",
        f"![dilution vs points]({name}/dilution_vs_points.png)",
        f"![MC vs analytic]({name}/mc_vs_analytic.png)",
    ]
    return "\n".join(txt)


def report_table1(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    return "\n".join(
        [
            region_markdown(
                out,
                "Table 1's statements (80 % of the sigmas in 1.1–1.3 um, two points as large "
                "as 1.5 um, all below the closure of 1.6 um)",
            ),
            "",
            f"The paper's production test: a 5 x 5 array at {cfg['plate.spacing_mm']:g} mm, "
            f"{cfg['errors.settings']} settings of {cfg['errors.setting_sigma_um']:g} um each and "
            f"{cfg['errors.comparator_sigma_um']:g} um from the comparator (range sigma "
            f"{prov['range_sigma_um']:.2f} um), reduced with the `pivot` model (2n + 7 unknowns). "
            "The printed standard deviations are sigma0 x sqrt(cofactor): sigma0 is the plate's "
            "printed closure (an input, 1.55–1.65 um at its rounding), the cofactor depends on "
            "the station offset and beta, which the paper does not print; so the rows above are "
            "decided over the region, never at one nominal geometry. The Monte Carlo below "
            f"(stations {cfg['comparator.station_offset_mm']:g} mm outside the midsides, a "
            "labelled example) checks the analytic covariance and the closure. The paper's "
            "listing of the residuals is lost; its summary line survives.",
            "",
            claims_markdown(out / "claims.parquet"),
            "",
            inputs_markdown(cfg, TABLE1),
            "",
            f"![consistent region]({name}/consistent_region.png)",
            f"![table 1]({name}/table1.png)",
        ]
    )
