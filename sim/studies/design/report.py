"""Report section of study ``brown_design`` (seed ``004``, Brown 1968): built from the study's
Parquet files and its claim book only, never from live model code, on the shared skeleton
:mod:`sim.report.section`. Every number and verdict in the prose is read from those files;
lengths in mm, sigmas in um, times in minutes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.instruments.ranges import brown as B
from sim.report.section import config, figure, region_lead, section, table
from sim.report.tables import fmt, md_table
from sim.studies.design.schema import SCHEMA, datum_geometry

__all__ = ["report"]


def _datum_findings(V, VH, feas_note, whose: str):
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
        f"Brown's datum the `stations` dilution of {whose} geometry is "
        f"{bl:.1f}-{bh:.1f} %; after the S-transformation to inner constraints over the points "
        f"it is {il:.1f}-{ih:.1f} %, after a similarity onto the four corners {cl:.1f}-{ch:.1f} %. "
        f"So {100 * (1 - ih / bh):.0f} % of the largest and {100 * (1 - il / bl):.0f} % of the "
        "smallest dilution belong to the station-defined datum (the station estimates' errors "
        "carried into every point as a translation and rotation), not to the precision of the "
        "point configuration. For `pivot` the inner-constraint dilution is "
        f"{pil:.1f}-{pih:.1f} % and the corner-similarity one {pcl:.1f}-{pch:.1f} %: a "
        f"similarity removes most of beta's extra, scale-like dilution.{feas_note}"
    )


#: the predictions of the region, in words
_WHAT = (
    "The tolerances and external comparisons that depend on the unprinted station offset, "
    "beta, the plate's closure (sigma0), screw pitch, Zeiss layout and the error of the "
    "two-screw comparator compared with"
)


def _lead(out: Path, cfg: dict) -> list[str]:
    """The region lead (two parts: the tolerances analytic on a refined design, the plate
    comparisons with simulated plates where Table 1 holds) and what bounds the region."""
    return [
        region_lead(
            out,
            _WHAT,
            design="per part a Sobol design (`tolerances` refined at the boundaries, `plates` not)",
            values=f"`tolerances` every value analytic, `plates` {cfg['unprinted.plates']} "
            "simulated plates per input vector that Table 1's statements leave in the region, "
            "whose noise enters the decision",
        ),
        f"The comparator bounds the region: {_scale_words(cfg)} must read Table 1's plate, "
        "and the Zeiss points for the Zeiss rows (figure: brown_table1's region). The "
        "tolerances and the plate comparisons are the built comparator's, the instrument "
        "that measured Table 1, so both parts also ask Table 1's printed statements to hold "
        "(closure 1.6 um, 80 % of the sigmas in 1.1-1.3 um, two points at 1.5 um, all below "
        "the closure): they are decided where Table 1 puts the stations (fifth reading), and "
        "the plates are drawn with each point's closure sigma0 as their range sigma.",
    ]


def _scale_words(cfg: dict) -> str:
    """The scale the region's hardware statement reads: the built comparator's 261 + 1 mm
    (:mod:`sim.instruments.ranges.brown`), whatever ``scale.*`` says; said so where the run's
    scale differs (it bounds the design trade-off only)."""
    paper = f"{B.SCALE_MM:g} + {B.MICROMETER_MM:g} mm scale"
    run = (cfg["scale.graduated_mm"], cfg["scale.micrometer_mm"])
    if run == (B.SCALE_MM, B.MICROMETER_MM):
        return f"its {paper}"
    return (
        f"the paper's {paper} (the built comparator's, whatever scale.graduated_mm and "
        f"scale.micrometer_mm say: this run's {run[0]:g} + {run[1]:g} mm bounds the design "
        "trade-off only)"
    )


def _time_words(cfg: dict) -> str:
    """The measuring times the trade-off is scaled to (``time.*``), the paper's or the run's."""
    keys = ("time.single_min", "time.double_min", "time.images")
    words = "{:g} and {:g} minutes for {:g} images"
    run = words.format(*(cfg[k] for k in keys))
    paper = words.format(*(SCHEMA[k].default for k in keys))
    return f"the paper's {paper}" if run == paper else f"{run} (the paper's: {paper})"


_INTRO = (
    "The questions Brown answered by simulation before building the comparator, asked "
    "systematically, and the printed numbers of his *Operation*, *Calibration* and "
    "*Results* sections. Accuracies are in a datum that does not lean on the stations "
    "(inner constraints over the measured points) unless stated."
)


def _findings(out: Path, cfg: dict) -> str:
    """The findings bullets: datum of the dilution, scale length, design, error budget."""
    cl = table(out, "claims.parquet")
    V = dict(zip(cl["claim"], cl["value"]))
    VH = dict(zip(cl["claim"], cl["value_high"]))
    N = dict(zip(cl["claim"], cl["note"]))
    b = table(out, "budget.parquet")
    bud = dict(zip(b["source"], b["rms_um"]))
    feas_note = (
        ""
        if all(table(out, "datum.parquet")["feasible"])
        else " (That geometry is *idealised*: its longest "
        "range does not fit on the scale plus micrometer; the rows are findings.)"
    )
    bullets = [
        _datum_findings(V, VH, feas_note, datum_geometry(cfg)),
        f"* *Scale length.* With every range on the scale plus micrometer the stations can stand "
        f"at most {fmt(V.get('brown.design.max_offset_paper_grid_mm'))} mm outside the midsides "
        f"for Table 1's grid and {fmt(V.get('brown.design.max_offset_dilution_grid_mm'))} mm "
        f"for {datum_geometry(cfg)} grid. Verdicts use feasible designs only.",
        f"* *Design.* {N.get('brown.design.paper_on_front_same_points', '')}.",
        f"* *Error budget.* Setting error alone {fmt(bud.get('setting'))} um rms after a rigid "
        f"fit; calibrated scale {fmt(bud.get('scale'))} um, uncalibrated scale at its "
        f"specification {fmt(bud.get('scale_spec'))} um, calibrated screw {fmt(bud.get('screw'))} "
        f"um, uncorrected drum {fmt(bud.get('drum_periodic'))} um, 3 kg wobble "
        f"{fmt(bud.get('wobble_3kg'))} um (as a first harmonic {fmt(bud.get('wobble_3kg_h1'))} um: "
        f"absorbed by the stations), ball sphericity {fmt(bud.get('sphericity'))} um.",
    ]
    return "**Findings.**\n\n" + "\n".join(bullets)


def _columns(t: dict, cols: tuple, index) -> list[list]:
    """Rows of ``t`` at ``index``: integer columns as they are, the others through ``fmt``
    (a column name prefixed ``=`` is taken as it is)."""
    return [[t[c[1:]][i] if c.startswith("=") else fmt(t[c][i]) for c in cols] for i in index]


_DESIGN_COLS = {
    "P": "=positions",
    "grid": "=grid",
    "extent (mm)": "extent_mm",
    "offset (mm)": "offset_mm",
    "beta (mm)": "beta_mm",
    "settings": "=settings",
    "setting sigma (um)": "setting_sigma_um",
    "time (min)": "time_min",
    "worst sigma (um)": "worst_sigma_um",
    "mean sigma (um)": "mean_sigma_um",
}


def _tradeoff(out: Path, cfg: dict) -> list[str]:
    """The design trade-off: feasible cells, the Pareto front, the paper's design."""
    d = table(out, "design.parquet")
    ok = np.array(d["feasible"])
    reasons: dict[str, int] = {}
    for r in np.array(d["reason"])[~ok]:
        for part in r.split("; "):
            key = " ".join(part.split(" ")[:2])
            reasons[key] = reasons.get(key, 0) + 1
    pf = np.flatnonzero(d["pareto"])
    pf = pf[np.argsort(np.array(d["time_min"])[pf])]
    jp = int(np.flatnonzero(d["paper_design"])[0])
    return [
        "### Design trade-off",
        f"{len(ok)} cells, {int(ok.sum())} feasible; infeasible cells stay in `design.parquet` "
        "with the reason (" + ", ".join(f"{k}: {v}" for k, v in reasons.items()) + "). "
        f"Measuring time: {_time_words(cfg)}, with "
        f"{fmt(cfg['time.pass_min'])} min per plate position (not printed; a labelled example).",
        md_table(list(_DESIGN_COLS), _columns(d, tuple(_DESIGN_COLS.values()), pf)),
        f"The paper's design: {fmt(d['time_min'][jp])} min, worst sigma "
        f"{fmt(d['worst_sigma_um'][jp])} um, mean {fmt(d['mean_sigma_um'][jp])} um.",
        figure(out, "pareto.png", "Pareto front"),
    ]


