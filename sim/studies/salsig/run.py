"""Run of ``salsig_encoders``: chunks through the runner, tables, figures, claims, and the
vertical test's predictions over the consistent region of its unprinted inputs."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import write_claims
from sim.claims.book_region import write_region
from sim.instruments import transforms2d as t2
from sim.lsq import distributions as D
from sim.mc import tolerance as tl
from sim.mc.runner import chunk_rng
from sim.mc.storage import provenance, write_table
from sim.report.plotting import draw
from sim.report.region import fig_region
from sim.studies import RunContext
from sim.studies.run_steps import over_region, run_part, spread_note
from sim.studies.salsig import figures as F
from sim.studies.salsig.claims import score
from sim.studies.salsig.model import (
    chain_chunk,
    decompositions,
    simulate_chain,
    simulate_zscale,
    vertical_chunk,
)
from sim.studies.salsig.region import RATIO, explore_region, nominal
from sim.studies.salsig.schema import SCHEMA

#: ``make verify`` (:mod:`sim.mc.tolerance`): E and SX - SY are small differences of numbers of
#: order pi and 12.7, so their rounding is absolute: 1e3 eps of what they are computed from
RECOVERY_TOLERANCES = {
    "E_arcsec": tl.arithmetic(atol=1e3 * tl.EPS * np.pi / t2.ARCSEC),
    "scale_diff_ppm": tl.arithmetic(atol=1e3 * tl.EPS * 1e6),
}


POWER_COLUMNS = (
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


def power_table(cfg: dict, ctx: RunContext) -> dict[str, list]:
    """``power.parquet``: per design cell (marks per side x B8 sigma, ``power.trials``
    calibrations each, stream part 101, 102, ...) the share of calibrations detecting E and
    SX - SY (with Wilson intervals) and their Monte-Carlo sd."""
    sw = {k: [] for k in POWER_COLUMNS}
    cells = [(k, s) for k in cfg["power.marks"] for s in cfg["power.sigma_um"]]
    for cell, (k, s) in enumerate(cells, start=1):
        r = run_part(
            cfg,
            ctx,
            partial(chain_chunk, cfg, k, s),
            part=100 + cell,
            label=f"power {k}x{k} {s:g}um",
            trials=cfg["power.trials"],
            quiet=True,
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
    return sw


def simulate_parts(cfg: dict, out: Path, ctx: RunContext, prov) -> tuple[dict, ...]:
    """The calibration chain (part 0), the power sweep, the z scale (part 2) and the vertical
    test (part 3) through the runner, each written to its table; returns their arrays."""
    rec = run_part(cfg, ctx, partial(chain_chunk, cfg, None, None), part=0, label="salsig chain")
    write_table(out / "trials_recovery.parquet", rec, prov, RECOVERY_TOLERANCES)
    sw = power_table(cfg, ctx)
    write_table(out / "power.parquet", sw, prov)
    zs = run_part(cfg, ctx, partial(simulate_zscale, cfg), part=2, label="z scale")
    write_table(out / "trials_zscale.parquet", zs, prov)
    vt = run_part(cfg, ctx, partial(vertical_chunk, cfg, None), part=3, label="vertical")
    write_table(out / "trials_vertical.parquet", vt, prov)
    return rec, sw, zs, vt


def run(cfg: dict, out: Path, ctx: RunContext) -> None:
    """The printed parameters decomposed, the simulated parts, the claims at the configured
    inputs, then the vertical test's predictions over the region (``claims.parquet``)."""
    prov = provenance(cfg)
    dec = decompositions()
    write_table(out / "decompositions.parquet", dec, prov)
    rec, sw, zs, vt = simulate_parts(cfg, out, ctx, prov)
    rows, book = score(cfg, dec, rec, zs, vt)
    draw(
        [
            (F.fig_recovery, (rec, cfg, out / "recovery.png")),
            (F.fig_power, (sw, cfg, out / "power.png")),
        ]
    )
    region, preds = explore_region(cfg, book, chunk_rng(cfg["region.seed"], 900, 0))
    write_region(out / "consistent_region.parquet", region, book, preds, prov)
    rows = over_region(book, region, preds, rows, spread_note("models"))
    ex = simulate_chain(cfg, chunk_rng(cfg["seed"], 1, 0), 1, return_all=True)
    r = next(x for x in rows if x["claim"] == RATIO)
    zone = (r["zone_low"], r["zone_high"])
    draw(
        [
            (
                F.fig_vertical,
                (region.x["relief_mm"], region.outputs[RATIO], zone, out / "vertical.png"),
            ),
            (F.fig_residuals, (ex, cfg, out / "residuals.png")),
        ]
    )
    fig_region(
        region,
        out / "consistent_region.png",
        title="seed 002: the vertical test's unprinted inputs (constrained by 'cut roughly in half')",
        nominal=nominal(cfg),
    )
    write_claims(out / "claims.parquet", rows, prov, book, SCHEMA)
