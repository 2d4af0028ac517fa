"""The run of study ``brown_design`` (seed ``004``, Brown 1968): every part through the runner,
its Parquet files and figures, the claims scored from the claim book.

Parts and chunk streams (``spawn_key = (part, chunk)``): 0 the Monte-Carlo check of the
paper's design; 10-20 the error budget (adaptive); 30-50 coverage; 60-72 emcee (one chain per
chunk); 90-93 the linearised plates of the external comparisons.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.claims.intervals import bootstrap_ci
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm
from sim.mc import tolerance as tl
from sim.mc.runner import chunk_rng
from sim.mc.storage import provenance, write_table
from sim.mc.workunits import DESIGN_UNITS
from sim.report.plotting import draw
from sim.studies import RunContext
from sim.studies.design import figures
from sim.studies.design import region as DR
from sim.studies.design.cells import (
    design_cells,
    measuring_time,
    pareto_front,
    plate_setup,
    range_sigma,
    within_front,
)
from sim.studies.design.checks import max_offset_mm
from sim.studies.design.chunks import design_chunk
from sim.studies.design.claims import load_book, score_all
from sim.studies.design.dilution import datum_analysis
from sim.studies.design.errbudget import budget_analysis
from sim.studies.design.external import external_at
from sim.studies.design.formal import coverage_analysis
from sim.studies.design.parts import side_by_side
from sim.studies.design.posterior import bayes_analysis, twoplate_analysis
from sim.studies.design.schema import SCHEMA, datum_geometry
from sim.studies.run_steps import run_part

__all__ = ["run"]


def _design(cfg, cols):
    cost, acc = np.array(cols["time_min"]), np.array(cols["worst_sigma_um"])
    ok = np.array(cols["feasible"])
    jp = int(np.flatnonzero(cols["paper_design"])[0])
    same = ok & np.isclose(np.array(cols["setting_sigma_um"]), cfg["paper.setting_sigma_um"])
    same_n = (
        same
        & (np.array(cols["n_points"]) == cols["n_points"][jp])
        & np.isclose(np.array(cols["extent_mm"]), cols["extent_mm"][jp])
    )
    better = np.flatnonzero(same_n & (cost <= cost[jp] + 1e-9) & (acc < acc[jp] - 1e-12))
    b = int(better[np.argmin(acc[better])]) if len(better) else jp
    return {
        "brown.design.paper_on_pareto_front": (
            float(cols["pareto"][jp]),
            (
                f"on the front of worst-point sigma against time over {int(ok.sum())} feasible of "
                f"{len(ok)} cells: 1 = yes; worst sigma {within_front(cost, acc, ok, jp):.3f} x the "
                "best available at no more time"
            ),
        ),
        "brown.design.paper_on_front_same_setting_sigma": (
            float(pareto_front(cost, acc, same)[jp]),
            (
                f"among the {int(same.sum())} feasible cells with the paper's setting sigma: worst "
                f"sigma {within_front(cost, acc, same, jp):.3f} x the best at no more time"
            ),
        ),
        "brown.design.paper_on_front_same_points": (
            float(pareto_front(cost, acc, same_n)[jp]),
            (
                f"among the {int(same_n.sum())} feasible cells with the paper's setting sigma and "
                f"its {cols['n_points'][jp]} points: worst sigma "
                f"{within_front(cost, acc, same_n, jp):.3f} x the best at no more time (best: P = "
                f"{cols['positions'][b]}, offset {cols['offset_mm'][b]:g} mm, {cols['settings'][b]} "
                f"settings, {cost[b]:.0f} min, {acc[b]:.3f} um)"
            ),
        ),
        "brown.design.paper_worst_sigma_um": (
            acc[jp],
            (
                f"analytic worst-point sigma of the paper's design (pivot model, inner datum over "
                f"the points, range sigma {cols['range_sigma_um'][jp]:.2f} um); mean "
                f"{cols['mean_sigma_um'][jp]:.3f} um"
            ),
        ),
        **_scale_length(cfg),
    }


def _scale_length(cfg) -> dict:
    """The largest station offsets the scale plus micrometer allow (values with notes)."""
    ext_d = (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2
    return {
        "brown.design.max_offset_paper_grid_mm": (
            max_offset_mm(cfg, cfg["paper.extent_mm"]),
            (
                f"largest station offset with every range of a +-{cfg['paper.extent_mm']:g} mm grid "
                "on the scale plus micrometer"
            ),
        ),
        "brown.design.max_offset_dilution_grid_mm": (
            max_offset_mm(cfg, ext_d),
            (
                f"the same for {datum_geometry(cfg)} +-{ext_d:g} mm grid (its station offset is "
                f"{cfg['datum.offset_mm']:g} mm)"
            ),
        ),
    }


def _mc_check(cfg, pts, th, sr, ctx):
    fn = partial(design_chunk, pts, th, sr)
    sim = run_part(cfg, ctx, fn, part=0, label="design MC", units=DESIGN_UNITS["check"])
    good = sim["status"] == 0
    E = sim["err_um"][good]
    Fan = (
        dm.s_transform(
            po.full_point_covariance(pts[None], th[None], "pivot", "inner"), dm.inner(pts)
        )[0]
        * sr**2
    )
    an2 = np.diag(Fan)
    v, ci = bootstrap_ci(
        lambda a: np.sqrt(a.var(0, ddof=1).mean() / an2.mean()),
        E,
        chunk_rng(cfg["seed"], 98, 0),
        n_boot=200,
    )
    return (
        v,
        ci,
        (
            f"pooled MC sigma / analytic sigma over {an2.size} coordinates of the paper's "
            f"design, P-position solver, inner datum; {int(good.sum())} converged of "
            f"{len(good)} trials; bootstrap interval"
        ),
    )


def _tolerances(R: dict) -> dict:
    """How ``make verify`` compares the emcee tables (:mod:`sim.mc.tolerance`): chain output
    within its Monte-Carlo interval, a relative half-width from the chains' own standard
    errors; the claims' values are compared by their rows' intervals (``claims.parquet``)."""
    by = R["bayes"]
    rel = max(4 * se / v for v, se, _, _ in by["ratio"].values())
    v, se, _, _ = by["max_corr_diff"]
    bay = {
        "post_mean": 1e-3,
        "post_sigma_mm": rel,
        "ratio": rel,
        "ratio_se": 0.5,
        "ratio_chain_spread": 1.0,
        "tau_steps": 0.5,
        "n_eff": 0.5,
        "acceptance": 0.05,
        "max_abs_corr_diff": 4 * se / max(v, 1e-12),
    }
    tol = {"bayes.parquet": bay}
    tp = R.get("twoplate")
    if tp is not None:
        f = tp["prior"].index("flat")
        w_rel = 4 * tp["chain_log10_width_se"][f] / tp["chain_log10_width"][f]
        s_rel = float(np.expm1(4 * np.log(10) * tp["chain_log10_width_se"][f]))  # chain sigmas
        # the quadrature's quantiles: deterministic to its error (decades; ratios relative)
        q_rel = float(np.expm1(4 * np.log(10) * max(tp["quad_err"])))
        tol["bayes_twoplate.parquet"] = {c: q_rel for c in ("rho_q025", "rho_median", "rho_q975")}
        tol["bayes_twoplate.parquet"].update(
            {
                "log10_width": 4 * max(tp["quad_err"]) / min(tp["log10_width"]),
                "quad_err": 1.0,
                "chain_log10_width": w_rel,
                "chain_log10_width_se": 0.5,
                "chain_tau": 0.5,
                "tau_max": 0.5,
                "n_eff": 0.5,
                "sigma_c_median_um": s_rel,
                "sigma_g_median_um": s_rel,
            }
        )
    return {f: {c: tl.chain(rtol=r) for c, r in t.items()} for f, t in tol.items()}


def _unbounded_as_null(row: dict) -> dict:
    """An open side of a bound's decision zone (+-inf) is stored as null: tables refuse
    infinities (:func:`sim.mc.storage.check_finite_table`)."""
    for k in ("zone_low", "zone_high"):
        if isinstance(row[k], float) and np.isinf(row[k]):
            row[k] = float("nan")
    return row


def _paper_plate(cfg: dict):
    """The paper's design: points and globals (mm) and its range sigma (um)."""
    pts, th = plate_setup(
        cfg,
        cfg["paper.positions"],
        cfg["paper.grid"],
        cfg["paper.extent_mm"],
        cfg["paper.offset_mm"],
        cfg["paper.beta_mm"],
    )
    sr = float(
        range_sigma(
            cfg["paper.setting_sigma_um"], cfg["paper.settings"], cfg["comparator.sigma_um"]
        )
    )
    return pts, th, sr


