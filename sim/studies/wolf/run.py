"""Run of ``wolf_polynomial`` through the runner (every part chunked, every chunk function
picklable, so ``--workers``, Dask and resume work). Wolf & Pearsall 1976, seed
``000_668e60e68f004f98.txt``.

Parts (spawn keys): 0 the main experiment (``trials``); 1 the cells run (``unprinted.trials``):
the readings trade-off;
10+i the degree trade-off at spacing i; 40 the stability trade-off; 30, 90, 91, 98 single
streams (reading-error table, the vector figure's instrument, one field draw, the bootstrap).
Writes ``trials.parquet``, ``vectors.parquet``, ``components.parquet``, ``degree.parquet``,
``trials_degree.parquet``, ``readings.parquet``, ``stability.parquet``,
``table1_real.parquet``, ``table3_real.parquet``, ``consistent_region.parquet`` (and
``region_inputs.parquet``), ``claims.parquet``, ``not_reproduced.parquet`` and the
figures. Parts 2, 3, ...: the joint exploration of the unprinted inputs
(:mod:`sim.studies.wolf.region`), one cells run per batch of input vectors.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.claims.book_region import write_region
from sim.claims.intervals import spread
from sim.instruments.plotter import errorfields as ef
from sim.mc.runner import chunk_rng
from sim.mc.storage import provenance, write_table
from sim.report.region import fig_region
from sim.studies import RunContext
from sim.studies.run_steps import over_region, run_part
from sim.studies.wolf import claims as cl
from sim.studies.wolf import figures, tables
from sim.studies.wolf.checks import table_digest, table_path
from sim.studies.wolf.chunks import degree_chunk, main_chunk, stability_chunk, sub_chunk
from sim.studies.wolf.grid import grid_nodes
from sim.studies.wolf.model import field_spec, reading_error_rms
from sim.studies.wolf.region import explore_region, nominal
from sim.studies.wolf.schema import SCHEMA

APPROACHES = ("one_side", "random")


def _summ(x):
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return np.nan, np.nan, np.nan
    med, (lo, hi) = spread(x)
    return med, lo, hi


def reading_cells(cfg: dict) -> list[tuple[str, str, float, int, dict]]:
    """``(tag, approach, sigma, readings, override)`` of the readings trade-off."""
    out = []
    for a in APPROACHES:
        for sg in cfg["trade.pointing_sigmas_um"]:
            for n in cfg["trade.readings"]:
                out.append(
                    (
                        f"r.{a}.{sg:g}.{n}.",
                        a,
                        float(sg),
                        int(n),
                        {
                            "reading.approach": a,
                            "reading.pointing_sigma_um": float(sg),
                            "reading.n": int(n),
                        },
                    )
                )
    return out


def example_note(row: dict) -> str:
    """The note of a prediction decided over the region: its result at the configured inputs
    (value and interval) and the outcome, kept as an example."""
    return (
        f"at the configured inputs (an example): {row['value']:.3g} "
        f"({row['ci_low']:.3g}-{row['ci_high']:.3g}), outcome {row['outcome']}"
    )


_READING_COLUMNS = (
    "approach",
    "pointing_sigma_um",
    "readings",
    "reading_error_um",
    "after_check_rms_um",
    "after_check_lo_um",
    "after_check_hi_um",
    "after_plate_rms_um",
    "after_plate_lo_um",
    "after_plate_hi_um",
)


def _readings(cfg: dict, out: Path, prov: dict, ctx: RunContext) -> None:
    """The readings trade-off (one cells run, part 1; the reading-error table from stream
    30): ``readings.parquet``, per approach, pointing sigma and number of readings."""
    rc = reading_cells(cfg)
    cells = [(t, o) for t, *_, o in rc]
    Ts, seed = cfg["unprinted.trials"], cfg["seed"]
    res = run_part(
        cfg,
        ctx,
        main_chunk(cfg, cells, full=False),
        1,
        "wolf cells",
        trials=Ts,
        chunk=sub_chunk(Ts, cfg["chunk"]),
    )
    er = chunk_rng(seed, 30, 0)
    rd = {k: [] for k in _READING_COLUMNS}
    for tag, a, sg, n, _ in rc:
        ca, pa = (
            np.sqrt((res[f"{tag}{e}.rms_x_um"] ** 2 + res[f"{tag}{e}.rms_y_um"] ** 2) / 2)
            for e in ("check_after", "plate_after")
        )
        vals = (
            a,
            sg,
            n,
            reading_error_rms(er, cfg["reading.count_um"], n, sg, cfg["reading.backlash_um"], a),
            *_summ(ca),
            *_summ(pa),
        )
        for k, v in zip(rd, vals):
            rd[k].append(v)
    write_table(out / "readings.parquet", rd, prov)


def _paper_tables(cfg: dict, out: Path, prov: dict) -> tuple[dict, dict]:
    """Tables 1 and 3 recomputed from the paper's transcribed coordinates (um), written."""
    for t in ("table1", "table3"):
        table_digest(cfg, t)  # the tables the config records, not ones edited since
    t1 = tables.table1_discrepancies(tables.load_table1(table_path(cfg, "table1.file")))
    t3 = tables.table3_discrepancies(tables.load_table3(table_path(cfg, "table3.file")))
    write_table(out / "table1_real.parquet", t1, prov)
    write_table(out / "table3_real.parquet", t3, prov)
    return t1, t3


