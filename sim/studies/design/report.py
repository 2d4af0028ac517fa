"""Report section of study ``brown_design`` (seed ``004``): built from the study's Parquet
files and its claim book only, never from live model code. Every number and verdict in the
prose is read from those files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.mc.storage import read_provenance, read_table
from sim.report.markdown import claims_markdown, fmt, inputs_markdown, md_table
from sim.studies.design.schema import SCHEMA

__all__ = ["report"]


def _t(out, name):
    return read_table(out / name).to_pydict()


def _datum_findings(V, VH, feas_note):
    g = lambda k: (V.get(k, np.nan), VH.get(k, np.nan))  # noqa: E731
    (bl, bh), (il, ih), (cl, ch) = (
        g(f"brown.datum.{d}.stations_pct") for d in ("brown", "invariant", "corners")
    )
    (pil, pih), (pcl, pch) = (
        g("brown.datum.invariant.pivot_pct"),
        g("brown.datum.corners.pivot_pct"),
    )
    return (
        f"* *Datum of the dilution* (findings, not scored against Brown's sentence): in "
        f"Brown's datum the `stations` dilution of brown_dilution's geometry is "
        f"{bl:.1f}-{bh:.1f} %; after the S-transformation to inner constraints over the points "
        f"it is {il:.1f}-{ih:.1f} %, after a similarity onto the four corners {cl:.1f}-{ch:.1f} %. "
        f"So {100 * (1 - ih / bh):.0f} % of the largest and {100 * (1 - il / bl):.0f} % of the "
        "smallest dilution belong to the station-defined datum (the station estimates' errors "
        "carried into every point as a translation and rotation), not to the precision of the "
        "point configuration. For `pivot` the inner-constraint dilution is "
        f"{pil:.1f}-{pih:.1f} % and the corner-similarity one {pcl:.1f}-{pch:.1f} %: a "
        f"similarity removes most of beta's extra, scale-like dilution.{feas_note}"
    )


def _span(lo, hi) -> str:
    if lo is None or not np.isfinite(lo):
        return "nowhere"
    return fmt(lo) if lo == hi else f"{fmt(lo)}–{fmt(hi)}"


def region_md(out: Path) -> str:
    """What the region says: per part, where every prediction holds, the region, the
    resolution, and the verdicts over it (region_inputs.parquet, claims.parquet)."""
    ins = read_table(out / "region_inputs.parquet").to_pylist()
    cl = [r for r in read_table(out / "claims.parquet").to_pylist() if r["interval"] == "region"]
    txt = []
    for part in dict.fromkeys(r["part"] for r in ins):
        rs = [r for r in ins if r["part"] == part]
        r0 = rs[0]
        txt.append(
            f"*Part `{part}`* ({r0['n_region']} of {r0['n_points']} explored input vectors in the "
            f"region; every prediction holds at {r0['n_together']}): "
            + "; ".join(
                f"`{r['input']}` possible {fmt(r['declared_low'])}–{fmt(r['declared_high'])}, "
                f"region {_span(r['region_low'], r['region_high'])}, all hold "
                f"{_span(r['together_low'], r['together_high'])} (resolution "
                f"{fmt(r['resolution_interior'])} / {fmt(r['resolution_boundary'])})"
                for r in rs
            )
            + "."
        )
    txt += ["", "Verdicts over the region:", ""]
    txt += [
        f"- `{r['claim']}`{' (headline)' if r['headline'] else ''}: **{r['verdict']}** — "
        f"{r['note']}"
        for r in cl
    ]
    return "\n".join(txt)


def report(out: Path) -> str:
    prov = read_provenance(out / "claims.parquet")
    cfg = prov["config"]
    name = out.name
    d, b, c = _t(out, "design.parquet"), _t(out, "budget.parquet"), _t(out, "coverage.parquet")
    by = _t(out, "bayes.parquet")
    cl = _t(out, "claims.parquet")
    V = dict(zip(cl["claim"], cl["value"]))
    VH = dict(zip(cl["claim"], cl["value_high"]))
    N = dict(zip(cl["claim"], cl["note"]))
    dt = _t(out, "datum.parquet")
    feas_note = (
        ""
        if all(dt["feasible"])
        else " (That geometry is *idealised*: its longest "
        "range does not fit on the scale plus micrometer; the rows are findings.)"
    )
    ok = np.array(d["feasible"])
    reasons: dict[str, int] = {}
    for r in np.array(d["reason"])[~ok]:
        for part in r.split("; "):
            key = " ".join(part.split(" ")[:2])
            reasons[key] = reasons.get(key, 0) + 1
    pf = np.flatnonzero(d["pareto"])
    pf = pf[np.argsort(np.array(d["time_min"])[pf])]
    jp = int(np.flatnonzero(d["paper_design"])[0])
    bud = dict(zip(b["source"], b["rms_um"]))
    txt = [
        "**Consistent region.** The tolerances and external comparisons that depend on the "
        "unprinted station offset, beta, screw pitch and Zeiss layout are decided over the "
        "region of those inputs that the comparator (the 261 + 1 mm scale reading Table 1's "
        "plate, and the Zeiss points for the Zeiss rows) allows, explored jointly "
        "(`consistent_region.parquet`, `region_inputs.parquet`; figure: brown_table1's region).",
        "",
        region_md(out),
        "",
        "The questions Brown answered by simulation before building the comparator, asked "
        "systematically, and the printed numbers of his *Operation*, *Calibration* and "
        "*Results* sections. Accuracies are in a datum that does not lean on the stations "
        "(inner constraints over the measured points) unless stated.",
        "",
        "**Findings.**",
        "",
        _datum_findings(V, VH, feas_note),
        f"* *Scale length.* With every range on the scale plus micrometer the stations can stand "
        f"at most {fmt(V.get('brown.design.max_offset_paper_grid_mm'))} mm outside the midsides "
        f"for Table 1's grid and {fmt(V.get('brown.design.max_offset_dilution_grid_mm'))} mm "
        "for brown_dilution's. Verdicts use feasible designs only.",
        f"* *Design.* {N.get('brown.design.paper_on_front_same_points', '')}.",
        f"* *Error budget.* Setting error alone {fmt(bud.get('setting'))} um rms after a rigid "
        f"fit; calibrated scale {fmt(bud.get('scale'))} um, uncalibrated scale at its "
        f"specification {fmt(bud.get('scale_spec'))} um, calibrated screw {fmt(bud.get('screw'))} "
        f"um, uncorrected drum {fmt(bud.get('drum_periodic'))} um, 3 kg wobble "
        f"{fmt(bud.get('wobble_3kg'))} um (as a first harmonic {fmt(bud.get('wobble_3kg_h1'))} um: "
        f"absorbed by the stations), ball sphericity {fmt(bud.get('sphericity'))} um.",
        "",
        claims_markdown(out / "claims.parquet"),
        "",
        inputs_markdown(cfg, SCHEMA),
        "",
        "### Design trade-off",
        "",
        f"{len(ok)} cells, {int(ok.sum())} feasible; infeasible cells stay in `design.parquet` "
        "with the reason (" + ", ".join(f"{k}: {v}" for k, v in reasons.items()) + "). "
        f"Measuring time: the paper's 60 and 90 minutes for 30 images, with "
        f"{fmt(cfg['time.pass_min'])} min per plate position (not printed; a labelled example).",
        "",
        md_table(
            [
                "P",
                "grid",
                "extent (mm)",
                "offset (mm)",
                "beta (mm)",
                "settings",
                "setting sigma (um)",
                "time (min)",
                "worst sigma (um)",
                "mean sigma (um)",
            ],
            [
                [
                    d["positions"][i],
                    d["grid"][i],
                    fmt(d["extent_mm"][i]),
                    fmt(d["offset_mm"][i]),
                    fmt(d["beta_mm"][i]),
                    d["settings"][i],
                    fmt(d["setting_sigma_um"][i]),
                    fmt(d["time_min"][i]),
                    fmt(d["worst_sigma_um"][i]),
                    fmt(d["mean_sigma_um"][i]),
                ]
                for i in pf
            ],
        ),
        "",
        f"The paper's design: {fmt(d['time_min'][jp])} min, worst sigma "
        f"{fmt(d['worst_sigma_um'][jp])} um, mean {fmt(d['mean_sigma_um'][jp])} um.",
        "",
        f"![Pareto front]({name}/pareto.png)",
        "",
        "### Error budget of the comparator",
        "",
        "Each source alone on the Table-1 plate (pivot model), coordinate errors after a rigid "
        "fit over all points; adaptive trial counts through the runner (target standard error "
        f"{fmt(cfg['budget.target_se_um'])} um).",
        "",
        md_table(
            ["source", "what", "rms (um)", "MC s.e. (um)", "trials", "rms sigma0 (um)"],
            [
                [s, de, fmt(r), fmt(se), t, fmt(s0)]
                for s, de, r, se, t, s0 in zip(
                    b["source"], b["description"], b["rms_um"], b["se_um"], b["trials"], b["s0_um"]
                )
            ],
        ),
        "",
        f"![error budget]({name}/budget.png)",
        "",
        "### Datum",
        "",
        "Brown's datum is x1 = x3 = 0, y4 = -y2 (the stations); `invariant` rows use the "
        "S-transformation to inner constraints over the points, `corners` a similarity onto the "
        "four corner points.",
        "",
        f"![datum]({name}/datum.png)",
        "",
        "### Formal against empirical",
        "",
        md_table(
            [
                "model",
                "scenario",
                "grid",
                "sigma (um)",
                "beta (mm)",
                "trials",
                "not converged",
                "dof",
                "ellipse cov. (known sigma)",
                "ellipse cov. (s0, F)",
                "chi2 false alarm",
                "E[s0]/sigma",
                "c4",
                "b cov.",
                "beta cov.",
            ],
            [
                [
                    c["model"][i],
                    c["scenario"][i],
                    c["grid"][i],
                    fmt(c["sigma_um"][i]),
                    fmt(c["beta_mm"][i]),
                    c["trials"][i],
                    c["nonconverged"][i],
                    c["dof"][i],
                    fmt(c["coverage_known"][i]),
                    fmt(c["coverage_f"][i]),
                    fmt(c["false_alarm"][i]),
                    fmt(c["s0_ratio"][i]),
                    fmt(c["s0_expected"][i]),
                    fmt(c["b_coverage"][i]),
                    fmt(c["beta_coverage"][i]),
                ]
                for i in range(len(c["model"]))
            ],
        ),
        "",
        f"![coverage]({name}/coverage.png)",
        "",
        "### Bayesian cross-check (emcee)",
        "",
        "One simulated plate of the paper's design; the point coordinates are marginalised "
        "analytically (Laplace), the 7 globals sampled with flat priors by "
        f"{cfg['bayes.chains']} independent ensembles (run in parallel). Each number carries its "
        "Monte-Carlo standard error from the integrated autocorrelation time, so the verdicts "
        "do not change with the BLAS's last bits; `make verify` compares these columns with "
        "tolerances of that size.",
        "",
        md_table(
            [
                "parameter",
                "LS sigma (mm)",
                "posterior sigma (mm)",
                "ratio",
                "MC s.e.",
                "spread over chains",
                "tau (steps)",
                "N_eff",
            ],
            [
                [p, fmt(a), fmt(s), fmt(r), fmt(se), fmt(sp), fmt(t), fmt(n)]
                for p, a, s, r, se, sp, t, n in zip(
                    by["param"],
                    by["ls_sigma_mm"],
                    by["post_sigma_mm"],
                    by["ratio"],
                    by["ratio_se"],
                    by["ratio_chain_spread"],
                    by["tau_steps"],
                    by["n_eff"],
                )
            ],
        ),
        "",
        f"Acceptance {fmt(by['acceptance'][0])}; largest correlation difference "
        f"{fmt(by['max_abs_corr_diff'][0])}.",
        "",
        f"![corner plot]({name}/corner.png)",
    ]
    if (out / "bayes_twoplate.parquet").is_file():
        tp = _t(out, "bayes_twoplate.parquet")
        txt += [
            "",
            "**Two-plate calibration (seed 001): variance components.** One simulated "
            "calibration of `gridplate_two_plates` (its defaults), the true grid coordinates "
            "integrated out exactly. Posterior of sigma_c^2 / sigma_g^2 (= P_cx / P_x):",
            "",
            md_table(
                [
                    "prior",
                    "2.5 %",
                    "median",
                    "97.5 %",
                    "width (decades)",
                    "MC s.e.",
                    "sigma_c (um)",
                    "sigma_g (um)",
                    "tau max",
                    "N_eff",
                    "re-weighting",
                    "truth",
                ],
                [
                    [
                        tp["prior"][i],
                        fmt(tp["rho_q025"][i]),
                        fmt(tp["rho_median"][i]),
                        fmt(tp["rho_q975"][i]),
                        fmt(tp["log10_width"][i]),
                        fmt(tp["log10_width_se"][i]),
                        fmt(tp["sigma_c_median_um"][i]),
                        fmt(tp["sigma_g_median_um"][i]),
                        fmt(tp["tau_max"][i]),
                        fmt(tp["n_eff"][i]),
                        fmt(tp["rw_ratio_mean"][i]),
                        fmt(tp["true_ratio"][i]),
                    ]
                    for i in range(len(tp["prior"]))
                ],
            ),
            "",
            f"![two-plate ratio]({name}/twoplate_ratio.png)",
        ]
    return "\n".join(txt)
