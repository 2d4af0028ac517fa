"""The consistent region of ``agnard_block``'s unprinted input (seed 003) and the verdicts of
the 5-control predictions over it (issue 21, :mod:`sim.claims.inference`).

Figure 5, the layout of the five control points of the third pass, is lost. ``region.toml``
declares the layout by one number, how far the four outer points stand inwards from the block
corners, over the range the block allows; nothing the paper prints constrains it (its
Table's numbers are the predictions), so the region is the whole range and each 5-control
row is decided over it: holds / fails everywhere, depends (with the insets where it holds),
or undecidable. The model adjusts the same ``region.trials`` simulated blocks once per
layout (:func:`sim.studies.agnard.chunks.sweep_chunk`, on the runner's workers); each
statistic is evidence with the claim book's rules
(:func:`sim.claims.book_region.sample_evidence`).
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import load_declaration, sample_evidence
from sim.claims.inference import Region, explore
from sim.instruments.block.layout import Block
from sim.mc.runner import chunk_rng
from sim.studies.agnard import chunks as ch

DECLARATION = Path(__file__).with_name("region.toml")


def five_samples(sw: dict, i: int) -> dict[str, np.ndarray]:
    """Per-block statistics (cm) of layout ``i`` keyed by claim id."""
    out = {}
    for w in ("ctrl", "check"):
        for c in ("x", "y", "xy", "z"):
            out[f"agnard.control_5.{w}_{c}_cm"] = 100 * np.asarray(sw[f"inset{i}.{w}_{c}_m"])
    for c in ("xy", "z"):  # the acceptance limit applies to the control rms
        out[f"agnard.max_residual.control_5_{c}_cm"] = 100 * np.asarray(sw[f"inset{i}.ctrl_{c}_m"])
    return out


def explore_region(
    cfg: dict, block: Block, book: ClaimBook, runner: Callable[..., dict], part: int
) -> tuple[Region, list[str], list[dict]]:
    """The region, its predictions, and the per-layout statistics of every explored layout
    (``runner(fn, trials, part, label)`` runs one part through the runner)."""
    dec = load_declaration(DECLARATION, book)
    stats: list[dict] = []

    def model(x: dict[str, np.ndarray]) -> dict:
        insets = tuple(float(u) for u in x["five_inset_1"])
        sw = runner(
            partial(ch.sweep_chunk, cfg, block, insets),
            cfg["region.trials"],
            part + len(stats),
            "five-point layouts",
        )
        per = [five_samples(sw, i) for i in range(len(insets))]
        stats.extend(per)
        return {
            c: sample_evidence(
                np.stack([p[c] for p in per]),
                float(book.spec(c)["ref"]) if book.spec(c)["form"] == "one-plate" else None,
            )
            for c in dec.predictions
        }

    region = explore(
        dec.inputs,
        dec.statements,
        model,
        chunk_rng(cfg["seed"], 900, 0),
        n=cfg["region.points"],
        rounds=0,
    )
    return region, dec.predictions, stats
