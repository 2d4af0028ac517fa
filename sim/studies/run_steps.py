"""Steps every study's ``run`` takes the same way (the layer of the studies; no study is
imported here, so the studies stay independent of each other).

* :func:`run_part` -- one Monte-Carlo part of a study through the chunk runner
  (:func:`sim.mc.runner.run_chunks`) with the config's ``trials``, ``seed`` and ``chunk``;
* :func:`over_region` -- the claims rows of the predictions replaced by their verdicts over
  the consistent region of the unprinted inputs (:func:`sim.claims.book_region.region_rows`),
  the configured inputs' result kept in the note as a labelled example;
* :func:`spread_note` -- that note for a one-plate statistic (median and 95 % of the
  simulated calibrations, models, ...).

No units here: values and notes carry the units of the claim they belong to.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import region_rows
from sim.claims.inference import Region
from sim.mc.runner import RunContext, run_chunks

__all__ = ["run_part", "over_region", "spread_note"]


def run_part(
    cfg: Mapping,
    ctx: RunContext,
    fn: Callable[[np.random.Generator, int], Mapping[str, np.ndarray]],
    part: int,
    label: str,
    trials: int | None = None,
    quiet: bool = False,
    chunk: int | None = None,
    units: float | None = None,
) -> dict[str, np.ndarray]:
    """``fn(rng, n)`` over chunks of ``chunk`` (default ``cfg["chunk"]``) trials (``trials``,
    default ``cfg["trials"]``) from stream ``part`` of ``cfg["seed"]``; quiet when ``quiet`` or
    ``ctx.quiet``; ``units``: a trial's unit adjustments on the run's bar. The per-trial
    arrays concatenated over chunks."""
    return run_chunks(
        fn,
        cfg["trials"] if trials is None else trials,
        cfg["seed"],
        cfg["chunk"] if chunk is None else chunk,
        part=part,
        label=label,
        quiet=quiet,
        ctx=ctx,
        units=units,
    )


def spread_note(over: str) -> Callable[[dict], str]:
    """The note of a prediction decided over the region: its result at the configured inputs
    (median and the 95 % spread over ``over``, e.g. ``"calibrations"``) and the outcome."""

    def note(row: dict) -> str:
        return (
            f"at the configured inputs (an example): median {row['value']:.3g}, 95 % of "
            f"{over} {row['ci_low']:.3g}-{row['ci_high']:.3g}, outcome {row['outcome']}"
        )

    return note


def over_region(
    book: ClaimBook,
    region: Region,
    preds: Sequence[str],
    rows: list[dict],
    note: Callable[[dict], str],
) -> list[dict]:
    """``rows`` with each prediction of ``preds`` replaced by its verdict over ``region``
    (scored on a fresh copy of ``book``); ``note(row)`` of the configured inputs' row is kept
    in the new row's note as an example."""
    by = {r["claim"]: r for r in rows}
    fresh = ClaimBook(list(book.specs.values()), [], book.path)
    notes = {c: note(by[c]) for c in preds}
    new = {r["claim"]: r for r in region_rows(fresh, region, preds, notes)}
    return [new.get(r["claim"], r) for r in rows]
