"""Report section of ``gridplate_two_plates``: built from the study's Parquet files and its
claim book only (no model code)."""

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
from sim.studies.gridplate.schema import SCHEMA

PARAM_LABEL = {"S": "S", "S2": "S'", "eps": "eps"}


def report(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    c = {r["claim"]: r for r in read_table(out / "claims.parquet").to_pylist()}

    def v(k, f="value"):
        r = c.get(k)
        return fmt(r[f]) if r is not None and r[f] is not None else "n/a"

    cov = read_table(out / "coverage.parquet").to_pydict()
    ch = read_table(out / "chi2_power.parquet").to_pydict()
    be = read_table(out / "beyond.parquet").to_pydict()
    imp = read_table(out / "implied_grid.parquet").to_pydict()
    k = cfg["plate.grid"]
    errata = [r for r in c.values() if r["verdict"] == "erratum"]
    txt = [
        region_markdown(out, list(c.values())),
        "",
        f"![consistent region]({name}/consistent_region.png)",
        "",
        f"Simulated calibrations of a comparator with {cfg['plate.count']} grid plates of "
        f"{k} x {k} points at {cfg['plate.spacing_mm']:g} mm, each on its carrier with "
        f"|kappa| <= {cfg['plate.kappa_deg']:g} deg, {cfg['readings.count']} readings per point "
        f"of {cfg['readings.sigma_um']:g} um, a mean comparator coordinate of "
        f"{cfg['comparator.coord_sigma_um']:g} um, grid coordinates of "
        f"{cfg['grid.sigma_true_um']:g} um (stated {cfg['grid.sigma_stated_um']:g} um), "
        f"{cfg['trials']} calibrations (seed {cfg['seed']}). The paper's numbers describe one "
        "calibration, so they are scored as one-plate statistics: where the paper's value "
        "falls among simulated calibrations (`p`), and whether the simulation is sharp enough "
        "to decide. The configured grid, scale difference and true grid sigma are one example "
        "point: the predictions above are decided over the whole region.",
        "",
        "**Model.** Grid -> comparator affine `x' = A1 x + B1 y + c1`, `y' = A2 x + B2 y + c2` "
        "(the paper's equation 2), decomposed by rows: `S = 1/sqrt(A1^2+B1^2)`, "
        "`S' = 1/sqrt(A2^2+B2^2)`, `phi' - phi = pi/2 - eps`. The combined adjustment carries "
        "`(A, B, C)` and the adjusted grid coordinates as unknowns, x' and y' apart. With "
        "`P_x = 1` and equal weights it is, to first order, the affine fit with the misclosure "
        "cofactor `1 + (A^2+B^2)/P_cx`: the weight-ratio sweeps use that closed form, checked "
        "against the iterated adjustment (`twoplate.self_check.closed_form`). The paper's "
        "re-weighting has the fixed point `P_cx = s_w^2/sg^2 - (A^2+B^2)`: after it the "
        "chi-square test passes by construction (only `sx'^2 + sg^2` is estimable from one "
        "plate), so the test cannot confirm the stated grid sigma.",
        "",
        "**Errata** (the paper against its own printed numbers): "
        + (
            "; ".join(
                f"`{r['claim']}`: printed {fmt(r['ref_low'] + (r['ref_high'] - r['ref_low']) / 2)}, "
                f"recomputed {fmt(r['value'])} ({r['note']})"
                for r in errata
            )
            or "none"
        )
        + ".",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, SCHEMA),
        "",
        "**Grid sigma implied by the weight ratio** (`s0/sqrt(P_cx)`, median and 95 % range):",
        "",
        md_table(
            ["P_cx : P_x", "median (um)", "95 % range (um)"],
            [
                [fmt(r), fmt(m), f"{fmt(lo)}-{fmt(hi)}"]
                for r, m, lo, hi in zip(imp["ratio"], imp["median"], imp["lo"], imp["hi"])
            ],
        ),
        "",
        f"![implied grid sigma]({name}/implied_grid.png)",
        "",
        "**Beyond the paper: grid fixed versus weighted.** Errors of the recovered parameters "
        "over all simulated plates; `stated sd` is the rms of the stated standard deviations "
        "(grid fixed: a-posteriori s0; weighted: a-priori weights).",
        "",
        md_table(
            ["parameter", "method", "bias", "95 % CI", "sd", "stated sd", "unit"],
            [
                [p, m, fmt(b), f"[{fmt(lo)}, {fmt(hi)}]", fmt(s), fmt(st), u]
                for p, m, b, lo, hi, s, st, u in zip(
                    be["param"],
                    be["method"],
                    be["bias"],
                    be["bias_lo"],
                    be["bias_hi"],
                    be["sd"],
                    be["stated_sd_rms"],
                    be["unit"],
                )
            ],
        ),
        "",
        "Coverage of the nominal 95 % intervals:",
        "",
        md_table(
            ["P_cx : P_x"]
            + [f"{PARAM_LABEL[p]} a-priori" for p in PARAM_LABEL]
            + [f"{PARAM_LABEL[p]} a-post." for p in PARAM_LABEL],
            [
                [fmt(r)]
                + [fmt(cov[f"{p}_pri"][i]) for p in PARAM_LABEL]
                + [fmt(cov[f"{p}_post"][i]) for p in PARAM_LABEL]
                for i, r in enumerate(cov["ratio"])
            ]
            + [
                ["grid fixed"]
                + [fmt(cov[f"{p}_fixed_pri"][0]) for p in PARAM_LABEL]
                + [fmt(cov[f"{p}_fixed_post"][0]) for p in PARAM_LABEL]
            ],
        ),
        "",
        f"![coverage]({name}/coverage.png)",
        f"![parameters]({name}/parameters.png)",
        "",
        "**Chi-square test with a wrong stated grid sigma** (fixed a-priori weights "
        f"`P_x = 1/sx'^2`, `P_cx = 1/sg_stated^2`, two-sided at {cfg['analysis.alpha']:g}, "
        "one test per coordinate and plate):",
        "",
        md_table(
            ["stated sigma (um)", "rejection rate", "95 % CI", "analytic"],
            [
                [fmt(s), fmt(r), f"[{fmt(lo)}, {fmt(hi)}]", fmt(a)]
                for s, r, lo, hi, a in zip(
                    ch["stated_um"], ch["reject"], ch["lo"], ch["hi"], ch["analytic"]
                )
            ],
        ),
        "",
        f"![chi-square]({name}/chi2_power.png)",
        "",
        f"Residual vectors of one simulated calibration (plate 1): ![residuals]({name}/residuals.png)",
        "",
        f"Re-weighted ratio (median {v('twoplate.weight_ratio.converged_ratio')}), comparator "
        f"sigma (median {v('twoplate.comparator_sigma.sigma_um')} um).",
    ]
    return "\n".join(txt)
