"""Claim rows from a declarative table: ``{claim id: what the simulation gave}`` plus the claim
book.

A study's claim builder used to call :meth:`ClaimBook.score` once per claim in 100-200 lines of
its own. With this module it states, per claim id, only the simulated value and its interval
(a :class:`Sim`, made by :func:`exact`, :func:`mc`, :func:`plates` or :class:`Sim` itself) and
hands the mapping to :func:`claim_rows`, which scores every entry with the book's rules (paper
words, form, reference and tolerance come from the book, never from the study), in the
mapping's order. An entry ``None`` marks a declared claim that this run has nothing for (an
optional part switched off): it counts as scored and gives no row.

No units here: a claim's value carries the units its claim book states. Used by every study
(seed papers 001-005); the studies not yet moved call ``book.score`` directly, which gives the
same rows (:func:`claim_rows` is a loop over it).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from sim.claims.book import ClaimBook

__all__ = ["Sim", "exact", "mc", "plates", "claim_rows"]

#: the two-sided 95 % normal quantile the Monte-Carlo intervals use
Z95 = 1.96


@dataclass(frozen=True)
class Sim:
    """What the simulation gave for one claim: the arguments of :meth:`ClaimBook.score`.

    value, ci : the estimate and its 95 % interval; ``interval`` says which kind (``ci``,
    ``spread`` or ``exact``). ``value_high``: the upper end of a range value. ``elems``:
    per-element interval arrays of a ``range`` claim. ``samples``: a one-plate statistic over
    the simulated plates. ``chain_tau``: an interval from a sampler chain, the chain's length
    in autocorrelation times (:data:`sim.claims.rules.MIN_CHAIN_TAU`). ``note``: the row's
    explanation."""

    value: float | None = None
    ci: tuple[float, float] | None = None
    interval: str = "ci"
    note: str = ""
    value_high: float | None = None
    elems: tuple[np.ndarray, np.ndarray] | None = None
    samples: np.ndarray | None = None
    chain_tau: float | None = None


def exact(value: float, note: str = "", **kw: Any) -> Sim:
    """A deterministic number (analytic, recomputed or counted): its interval is itself."""
    return Sim(float(value), interval="exact", note=note, **kw)


def mc(value: float, se: float, note: str = "", **kw: Any) -> Sim:
    """A Monte-Carlo estimate with standard error ``se``: interval value +- 1.96 se."""
    return Sim(value, (value - Z95 * se, value + Z95 * se), note=note, **kw)


def plates(samples: np.ndarray, note: str = "") -> Sim:
    """A one-plate statistic over simulated plates (median and 2.5-97.5 % spread)."""
    return Sim(samples=samples, note=note)


def claim_rows(book: ClaimBook, table: Mapping[str, Sim | None]) -> list[dict[str, Any]]:
    """The claims rows of ``table`` (claim id -> :class:`Sim`, or ``None`` for a declared claim
    this run does not produce), scored by ``book`` in the table's order."""
    rows = []
    for cid, s in table.items():
        if s is None:
            book.spec(cid)  # a declared claim, or KeyError naming it
            book._scored.add(cid)  # nothing simulated: complete without a row
            continue
        rows.append(
            book.score(
                cid,
                s.value,
                s.ci,
                s.interval,
                s.note,
                value_high=s.value_high,
                elems=s.elems,
                samples=s.samples,
                chain_tau=s.chain_tau,
            )
        )
    return rows