def _region_figure(cfg: dict, out: Path, region) -> None:
    fig_region(
        region,
        out / "consistent_region.png",
        title="seed 000: unprinted inputs left by the 'before' rows and Table 1",
        nominal=nominal(cfg),
        labels={
            "pointing_sigma_um": "pointing sigma of one reading (um)",
            "field_scale_1": "factor on the field amplitudes",
            "mono_sigma_um": "monocomparator sigma (um)",
            "drift_share_1": "drifting share of the field's variance",
            "noncubic_factor_1": "factor on the sources a cubic cannot fit",
        },
    )


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    """The main experiment, the vectors and components, the readings trade-off, the region
    of the unprinted inputs, the degree and stability trade-offs, the paper's tables, the
    claims (predictions over the region), the figures."""
    prov = provenance(cfg)
    T = cfg["trials"]
    main = run_part(cfg, ctx, main_chunk(cfg), 0, "wolf main")
    write_table(out / "trials.parquet", {"trial": np.arange(T), **main}, prov)
    _vectors_and_components(cfg, out, prov)
    _readings(cfg, out, prov, ctx)
    book = cl.load_book()
    region, preds = explore_region(cfg, book, ctx)
    write_region(out / "consistent_region.parquet", region, book, preds, prov)
    degt = _degree(cfg, out, prov, ctx)
    _stability(cfg, out, prov, ctx)
    t1, t3 = _paper_tables(cfg, out, prov)
    rows = over_region(book, region, preds, cl.rows(cfg, main, t1, t3, degt, book), example_note)
    write_claims(out / "claims.parquet", rows, prov, book, SCHEMA)
    _region_figure(cfg, out, region)
    figures.figures(cfg, out)


