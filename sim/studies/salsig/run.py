"""Run of ``salsig_encoders``: chunks through the runner, tables, figures, claims, sweep."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.instruments import transforms2d as t2
from sim.lsq import distributions as D
from sim.mc import tolerance as tl
from sim.mc.runner import chunk_rng, run_chunks
from sim.mc.storage import provenance, write_table
from sim.report.figure_jobs import start_figures
from sim.studies import RunContext
from sim.studies.salsig import figures as F
from sim.studies.salsig.claims import score
from sim.studies.salsig.model import (
    chain_chunk,
    decompositions,
    simulate_chain,
    simulate_zscale,
    vertical_chunk,
)
from sim.studies.salsig.sweep import run_sweep

#: ``make verify`` (:mod:`sim.mc.tolerance`): E and SX - SY are small differences of numbers of
#: order pi and 12.7, so their rounding is absolute: 1e3 eps of what they are computed from
RECOVERY_TOLERANCES = {
    "E_arcsec": tl.arithmetic(atol=1e3 * tl.EPS * np.pi / t2.ARCSEC),
    "scale_diff_ppm": tl.arithmetic(atol=1e3 * tl.EPS * 1e6),
}


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    prov = provenance(cfg)
    dec = decompositions()
    write_table(out / "decompositions.parquet", dec, prov)
    rec = run_chunks(
        partial(chain_chunk, cfg, None, None),
        cfg["trials"],
        cfg["seed"],
        cfg["chunk"],
        part=0,
        label="salsig chain",
        quiet=ctx.quiet,
        ctx=ctx,
    )
    write_table(out / "trials_recovery.parquet", rec, prov, RECOVERY_TOLERANCES)
    sw = {
        k: []
        for k in (
            "n_marks",
            "sigma_um",
            "power_E",
            "power_E_lo",
            "power_E_hi",
            "power_scale",
            "power_scale_lo",
            "power_scale_hi",
            "sd_E_arcsec",
            "sd_scale_diff_ppm",
        )
    }
    cell = 0
    for k in cfg["power.marks"]:
        for s in cfg["power.sigma_um"]:
            cell += 1
            r = run_chunks(
                partial(chain_chunk, cfg, k, s),
                cfg["power.trials"],
                cfg["seed"],
                cfg["chunk"],
                part=100 + cell,
                label=f"power {k}x{k} {s:g}um",
                quiet=True,
                ctx=ctx,
            )
            sw["n_marks"].append(k * k)
            sw["sigma_um"].append(s)
            for key, col in (("detect_E", "power_E"), ("detect_scale", "power_scale")):
                x = r[key]
                lo, hi = D.wilson_ci(int(x.sum()), x.size, 0.95)
                sw[col].append(float(x.mean()))
                sw[col + "_lo"].append(lo)
                sw[col + "_hi"].append(hi)
            sw["sd_E_arcsec"].append(float(np.std(r["E_arcsec"], ddof=1)))
            sw["sd_scale_diff_ppm"].append(float(np.std(r["scale_diff_ppm"], ddof=1)))
    write_table(out / "power.parquet", sw, prov)
    zs = run_chunks(
        partial(simulate_zscale, cfg),
        cfg["trials"],
        cfg["seed"],
        cfg["chunk"],
        part=2,
        label="z scale",
        quiet=ctx.quiet,
        ctx=ctx,
    )
    write_table(out / "trials_zscale.parquet", zs, prov)
    vt = run_chunks(
        partial(vertical_chunk, cfg, None),
        cfg["trials"],
        cfg["seed"],
        cfg["chunk"],
        part=3,
        label="vertical",
        quiet=ctx.quiet,
        ctx=ctx,
    )
    write_table(out / "trials_vertical.parquet", vt, prov)
    rows, book = score(cfg, dec, rec, zs, vt)
    drawn = start_figures(
        [
            (F.fig_recovery, (rec, cfg, out / "recovery.png")),
            (F.fig_power, (sw, out / "power.png")),
        ],
        ctx.executor,
    )  # on the idle workers while the sweep is made here
    det, cons = run_sweep(book, cfg)
    write_table(out / "sweep.parquet", det, prov)
    write_table(out / "consistent_set.parquet", cons, prov)
    ex = simulate_chain(cfg, chunk_rng(cfg["seed"], 1, 0), 1, return_all=True)
    r = next(x for x in rows if x["claim"] == "salsig.vertical_halved.rms_ratio")
    more = start_figures(
        [
            (F.fig_vertical, (det, (r["zone_low"], r["zone_high"]), out / "vertical.png")),
            (F.fig_residuals, (ex, cfg, out / "residuals.png")),
        ],
        ctx.executor,
    )
    F.fig_consistent(det, cons, out / "consistent_set.png")
    drawn()
    more()
    write_claims(out / "claims.parquet", rows, prov, book)
