"""The consistent region of ``wolf_polynomial``'s unprinted inputs (seed 000) and the verdicts of
its predictions over it (issue 21, :mod:`sim.claims.inference`).

Wolf & Pearsall print neither the pointing error of one reading, nor the sizes of the
systematic error sources, nor the monocomparator's error. ``region.toml`` declares them with
their physically possible ranges and the printed statements that constrain them: the
'before correction' statistics (the size of the field) and Table 1's repeatability (the
pointing error), all inputs of the simulation. The inputs are explored jointly on the
runner's workers: each input vector is a *cell* of the main experiment
(:func:`sim.studies.wolf.chunks.main_chunk`), all cells on the same simulated instruments
(common random numbers, ``unprinted.trials`` of them). Each statistic is evidence with the
claim book's own rules (:func:`sim.claims.book_region.sample_evidence`, the one-plate p over
the printed rounding). Table 2's 24 one-plate rows are 24 correlated tests of one table: each
row's p is its Holm-adjusted p over the 24 at the same input vector
(:func:`sim.studies.wolf.claims.holm`, valid under any dependence), Table 2 as one statement
is the smallest of them, and the headline ("mean discrepancies ranged from 3 to 9") is the
Holm family of the eight plate means alone; both families by the one rule of
:mod:`sim.claims.family`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import load_declaration, plate_ref, sample_evidence
from sim.claims.family import family_evidence, holm, mc_p
from sim.claims.inference import Region, explore, status
from sim.claims.region import statement_of
from sim.mc.runner import chunk_rng
from sim.studies.run_steps import run_part
from sim.studies.wolf.chunks import main_chunk, sub_chunk
from sim.studies.wolf.claims import HEADLINE, JOINT, is_mean_row, stat_key

DECLARATION = Path(__file__).with_name("region.toml")
#: region input -> the cell key it overrides
CELL = {
    "pointing_sigma_um": "reading.pointing_sigma_um",
    "field_scale_1": "field_scale",
    "mono_sigma_um": "mono.sigma_um",
    "drift_share_1": "field.drift_fraction",
    "noncubic_factor_1": "noncubic_factor",
}


def nominal(cfg: dict) -> dict[str, float]:
    """The configured inputs in the region's names (an example in the figure)."""
    return {
        "pointing_sigma_um": float(cfg["reading.pointing_sigma_um"]),
        "field_scale_1": 1.0,
        "mono_sigma_um": float(cfg["mono.sigma_um"]),
        "drift_share_1": float(cfg["field.drift_fraction"]),
        "noncubic_factor_1": 1.0,
    }


def _cells(x: dict[str, np.ndarray], call: int) -> list[tuple[str, dict]]:
    n = len(x["pointing_sigma_um"])
    return [(f"g{call}.{i}.", {CELL[k]: float(x[k][i]) for k in CELL}) for i in range(n)]


def evidence(book: ClaimBook, ids: list[str], res: dict, tags: list[str]) -> dict:
    """Per-point evidence of every claim in ``ids`` from the cells' per-trial statistics.

    Each Table 2 row's ``p`` is its Holm-adjusted p over the 24 rows at the same point (the
    rows are 24 correlated tests of one table); ``JOINT`` is the smallest of them, the
    headline (``HEADLINE``) the smallest Holm-adjusted p over the eight plate means alone.
    The p values entering Holm are the Monte-Carlo test's (:func:`sim.claims.family.mc_p`)."""
    out = {}
    t2 = [c for c in book.specs if c.startswith("wolf.table2.p")]
    for cid in dict.fromkeys(ids + t2):
        if cid in (HEADLINE, JOINT):
            continue
        x = np.stack([res[t + stat_key(cid)] for t in tags])
        out[cid] = sample_evidence(x, *plate_ref(book.spec(cid)))
    n = np.asarray(res[tags[0] + stat_key(t2[0])]).size  # plates per point (one cell's trials)
    raw = mc_p(np.stack([out[c]["p"] for c in t2], 1), n)
    means = np.array([is_mean_row(c) for c in t2])
    adj = np.stack([holm(row) for row in raw])
    for k, c in enumerate(t2):
        out[c]["p"] = adj[:, k]
    member = np.stack([status(statement_of(book, c), out[c], raw.shape[0]) for c in t2], 1)
    if HEADLINE in ids:  # the families by the one rule of sim.claims.family
        out[HEADLINE] = family_evidence(raw[:, means], member[:, means])
    if JOINT in ids:
        out[JOINT] = family_evidence(raw, member)
    return out


def explore_region(cfg: dict, book: ClaimBook, ctx) -> tuple[Region, list[str]]:
    """Explore the declared inputs jointly; each batch of input vectors is one cells run of
    the main experiment on the runner's workers (parts 2, 3, ...)."""
    dec = load_declaration(DECLARATION, book)
    ids = [s.id for s in dec.statements if s.id in book.specs] + dec.predictions
    Ts = cfg["unprinted.trials"]
    calls = [0]

    def model(x: dict[str, np.ndarray]) -> dict:
        calls[0] += 1
        cells = _cells(x, calls[0])
        res = run_part(
            {**cfg, "seed": cfg["region.seed"]},  # the region's own stream (region_seed)
            ctx,
            main_chunk(cfg, cells, full=False),
            1 + calls[0],
            f"wolf region {calls[0]}",
            trials=Ts,
            chunk=sub_chunk(Ts, cfg["chunk"]),
        )
        return evidence(book, ids, res, [t for t, _ in cells])

    region = explore(
        dec.inputs,
        dec.statements,
        model,
        chunk_rng(cfg["region.seed"], 900, 0),
        n=cfg["region.points"],
        rounds=cfg["region.rounds"],
        per_point=1,
        max_new=max(1, cfg["region.points"] // 4),
    )
    return region, dec.predictions
