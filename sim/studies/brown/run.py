"""Runs of the two Brown studies: simulate, decide over the region of unprinted inputs, draw.

``run_dilution`` (the *Concept* section) and ``run_table1`` (the *Results* section) write
their Parquet files and figures into ``out``; the Monte Carlo goes through the runner
(chunk functions pickle), everything else is analytic and batched. Seed paper 004.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.mc.storage import provenance, write_table
from sim.report.plotting import draw
from sim.studies import RunContext
from sim.studies.brown import figures as F
from sim.studies.brown import region as RG
from sim.studies.brown import values as V
from sim.studies.brown.claims import load_book, score_dilution, score_table1
from sim.studies.brown.core import MC, analytic_sigma, points_table, run_mc
from sim.studies.brown.schema import (
    DILUTION,
    MODEL_NAMES,
    TABLE1,
    as_printed,
    range_sigma_um,
    setup,
)


def _common(cfg, ctx, **kw):
    pts, theta = setup(cfg)
    sr = range_sigma_um(cfg)
    an = {m: analytic_sigma(pts, theta, m, sr) for m in MODEL_NAMES}
    sim = run_mc(cfg, pts, theta, ctx, **kw)
    return pts, theta, sr, an, sim, MC(sim)


def _write_region(out, prov, book, reg, preds, verdicts, notes) -> list[dict]:
    """``consistent_region.parquet``, ``region_inputs.parquet``; the region's claim rows."""
    write_table(out / "consistent_region.parquet", RG.table_of(reg, preds), prov)
    write_table(out / "region_inputs.parquet", RG.inputs_table(reg, preds, verdicts), prov)
    return RG.rows_of(book, reg, preds, verdicts, notes)


def run_dilution(cfg: dict, out: Path, ctx: RunContext) -> None:
    pts, theta, sr, an, sim, mc = _common(cfg, ctx, shift_um=cfg["checks.bias_shift_um"])
    prov = provenance(cfg, range_sigma_um=sr)
    cols = points_table(pts, an, mc, sr)
    write_table(out / "points.parquet", cols, prov)

    ext = float(np.abs(pts).max())
    curve, extra = V.dilution_curve(
        cfg["plate.format_mm"], cfg["dilution.grids"], ext, cfg["comparator.station_offset_mm"]
    )
    mono = bool(V.monotone(curve)[0])
    ks = list(curve)
    write_table(
        out / "dilution_vs_points.parquet",
        {
            "grid": ks,
            "n_points": [k * k for k in ks],
            "dil_min_pct": [float(curve[k].min()) for k in ks],
            "dil_mean_pct": [float(curve[k].mean()) for k in ks],
            "dil_max_pct": [float(curve[k].max()) for k in ks],
            "pivot_extra_max_pct": [float(extra[k].max()) for k in ks],
        },
        prov,
    )
    unit = {m: an[m] / sr for m in MODEL_NAMES}
    draw(
        [
            (F.fig_dilution_points, (cfg, pts, theta, unit, out / "dilution_points.png")),
            (F.fig_sigma_maps, (cfg, pts, theta, out / "sigma_maps.png")),
            (F.fig_mc_vs_analytic, (cols, mc.N, out / "mc_vs_analytic.png")),
            (
                F.fig_dilution_vs_points,
                (out / "dilution_vs_points.parquet", out / "dilution_vs_points.png"),
            ),
        ]
    )

    book = load_book("brown_dilution")
    rows = score_dilution(book, cfg, pts, theta, unit, mc, sim, curve, extra, mono)
    reg, preds, verdicts = RG.concept_region(cfg, book)
    rows += _write_region(out, prov, book, reg, preds, verdicts, RG.CONCEPT_NOTES)
    write_claims(
        out / "claims.parquet", rows, prov, book, DILUTION, paper_design=RG.CONCEPT_ON_PAPER
    )
    F.fig_region(out, RG.CONCEPT_PAIRS, out / "consistent_region.png")


def run_table1(cfg: dict, out: Path, ctx: RunContext) -> None:
    pts, theta, sr, an, sim, mc = _common(cfg, ctx, table1=True)
    prov = provenance(cfg, range_sigma_um=sr)
    write_table(out / "points.parquet", points_table(pts, an, mc, sr), prov)
    ok = np.isfinite(sim["t1.sigma0_um"])  # converged pivot adjustments
    t1 = {
        k: sim[f"t1.{k}"][ok]
        for k in (
            "sigma0_um",
            "share_1p1_1p3",
            "max_sigma_um",
            "points_ge_1p45",
            "setting_sigma_um",
        )
    }
    write_table(
        out / "table1_trials.parquet",
        {
            "trial": np.flatnonzero(ok),
            "sigma0_um": t1["sigma0_um"],
            "share_sigma_1p1_1p3": t1["share_1p1_1p3"],
            "max_sigma_um": t1["max_sigma_um"],
            "points_sigma_ge_1p45": t1["points_ge_1p45"],
            "setting_sigma_est_um": t1["setting_sigma_um"],
        },
        prov,
    )
    book = load_book("brown_table1")
    rows = score_table1(book, cfg, pts, an["pivot"], sr, mc, t1)
    draw([(F.fig_table1, (cfg, pts, theta, an["pivot"], t1, out / "table1.png"))])
    reg, preds, verdicts = RG.table1_region(cfg, book)
    rows += _write_region(out, prov, book, reg, preds, verdicts, RG.TABLE1_NOTES)
    write_claims(
        out / "claims.parquet",
        rows,
        prov,
        book,
        TABLE1,
        paper_design=RG.TABLE1_ON_PAPER,
        as_printed=as_printed,
    )
    F.fig_region(out, RG.TABLE1_PAIRS, out / "consistent_region.png")
