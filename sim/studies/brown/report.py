"""Report sections of the Brown studies, built from their Parquet files alone (and the
schema's key descriptions). Every number and verdict in the prose is read from a file."""

from __future__ import annotations

import math
from pathlib import Path

from sim.mc.storage import read_provenance, read_table
from sim.report.markdown import claims_markdown, fmt, inputs_markdown, md_table
from sim.studies.brown.schema import DILUTION, TABLE1

OFFSET = "comparator.station_offset_mm"


def _iv(lo, hi, contiguous=True, unit="") -> str:
    if lo is None or (isinstance(lo, float) and math.isnan(lo)):
        return "nowhere"
    s = f"{fmt(lo)}" if lo == hi else f"{fmt(lo)}–{fmt(hi)}"
    return s + unit + ("" if contiguous else " (with gaps)")


def _cell(r) -> str:
    h = _iv(r["holds_low"], r["holds_high"], r["contiguous"])
    ok = _iv(r["ok_low"], r["ok_high"])
    return h if ok == _iv(r["holds_low"], r["holds_high"]) else f"{h} (not contradicted: {ok})"


def consistency_markdown(out: Path) -> str:
    """Where each swept claim holds, per fixed value of the other unprinted input; the
    consistent set; the conflicts (all read from consistent_set.parquet)."""
    cs = read_table(out / "consistent_set.parquet").to_pylist()
    off = [r for r in cs if r["input"] == OFFSET]
    fixed = list(dict.fromkeys(r["fixed"] for r in off))
    claims = list(dict.fromkeys(r["claim"] for r in off))
    get = {(r["fixed"], r["claim"]): r for r in off}
    head = ["claim"] + [
        f"{f} (feasible to {fmt(get[(f, 'ALL')]['feasible_high'])} mm)" for f in fixed
    ]
    rows = [
        [f"`{c}`" if not c.startswith("ALL") else f"**{c}**"] + [_cell(get[(f, c)]) for f in fixed]
        for c in claims
    ]
    sw_lo, sw_hi = off[0]["swept_low"], off[0]["swept_high"]
    txt = [
        f"Station offsets (mm) at which each claim holds, swept from {fmt(sw_lo)} to "
        f"{fmt(sw_hi)} mm; only offsets whose ranges all fit the scale plus micrometer "
        "count (the rest are idealised). **ALL**: every swept prediction holds; "
        "**ALL_SATISFIABLE**: every swept prediction that holds somewhere.",
        "",
        md_table(head, rows),
        "",
    ]
    for f in fixed:
        a = get[(f, "ALL")]
        ok = _iv(a["ok_low"], a["ok_high"], unit=" mm")
        line = (
            f"- {f}: consistent set "
            f"{_iv(a['holds_low'], a['holds_high'], a['contiguous'], ' mm')}; no swept claim "
            f"contradicted (each holds or is inconclusive): {ok}"
        )
        if a["conflicts"]:
            sat = get[(f, "ALL_SATISFIABLE")]
            line += (
                f"; {a['conflicts']}; the claims that hold somewhere hold together for "
                f"{_iv(sat['holds_low'], sat['holds_high'], sat['contiguous'], ' mm')}"
            )
        txt.append(line + ".")
    ext = [r for r in cs if r["input"] == "plate.half_extent_mm"]
    if ext:
        txt += [
            "",
            "Half extents of the points (mm) for which some feasible offset makes the claim hold:",
            "",
            md_table(["claim", "half extents (mm)"], [[r["claim"], _cell(r)] for r in ext]),
        ]
    return "\n".join(txt)


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
        f"Design simulation of the paper's *Concept* section. Plate {cfg['plate.format_mm']:g} mm, "
        f"{cfg['plate.pattern']} pattern ({n} points), stations "
        f"{cfg['comparator.station_offset_mm']:g} mm outside the midsides (nominal), {scale}; "
        f"range sigma {prov['range_sigma_um']:.3f} um, {cfg['trials']} Monte-Carlo trials (seed "
        f"{cfg['seed']}). Three adjustments of the same simulated ranges: `known` (stations "
        "known), `stations` (Brown's datum x1 = x3 = 0, y4 = -y2), `pivot` (plus alpha and "
        "beta). The predictions are the analytic (rigorous) covariances of the nominal "
        "geometry; the Monte Carlo checks them (self-checks) and the bias invariance.",
        "",
        "**Unprinted inputs, swept.** The paper prints neither the station offset ('a short "
        "distance from the midsides') nor the layout of its '25 well-distributed points'. "
        "Both are swept (`consistent_set.parquet`, `sweep.parquet`, figure below); each "
        "geometry is scored by the same claim book and rule as the nominal rows.",
        "",
        consistency_markdown(out),
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
        "nominal offset):",
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
        f"![claims against the station offset]({name}/consistent_set.png)",
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
            f"The paper's production test: a 5 x 5 array at {cfg['plate.spacing_mm']:g} mm, "
            f"{cfg['errors.settings']} settings of {cfg['errors.setting_sigma_um']:g} um each and "
            f"{cfg['errors.comparator_sigma_um']:g} um from the comparator (range sigma "
            f"{prov['range_sigma_um']:.2f} um), reduced with the `pivot` model (2n + 7 unknowns); "
            f"stations {cfg['comparator.station_offset_mm']:g} mm outside the midsides (nominal), "
            f"every range on the {cfg['comparator.scale_length_mm']:g} mm scale plus "
            f"{cfg['comparator.micrometer_mm']:g} mm of micrometer. The paper's listing of the "
            "residuals is lost; its summary line survives. The paper's numbers describe one plate: "
            "*one-plate* rows give the median and the 95 % range over simulated plates and p, the "
            "probability of a plate at least as extreme as the paper's. The *at paper closure* "
            "rows take the paper's own sigma0 (1.6 um as printed), so only the geometry decides.",
            "",
            "**The unprinted station offset, swept** (the grid is printed; one-plate rows "
            "semi-analytically, sigma0 from its chi-square distribution):",
            "",
            consistency_markdown(out),
            "",
            claims_markdown(out / "claims.parquet"),
            "",
            inputs_markdown(cfg, TABLE1),
            "",
            f"![claims against the station offset]({name}/consistent_set.png)",
            f"![table 1]({name}/table1.png)",
        ]
    )
