"""Run of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``) through the runner.

Streams (``part``): 0 the 2 x 8 block with every adjustment of the paper; then one per scan
resolution, one per block size, one per mechanical re-centring error, one for the region
of the unprinted five-point control layout (each layout without and with the models'
projection centres, on the same blocks), and (from 800, apart) the scanner region under
Table 1 (:mod:`.region`). Every part goes through :func:`sim.mc.runner.run_chunks` with
the run context (executor, chunk store), with picklable chunk functions
(:mod:`.chunks`), so ``--workers``, Dask and resumption after a kill apply.
Writes ``trials.parquet``, ``layout.parquet``, ``check_vectors.parquet``, the trade-off
tables, ``region_five.parquet`` (per block, layout and centres option), ``consistent_region.parquet``,
``region_inputs.parquet``, ``region_layouts.parquet``, ``scanner_region.parquet`` (every
explored scanner vector, with the 21-control rows' per-vector outcomes),
``scanner_region_inputs.parquet``, ``scanner_shift.parquet`` (each vector's paired shift),
``claims.parquet`` + ``not_reproduced.parquet`` and the figures (each drawn as soon as its data exist).
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.instruments.block import independent_models as im
from sim.instruments.block.layout import select_control
from sim.mc.agnard_size import agnard_units
from sim.mc.runner import run_chunks
from sim.mc.storage import provenance, write_table
from sim.report.plotting import draw
from sim.studies import RunContext
from sim.studies.agnard import chunks as ch
from sim.studies.agnard import decide as dc
from sim.studies.agnard import figures as fg
from sim.studies.agnard.centre import ground_density
from sim.studies.agnard.claims import claim_rows, load_book
from sim.studies.agnard.schema import NAME, SCHEMA, block_of, five_control
from sim.studies.agnard.simulate import centre_points


def _mean_se(x: np.ndarray) -> tuple[float, float]:
    x = np.asarray(x, float)
    return float(x.mean()), float(x.std(ddof=1) / np.sqrt(x.size))


def _add_mean_se(t: dict, q: str, x: np.ndarray) -> None:
    """Append the mean of ``x`` to column ``q`` of ``t`` and its standard error to ``q_se``."""
    m, se = _mean_se(x)
    t[q].append(m)
    t[q + "_se"].append(se)


def _run(fn, trials, cfg, part, label, ctx, chunk=None, units=None):
    """One part through the runner, in at least four chunks (when it has the trials) so that
    the parts, run one after the other, keep every worker busy; ``units``: a trial's unit
    adjustments on the run's bar (:func:`sim.mc.agnard_size.agnard_units`)."""
    chunk = chunk or min(cfg["chunk"], max(1, -(-trials // 4)))
    return run_chunks(
        fn,
        trials,
        cfg["seed"],
        chunk,
        part=part,
        label=f"{NAME} {label}",
        quiet=ctx.quiet,
        ctx=ctx,
        units=units,
    )


def _check_vectors(cfg, block, sim, c5, c21, T, prov, out):
    ng = block.n_ground
    parts = []
    for lay, ctrl in (("few", c5), ("many", c21)):
        first = sim[f"{ch.CHUNK}{lay}_first_e_m"][0]
        mean = sim[f"{ch.CHUNK}{lay}_sum_e_m"].sum(0) / T
        parts.append(
            {
                "layout": np.full(ng, lay),
                "point": np.arange(ng),
                "x_m": block.points[:ng, 0],
                "y_m": block.points[:ng, 1],
                **{f"e{c}_m": first[:, a] for a, c in enumerate("xyz")},
                **{f"mean_e{c}_m": mean[:, a] for a, c in enumerate("xyz")},
                "is_control": np.isin(np.arange(ng), ctrl),
                "mean_over_trials": np.full(ng, T),
            }
        )
    vec = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    write_table(out / "check_vectors.parquet", vec, prov)
    return vec


def _scanner_table(cfg, block, sim, ctx, prov, out):
    """Scan resolution x calibration; the run's own resolution reuses the main blocks when
    their 'without' adjustment has the 21-control layout."""
    t = {
        k: []
        for k in (
            "dpi",
            "calibration",
            "trials",
            "check_xy_m",
            "check_xy_m_se",
            "check_z_m",
            "check_z_m_se",
            "ctrl_xy_m",
            "ctrl_z_m",
            "gain_xy_pct",
            "gain_xy_pct_se",
        )
    }
    for i, dpi in enumerate(cfg["tradeoff.dpis"]):
        if dpi == cfg["scan.dpi"] and cfg["control.table1"] == cfg["control.many"]:
            r = {
                f"{cal}.{q}": sim[f"{pre}.{q}"]
                for cal, pre in (("raw", "without"), ("corrected", f"layout_{cfg['control.many']}"))
                for q in ("check_xy_m", "check_z_m", "ctrl_xy_m", "ctrl_z_m")
            }
            r["gain_xy_pct"] = 100 * (1 - r["corrected.check_xy_m"] / r["raw.check_xy_m"])
        else:
            r = _run(
                partial(ch.scanner_chunk, cfg, block, dpi),
                cfg["tradeoff.trials"],
                cfg,
                1 + i,
                f"{dpi:g} DPI",
                ctx,
                units=agnard_units(cfg)["scanner"],
            )
        for cal in ("raw", "corrected"):
            t["dpi"].append(dpi)
            t["calibration"].append(cal)
            t["trials"].append(len(r["gain_xy_pct"]))
            for q in ("check_xy_m", "check_z_m"):
                _add_mean_se(t, q, r[f"{cal}.{q}"])
            t["ctrl_xy_m"].append(float(r[f"{cal}.ctrl_xy_m"].mean()))
            t["ctrl_z_m"].append(float(r[f"{cal}.ctrl_z_m"].mean()))
            _add_mean_se(t, "gain_xy_pct", r["gain_xy_pct"])  # paired: same trials with, without
    write_table(out / "tradeoff_scanner.parquet", t, prov)
    return t


def _control_table(cfg, block, sim, prov, out):
    t = {
        k: []
        for k in (
            "layout",
            "n_control",
            "check_xy_m",
            "check_xy_m_se",
            "check_z_m",
            "check_z_m_se",
            "ctrl_xy_m",
            "ctrl_z_m",
        )
    }
    for lay in cfg["tradeoff.layouts"]:
        t["layout"].append(lay)
        t["n_control"].append(int(select_control(block, lay).size))
        for q in ("check_xy_m", "check_z_m"):
            _add_mean_se(t, q, sim[f"layout_{lay}.{q}"])
        t["ctrl_xy_m"].append(float(sim[f"layout_{lay}.ctrl_xy_m"].mean()))
        t["ctrl_z_m"].append(float(sim[f"layout_{lay}.ctrl_z_m"].mean()))
    write_table(out / "tradeoff_control.parquet", t, prov)
    return t


def _size_table(cfg, block, ctx, base, prov, out):
    density = ground_density(block)
    t = {
        k: []
        for k in (
            "strips",
            "models",
            "n_models",
            "n_points",
            "n_control",
            "centre_xy_m",
            "centre_xy_m_se",
            "centre_z_m",
            "centre_z_m_se",
            "check_xy_m",
            "check_xy_m_se",
            "check_z_m",
            "check_z_m_se",
        )
    }
    for i, (S, M) in enumerate(zip(cfg["tradeoff.block_strips"], cfg["tradeoff.block_models"])):
        b = block_of(cfg, S, M, density=density)
        ctrl = select_control(b, cfg["tradeoff.block_control"])
        cen = centre_points(b, ctrl, cfg["tradeoff.centre_points"])
        # bound the memory of the pair blocks (trials x observation pairs x 7 x 7)
        npair = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points).pk1.size
        chunk = max(
            1, min(cfg["chunk"], 4_000_000 // (49 * npair), -(-cfg["tradeoff.block_trials"] // 4))
        )  # >= 4 chunks: parallel
        r = _run(
            partial(ch.size_chunk, cfg, b, cen),
            cfg["tradeoff.block_trials"],
            cfg,
            base + i,
            f"{S}x{M}",
            ctx,
            chunk,
            agnard_units(cfg)["size"](S, M),
        )
        t["strips"].append(S)
        t["models"].append(M)
        t["n_models"].append(S * M)
        t["n_points"].append(b.n_points)
        t["n_control"].append(int(ctrl.size))
        for q in ("centre_xy_m", "centre_z_m", "check_xy_m", "check_z_m"):
            _add_mean_se(t, q, r[f"size.{q}"])
    write_table(out / "tradeoff_block.parquet", t, prov)
    return t


def _pugging(cfg, block, sim, ctx, base, prov, out):
    """Rejections against the re-centring error; the run's own value is the main blocks'."""
    t = {k: [] for k in ("recentre_px", "trials", "mean_share_pct", "mean_share_pct_se")}
    per = {}
    for i, rc in enumerate(cfg["tradeoff.recentre_px"]):
        if rc == cfg["pugging.recentre_px"]:
            r = {"share_pct": sim["snoop_mechanical.share_pct"]}
        else:
            r = _run(
                partial(ch.pugging_chunk, cfg, block, rc),
                cfg["tradeoff.trials"],
                cfg,
                base + i,
                f"re-centring {rc:g} px",
                ctx,
                units=agnard_units(cfg)["recentre"],
            )
        per[float(rc)] = r["share_pct"]
        t["recentre_px"].append(rc)
        t["trials"].append(len(r["share_pct"]))
        _add_mean_se(t, "mean_share_pct", r["share_pct"])
    write_table(out / "tradeoff_pugging.parquet", t, prov)
    return per


def _layout(block, c5, c21, prov, out) -> None:
    """``layout.parquet``: every point of the block (m), its kind (check, pass, control of
    the many- or few-point layout or both) and the number of models it appears in."""
    kind = np.full(block.n_points, "check", dtype=object)
    kind[block.is_pass] = "pass"
    kind[c21] = "control_many"
    kind[c5] = np.where(np.isin(c5, c21), "control_both", "control_few")
    nmod = np.bincount(block.obs_point, minlength=block.n_points)
    write_table(
        out / "layout.parquet",
        {
            "x_m": block.points[:, 0],
            "y_m": block.points[:, 1],
            "z_m": block.points[:, 2],
            "kind": kind.astype(str),
            "models": nmod,
        },
        prov,
    )


def _region_layouts(block, insets: list[float], prov, out) -> list[np.ndarray]:
    """``region_layouts.parquet``: the five control points (m) of each explored inset; returns
    their indices per inset."""
    ctrl_idx = [five_control(block, u) for u in insets]
    write_table(
        out / "region_layouts.parquet",
        {
            "inset": np.repeat(insets, 5),
            "point": np.concatenate(ctrl_idx),
            "x_m": block.points[np.concatenate(ctrl_idx), 0],
            "y_m": block.points[np.concatenate(ctrl_idx), 1],
        },
        prov,
    )
    return ctrl_idx


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    """The 2 x 8 block with every adjustment of the paper, its layout and check vectors, the
    trade-offs (scan resolution, control layout, block size, re-centring), the claims with
    the 5-control rows decided over the region of the lost layout, and the figures."""
    block = block_of(cfg)
    prov = provenance(cfg, sparse_from_models=im.SPARSE_FROM_MODELS)
    book = load_book()
    T = cfg["trials"]
    c5 = select_control(block, cfg["control.few"])
    c21 = select_control(block, cfg["control.many"])
    draw([(fg.fig_scanner, (cfg, out / "scanner_field.png"))])
    units = agnard_units(cfg)
    sim = _run(partial(ch.main_chunk, cfg, block), T, cfg, 0, "2x8 block", ctx, units=units["main"])
    per_trial = {k: v for k, v in sim.items() if not k.startswith(ch.CHUNK)}
    write_table(out / "trials.parquet", {"trial": np.arange(T), **per_trial}, prov)
    _layout(block, c5, c21, prov, out)
    vec = _check_vectors(cfg, block, sim, c5, c21, T, prov, out)
    draw([(fg.fig_residuals, (vec, out / "check_residuals.png"))])
    scan_t = _scanner_table(cfg, block, per_trial, ctx, prov, out)
    lay_t = _control_table(cfg, block, sim, prov, out)
    base = 1 + len(cfg["tradeoff.dpis"])
    size_t = _size_table(cfg, block, ctx, base, prov, out)
    base += len(cfg["tradeoff.block_strips"])
    pug = _pugging(cfg, block, per_trial, ctx, base, prov, out)
    base += len(cfg["tradeoff.recentre_px"])

    # --- the unprinted five-point layout (at the configured scanner), the scanner's inputs
    # --- under Table 1 (with the 5-control pass at the joint design's layout points), then
    # --- every claim: over the scanner, and the 5-control rows over both together
    def runner(fn, trials, p, label, units=None):  # the regions' parts
        return _run(fn, trials, cfg, p, label, ctx, units=units)

    layout, preds5, stats5, insets = dc.five_region(cfg, block, book, runner, base, prov, out)
    scanner, spreds, sstats, five = dc.scanner_region(
        cfg, block, book, per_trial, runner, layout, prov, out
    )
    rows = claim_rows(cfg, block, per_trial, c5, c21, scan_t, pug, book, scanner, sstats)
    rows = dc.over_scanner(book, scanner, spreds, rows, cfg["table1.trials"], T)
    regions = (layout, preds5, stats5, scanner, sstats)
    rows = dc.over_joint(cfg, book, rows, regions, five, prov, out)
    ctrl_idx = _region_layouts(block, insets, prov, out)
    write_claims(out / "claims.parquet", dc.without_snooping(cfg, rows), prov, book, SCHEMA)
    draw(
        [
            (fg.fig_tradeoffs, (scan_t, lay_t, size_t, c21.size, out / "tradeoffs.png")),
            (fg.fig_layout, (block, c5, c21, out / "block_layout.png", ctrl_idx, insets)),
        ]
    )
