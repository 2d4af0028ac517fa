"""Run of ``gridplate_two_plates``: the chunks through the runner, tables, figures, claims and
the sweep of the unprinted inputs."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.claims.book_region import write_region
from sim.claims.intervals import spread
from sim.lsq import distributions as D
from sim.mc.gridplate_size import gridplate_units
from sim.mc.runner import chunk_rng
from sim.mc.storage import provenance, write_table
from sim.report.plotting import draw
from sim.report.region import fig_region
from sim.studies import RunContext
from sim.studies.gridplate import figures as F
from sim.studies.gridplate.beyond import beyond_table
from sim.studies.gridplate.claims import score
from sim.studies.gridplate.model import PARAMS, chunk, simulate
from sim.studies.gridplate.region import IT, explore_region, iteration_note, nominal, plates_basis
from sim.studies.gridplate.schema import SCHEMA
from sim.studies.run_steps import over_region, run_part, spread_note


def analytic_reject(cfg: dict, stated_um: float, dof: int) -> float:
    """Rejection rate of the two-sided test when the grid sigma is stated wrongly:
    ``dof s0^2 / sigma_x'^2 ~ c chi2(dof)``, ``c = (sx^2 + sg_true^2) / (sx^2 + sg_stated^2)``."""
    sx, st = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    c = (sx**2 + st**2) / (sx**2 + stated_um**2)
    a = cfg["analysis.alpha"]
    lo, hi = D.chi2_ppf(a / 2, dof), D.chi2_ppf(1 - a / 2, dof)
    return float(D.chi2_cdf(lo / c, dof) + D.chi2_sf(hi / c, dof))


def decide_over_region(
    cfg: dict, book, rows: list[dict], out: Path, prov, gn_iterations: np.ndarray
) -> list[dict]:
    """Explore the unprinted inputs jointly (``region.toml``), write ``consistent_region.parquet``
    and its figure, and replace each prediction's row by its verdict over the region (the
    configured inputs' result kept in the note as an example; for the iterations, the run's
    counts ``gn_iterations``)."""
    region, preds = explore_region(
        cfg, book, chunk_rng(cfg["region.seed"], 900, 0), chunk_rng(cfg["region.seed"], 901, 0)
    )
    write_region(out / "consistent_region.parquet", region, book, preds, prov)
    fig_region(
        region,
        out / "consistent_region.png",
        title="seed 001: unprinted inputs left by the printed statements",
        nominal=nominal(cfg),
        boundary={
            ("grid_points_1", "spacing_mm"): lambda g: 230.0 / np.maximum(np.round(g) - 1, 1)
        },
    )
    spread = spread_note("calibrations")
    it_note = iteration_note(cfg, region, np.asarray(gn_iterations))

    def note(row: dict) -> str:
        return it_note if row["claim"] == IT else spread(row)

    basis = plates_basis(cfg, book)  # off the paper's two plates: what the region rests on
    return [
        {**r, "note": basis + r["note"]} if basis and r["claim"] in preds else r
        for r in over_region(book, region, preds, rows, note)
    ]


def trials_table(res: dict) -> dict[str, np.ndarray]:
    """``trials.parquet``: one row per calibration, the per-trial arrays (a column per plate
    or adjustment ``<name>_<k>`` where an array has more than one)."""
    T = res["sim_sigma_um"].shape[0]
    cols = {"trial": np.arange(T)}
    for k, v in res.items():
        v = np.asarray(v)
        if v.shape[0] != T:
            continue
        if v.ndim == 1:
            cols[k] = v
        else:
            for p in range(v.shape[1]):
                cols[f"{k}_{p + 1}"] = v[:, p]
    return cols


def coverage_table(res: dict, ratios: list) -> dict[str, np.ndarray]:
    """``coverage.parquet``: coverage of the nominal 95 % intervals of S, S', eps per swept
    weight ratio (a-priori and a-posteriori sigma), and with the grid fixed."""
    cov = {"ratio": np.asarray(ratios)}
    for k in PARAMS:
        for tag in ("pri", "post"):
            cov[f"{k}_{tag}"] = np.array(
                [res[f"{k}_cov_w{tag}_r{j}"].mean() for j in range(len(ratios))]
            )
            cov[f"{k}_fixed_{tag}"] = np.full(len(ratios), res[f"{k}_cov_fixed_{tag}"].mean())
    return cov