def _datum(cfg: dict, out: Path, prov: dict, figs) -> dict:
    """3. The datum of the dilution (analytic): ``datum.parquet`` and its figure."""
    dcols, dr = datum_analysis(cfg)
    dr["geometry"] = (
        f"{cfg['datum.grid']}x{cfg['datum.grid']} points at "
        f"{cfg['datum.spacing_mm']:g} mm, stations "
        f"{cfg['datum.offset_mm']:g} mm out"
    )
    write_table(out / "datum.parquet", dcols, prov)
    figs("datum", cfg, dcols)
    return dr


def _mc_parts(cfg: dict, out: Path, prov: dict, ctx: RunContext, figs, plate) -> dict:
    """The Monte-Carlo parts, side by side on the workers (:mod:`.parts`); each writes its
    table and sends its figures as soon as it is done."""
    pts, th, sr = plate

    def budget():  # 2. error budget (adaptive, through the runner)
        bcols, sims = budget_analysis(cfg, pts, th, ctx)
        write_table(out / "budget.parquet", bcols, prov)
        figs("budget", bcols)
        return bcols, sims

    def coverage():  # 4. coverage
        ccols = coverage_analysis(cfg, ctx)
        write_table(out / "coverage.parquet", ccols, prov)
        figs("coverage", ccols)
        return ccols

    def bayes():  # 5. emcee
        bycols, vals, samples = bayes_analysis(cfg, pts, sr, ctx)
        figs("bayes", samples, vals)
        return bycols, vals

    def twoplate():
        tcols, _, tsamples, why = twoplate_analysis(cfg, ctx)
        figs("twoplate", tcols, tsamples)
        return tcols, why

    return side_by_side(
        {  # the error budget first: its adaptive stages tell the bar the trials they need
            "budget": budget,
            "bayes": bayes,
            "twoplate": twoplate,
            "coverage": coverage,
            "mc": lambda: _mc_check(cfg, pts, th, sr, ctx),
        },
        ctx,
    )


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    """Every part of ``brown_design``: tables, figures and the scored claims under ``out``."""
    prov = provenance(cfg)
    book = load_book()
    R: dict = {}

    def figs(stage, *data):  # each stage's figures, as soon as its tables exist
        draw(figures.figure_jobs(stage, out, *data))

    # 1. design trade-off (analytic) and its Monte-Carlo check
    with ctx.doing("design grid"):
        cols = design_cells(cfg)
        write_table(out / "design.parquet", cols, prov)
        figs("design", cols)
    # the unprinted inputs explored jointly (.region): the tolerances analytic, the external
    # comparisons on a small design of plates
    with ctx.doing("tolerance region"):
        tolerances = DR.tolerance_region(cfg, book)
    with ctx.doing("plate region"):
        parts = {"tolerances": tolerances, "plates": DR.plates_region(cfg, book)}
        region_rows, region_table, region_inputs = DR.region_rows(book, parts, cfg)
    R["design"] = _design(cfg, cols)
    R["time"] = (
        measuring_time(cfg, 4, cfg["time.images"], 1),
        measuring_time(cfg, 4, cfg["time.images"], 2),
    )
    plate = _paper_plate(cfg)
    R["datum"] = _datum(cfg, out, prov, figs)
    done = _mc_parts(cfg, out, prov, ctx, figs, plate)
    R["mc_ratio"] = done["mc"]
    R["budget"], R["budget_sims"] = done["budget"]
    R["coverage"] = done["coverage"]
    bycols, R["bayes"] = done["bayes"]
    tcols, why = done["twoplate"]
    R["twoplate"] = tcols
    # 6. external comparisons at the configured inputs
    R["external"] = external_at(
        cfg,
        cfg["paper.offset_mm"],
        cfg["paper.beta_mm"],
        cfg["zeiss.half_extent_mm"],
        cfg["budget.pitch_mm"],
    )
    rows = [_unbounded_as_null(r) for r in region_rows + score_all(book, cfg, R)]
    tols = _tolerances(R)
    write_table(out / "bayes.parquet", bycols, prov, tols["bayes.parquet"])
    if tcols is not None:
        write_table(out / "bayes_twoplate.parquet", tcols, prov, tols["bayes_twoplate.parquet"])
    else:
        print(f"brown_design: bayes.twoplate_ratio skipped: {why}")
    write_table(out / "consistent_region.parquet", region_table, prov)
    write_table(out / "region_inputs.parquet", region_inputs, prov)
    write_claims(out / "claims.parquet", rows, prov, book, SCHEMA)