def _budget(out: Path, cfg: dict) -> list[str]:
    """The error budget of the comparator (``budget.parquet``)."""
    b = table(out, "budget.parquet")
    cols = ("=source", "=description", "rms_um", "se_um", "=trials", "s0_um")
    return [
        "### Error budget of the comparator",
        "Each source alone on the Table-1 plate (pivot model), coordinate errors after a rigid "
        "fit over all points; adaptive trial counts through the runner (target standard error "
        f"{fmt(cfg['budget.target_se_um'])} um).",
        md_table(
            ["source", "what", "rms (um)", "MC s.e. (um)", "trials", "rms sigma0 (um)"],
            _columns(b, cols, range(len(b["source"]))),
        ),
        figure(out, "budget.png", "error budget"),
        "### Datum",
        "Brown's datum is x1 = x3 = 0, y4 = -y2 (the stations); `invariant` rows use the "
        "S-transformation to inner constraints over the points, `corners` a similarity onto the "
        "four corner points.",
        figure(out, "datum.png", "datum"),
    ]


_COVERAGE_COLS = {
    "model": "=model",
    "scenario": "=scenario",
    "grid": "=grid",
    "sigma (um)": "sigma_um",
    "beta (mm)": "beta_mm",
    "trials": "=trials",
    "not converged": "=nonconverged",
    "dof": "=dof",
    "ellipse cov. (known sigma)": "coverage_known",
    "ellipse cov. (s0, F)": "coverage_f",
    "chi2 false alarm": "false_alarm",
    "E[s0]/sigma": "s0_ratio",
    "c4": "s0_expected",
    "b cov.": "b_coverage",
    "beta cov.": "beta_coverage",
    "note": "=note",
}