def implied_table(res: dict, ratios: list) -> dict[str, list]:
    """``implied_grid.parquet``: the grid sigma implied by each weight ratio (um), median and
    the 2.5-97.5 % spread over calibrations."""
    imp = {"ratio": np.asarray(ratios), "median": [], "lo": [], "hi": []}
    for j in range(len(ratios)):
        m, (lo, hi) = spread(res[f"implied_grid_um_r{j}"])
        imp["median"].append(m)
        imp["lo"].append(lo)
        imp["hi"].append(hi)
    return imp


def chi2_table(cfg: dict, res: dict) -> dict[str, list]:
    """``chi2_power.parquet``: rejection rate of the chi-square test per stated grid sigma,
    its Wilson interval, the analytic rate and the number of tests."""
    dof = cfg["plate.grid"] ** 2 - 3
    ch = {
        "stated_um": np.asarray(cfg["analysis.stated_sigmas_um"]),
        "reject": [],
        "lo": [],
        "hi": [],
        "analytic": [],
        "tests": [],
    }
    for j, st in enumerate(cfg["analysis.stated_sigmas_um"]):
        x = res[f"reject_s{j}"].ravel()
        lo, hi = D.wilson_ci(int(x.sum()), x.size, 0.95)
        for col, v in (
            ("reject", x.mean()),
            ("lo", lo),
            ("hi", hi),
            ("analytic", analytic_reject(cfg, st, dof)),
            ("tests", x.size),
        ):
            ch[col].append(v)
    return ch


def true_ratio(cfg: dict) -> tuple[float, int]:
    """The true weight ratio ``sx'^2 / sg^2`` and the index of the swept ratio nearest it
    (the largest when the grid is error-free)."""
    ratios = list(cfg["analysis.ratios"])
    sx, sgt = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    ratio_true = sx**2 / sgt**2 if sgt > 0 else np.inf
    j_true = (
        int(np.argmin(np.abs(np.log(np.asarray(ratios) / ratio_true))))
        if np.isfinite(ratio_true)
        else int(np.argmax(ratios))
    )
    return ratio_true, j_true


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    """The calibrations through the runner, their tables and figures, the claims at the
    configured inputs, then the predictions over the region (``claims.parquet``)."""
    per, region = gridplate_units(cfg)  # the bar: the trials' work, then the region's
    res = run_part(cfg, ctx, partial(chunk, cfg), part=0, label="gridplate", units=per)
    prov = provenance(cfg)
    ratios = list(cfg["analysis.ratios"])
    ratio_true, j_true = true_ratio(cfg)
    write_table(out / "trials.parquet", trials_table(res), prov)
    write_table(
        out / "adjustments_sample.parquet",
        {k: np.asarray(res[k]) for k in ("gn_iterations", "closed_form_rel", "passes_rw")},
        prov,
    )
    cov, imp, ch = coverage_table(res, ratios), implied_table(res, ratios), chi2_table(cfg, res)
    beyond = beyond_table(res, ratios, j_true)
    for name, t in (
        ("coverage", cov),
        ("implied_grid", imp),
        ("chi2_power", ch),
        ("beyond", beyond),
    ):
        write_table(out / f"{name}.parquet", t, prov)
    rows, book = score(cfg, res, beyond, {"j_true": j_true})
    paper = [(r, book.spec(f"twoplate.weight_ratio.grid_sigma_1to{r}_um")["ref"]) for r in (2, 3)]
    sgt, stated = cfg["grid.sigma_true_um"], cfg["grid.sigma_stated_um"]
    draw(
        [
            (F.fig_params, (cfg, res, out / "parameters.png")),
            (F.fig_coverage, (cov, ratio_true, out / "coverage.png")),
            (F.fig_chi2, (ch, sgt, out / "chi2_power.png")),
            (F.fig_implied, (imp, stated, paper, out / "implied_grid.png")),
        ]
    )
    with ctx.doing("region", region):
        rows = decide_over_region(cfg, book, rows, out, prov, res["gn_iterations"])
    ex = simulate(cfg, chunk_rng(cfg["seed"], 1, 0), 1)  # one calibration, its own stream
    write_table(
        out / "example_plate.parquet", F.fig_residuals(cfg, ex, out / "residuals.png"), prov
    )
    write_claims(out / "claims.parquet", rows, prov, book, SCHEMA)