def _vectors_and_components(cfg, out, prov):
    seed = cfg["seed"]
    rep = main_chunk(cfg, keep_vectors=True)(chunk_rng(seed, 90, 0), 1)
    G = grid_nodes(cfg["plate.area_mm"], cfg["plate.spacing_mm"])
    S = cfg["calib.n_sets"]
    vb, va = rep["vec.before"][0], rep["vec.after"][0]
    write_table(
        out / "vectors.parquet",
        {
            "set": np.repeat(np.arange(1, S + 1), len(G)),
            "x_mm": np.tile(G[:, 0], S),
            "y_mm": np.tile(G[:, 1], S),
            "dx_before_um": vb[..., 0].ravel(),
            "dy_before_um": vb[..., 1].ravel(),
            "dx_after_um": va[..., 0].ravel(),
            "dy_after_um": va[..., 1].ravel(),
        },
        prov,
    )
    spec = field_spec(cfg)
    comp = ef.evaluate_components(spec, ef.draw(spec, chunk_rng(seed, 91, 0), 1), G)
    names = list(ef.COMPONENTS)
    write_table(
        out / "components.parquet",
        {
            "component": np.repeat(names, len(G)),
            "x_mm": np.tile(G[:, 0], len(names)),
            "y_mm": np.tile(G[:, 1], len(names)),
            "dx_um": np.concatenate([comp[k][0, :, 0] for k in names]),
            "dy_um": np.concatenate([comp[k][0, :, 1] for k in names]),
            "amplitude_um": np.repeat([spec.amplitude(k) for k in names], len(G)),
        },
        prov,
    )


def _degree(cfg, out, prov, ctx) -> dict:
    Tt = cfg["trade.trials"]
    cht = sub_chunk(Tt, cfg["chunk"])
    rows = {
        k: []
        for k in (
            "spacing_mm",
            "n_points",
            "n_sets",
            "degree",
            "terms",
            "fit_rms_um",
            "fit_lo_um",
            "fit_hi_um",
            "check_rms_um",
            "check_lo_um",
            "check_hi_um",
            "estimable_share",
        )
    }
    trials = {
        k: [] for k in ("spacing_mm", "n_sets", "degree", "trial", "fit_rms_um", "check_rms_um")
    }
    for i, sp in enumerate(cfg["trade.spacings_mm"]):
        r = run_part(
            cfg, ctx, degree_chunk(cfg, sp), 10 + i, f"degree, {sp:g} mm", trials=Tt, chunk=cht
        )
        npts = len(grid_nodes(cfg["plate.area_mm"], sp))
        for ns in cfg["trade.n_sets"]:
            for d in cfg["trade.degrees"]:
                fr, cr = r[f"fit.{ns}.{d}"], r[f"check.{ns}.{d}"]
                vals = (
                    sp,
                    npts,
                    ns,
                    d,
                    (d + 1) * (d + 2) // 2,
                    *_summ(fr),
                    *_summ(cr),
                    float(np.isfinite(fr).mean()),
                )
                for k, v in zip(rows, vals):
                    rows[k].append(v)
                for k, v in zip(
                    trials,
                    (np.full(Tt, sp), np.full(Tt, ns), np.full(Tt, d), np.arange(Tt), fr, cr),
                ):
                    trials[k].append(v)
    write_table(out / "degree.parquet", rows, prov)
    degt = {k: np.concatenate(v) for k, v in trials.items()}
    write_table(out / "trials_degree.parquet", degt, prov)
    return degt


def _stability(cfg, out, prov, ctx) -> None:
    Tt = cfg["trade.trials"]
    cht = sub_chunk(Tt, cfg["chunk"])
    fr_, ages = cfg["trade.drift_fractions"], cfg["trade.ages_weeks"]
    r = run_part(cfg, ctx, stability_chunk(cfg, fr_, ages), 40, "stability", trials=Tt, chunk=cht)
    stb = {
        k: []
        for k in (
            "drift_fraction",
            "age_weeks",
            "before_rms_um",
            "before_lo_um",
            "before_hi_um",
            "after_rms_um",
            "after_lo_um",
            "after_hi_um",
            "share_after_better",
        )
    }
    for f in fr_:
        for i, age in enumerate(ages):
            b, a = r[f"before.{f}.{i}"], r[f"after.{f}.{i}"]
            for k, v in zip(stb, (f, age, *_summ(b), *_summ(a), float(np.mean(a < b)))):
                stb[k].append(v)
    write_table(out / "stability.parquet", stb, prov)