def _coverage(out: Path) -> list[str]:
    """Formal against empirical coverage (``coverage.parquet``)."""
    c = table(out, "coverage.parquet")
    # results written before the note column (an older version's run) have none to show
    cols = {h: k for h, k in _COVERAGE_COLS.items() if k != "=note" or "note" in c}
    return [
        "### Formal against empirical",
        md_table(list(cols), _columns(c, tuple(cols.values()), range(len(c["model"])))),
        figure(out, "coverage.png", "coverage"),
    ]


_BAYES_COLS = {
    "parameter": "=param",
    "LS sigma (mm)": "ls_sigma_mm",
    "posterior sigma (mm)": "post_sigma_mm",
    "ratio": "ratio",
    "MC s.e.": "ratio_se",
    "spread over chains": "ratio_chain_spread",
    "tau (steps)": "tau_steps",
    "N_eff": "n_eff",
}


def _bayes(out: Path, cfg: dict) -> list[str]:
    """The emcee cross-check (``bayes.parquet``)."""
    by = table(out, "bayes.parquet")
    return [
        "### Bayesian cross-check (emcee)",
        "One simulated plate of the paper's design; the point coordinates are marginalised "
        "analytically (Laplace), the 7 globals sampled with flat priors by "
        f"{cfg['bayes.chains']} independent ensembles (run in parallel). Each number carries its "
        "Monte-Carlo standard error from the integrated autocorrelation time, so the verdicts "
        "do not change with the BLAS's last bits; `make verify` compares these columns with "
        "tolerances of that size. That error rests on tau, which a short chain underestimates: "
        "the self-checks are decided only on chains of at least 50 tau (emcee's rule; "
        "docs/verdict-rules.md), otherwise inconclusive.",
        md_table(
            list(_BAYES_COLS), _columns(by, tuple(_BAYES_COLS.values()), range(len(by["param"])))
        ),
        f"Acceptance {fmt(by['acceptance'][0])}; largest correlation difference "
        f"{fmt(by['max_abs_corr_diff'][0])}.",
        figure(out, "corner.png", "corner plot"),
    ]


_TWOPLATE_COLS = {
    "prior": "=prior",
    "2.5 %": "rho_q025",
    "median": "rho_median",
    "97.5 %": "rho_q975",
    "width (decades)": "log10_width",
    "quadrature error": "quad_err",
    "chain width": "chain_log10_width",
    "chain length (tau)": "chain_tau",
    "sigma_c (um)": "sigma_c_median_um",
    "sigma_g (um)": "sigma_g_median_um",
    "tau max": "tau_max",
    "N_eff": "n_eff",
    "re-weighting": "rw_ratio_mean",
    "truth": "true_ratio",
}


def _twoplate(out: Path) -> list[str]:
    """The two-plate variance components (``bayes_twoplate.parquet``, if the part ran)."""
    if not (out / "bayes_twoplate.parquet").is_file():
        return []
    tp = table(out, "bayes_twoplate.parquet")
    return [
        "**Two-plate calibration (seed 001): variance components.** One simulated "
        "calibration of `gridplate_two_plates` (its defaults), the true grid coordinates "
        "integrated out exactly. Posterior of sigma_c^2 / sigma_g^2 (= P_cx / P_x), its "
        "quantiles by quadrature; the emcee chains' width and length (in autocorrelation "
        "times) beside them as the cross-check:",
        md_table(
            list(_TWOPLATE_COLS),
            _columns(tp, tuple(_TWOPLATE_COLS.values()), range(len(tp["prior"]))),
        ),
        figure(out, "twoplate_ratio.png", "two-plate ratio"),
    ]


def report(out: Path) -> str:
    """The section of ``brown_design``: the region, the findings, the claims, then one
    subsection per part (trade-off, budget, datum, coverage, emcee, two plates)."""
    out = Path(out)
    cfg = config(out)["config"]
    return section(
        out,
        lead=_lead(out, cfg),
        intro=[_INTRO, _findings(out, cfg)],
        schema=SCHEMA,
        body=[
            *_tradeoff(out, cfg),
            *_budget(out, cfg),
            *_coverage(out),
            *_bayes(out, cfg),
            *_twoplate(out),
        ],
    )
