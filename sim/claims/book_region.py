"""Claim-book rows decided over a consistent region (issue 21 items 1-2), for the studies that
keep their printed statements in a claim book (``claims.toml``).

The bridge between :mod:`sim.claims.book` and :mod:`sim.claims.inference` /
:mod:`sim.claims.region`: a claim's spec becomes a :class:`~sim.claims.inference.Statement`
(the same zone: printed rounding widened by ``tol``, one-sided for bounds), per-point
Monte-Carlo samples become evidence with the book's own rules (one-plate: the 2.5-97.5 %
spread and the probability ``p`` of a plate at least as extreme; other forms: the spread
alone), and the region verdicts become claims rows (:func:`sim.claims.region.region_row`).
Arrays in, arrays out: samples have a leading point axis ``(N, M)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.declaration import read_toml
from sim.claims.inference import Input, Region, Statement, parse_declaration
from sim.claims.intervals import spread_rows
from sim.claims.region import (
    OUTCOME_NAMES,
    decide_over,
    inputs_table,
    outcomes,
    region_row,
    region_table,
    statement_of,
)
from sim.mc.config import ConfigError
from sim.mc.storage import write_table

__all__ = [
    "Declaration",
    "load_declaration",
    "statements",
    "sample_evidence",
    "plate_ref",
    "region_rows",
    "write_region",
    "write_explored",
    "region_summary",
]


_EXPLORE = {"n": (4, 65536), "rounds": (0, 10), "per_point": (1, 64), "draws": (50, 1_000_000)}


@dataclass(frozen=True)
class Declaration:
    """A paper's unprinted inputs (ranges), the statements that constrain them (hardware
    limits declared here, printed ones by claim id from the claim book), the predictions
    decided over the region, and the exploration's size."""

    inputs: list[Input]
    statements: list[Statement]
    predictions: list[str]
    explore: dict[str, int]


def load_declaration(path: str | Path, book: ClaimBook) -> Declaration:
    """Read ``region.toml``: ``constraints`` and ``predictions`` (claim ids of ``book``),
    ``[inputs]`` and ``[statements]`` as :func:`sim.claims.inference.parse_declaration`
    (hardware limits; the printed statements come from the book), and ``[explore]`` (``n``,
    ``rounds``, ``per_point``, ``draws``). Unknown keys and ids raise ConfigError naming them."""
    p = Path(path)
    try:
        return _load_declaration(p, book)
    except ConfigError as e:  # name the file: the book's and the study file's keys look alike
        if str(p) in str(e):
            raise
        err = ConfigError(None, f"{p}: {e}")
        err.key = e.key
        raise err from None


def _load_declaration(p: Path, book: ClaimBook) -> Declaration:
    doc = read_toml(p, "region declaration")
    cons, preds = doc.pop("constraints", []), doc.pop("predictions", [])
    explore = doc.pop("explore", {})
    for key, ids in (("constraints", cons), ("predictions", preds)):
        if not isinstance(ids, list) or not all(isinstance(i, str) for i in ids):
            raise ConfigError(key, "must be a list of claim ids")
        for i in ids:
            if i not in book.specs:
                raise ConfigError(key, f"{i!r} is not a claim of {book.path}")
            if "ref" not in book.specs[i]:
                raise ConfigError(key, f"{i!r} prints no number (no ref)")
    if isinstance(cons, list) and isinstance(preds, list):
        seen: set[str] = set()
        for key, i in [("constraints", i) for i in cons] + [("predictions", i) for i in preds]:
            if i in seen:  # constrains the region and is decided over it, or listed twice
                raise ConfigError(key, f"{i!r} is listed twice (a claim is one or the other)")
            seen.add(i)
    if not isinstance(explore, dict):
        raise ConfigError("explore", "must be a table")
    ex = {}
    for k, v in explore.items():
        if k not in _EXPLORE:
            raise ConfigError(f"explore.{k}", f"unknown key (allowed: {', '.join(_EXPLORE)})")
        lo, hi = _EXPLORE[k]
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            raise ConfigError(f"explore.{k}", f"must be an integer in [{lo}, {hi}]")
        ex[k] = v
    inputs, hard = parse_declaration(doc)
    return Declaration(inputs, hard + statements(book, cons), list(preds), ex)


def statements(book: ClaimBook, ids: Sequence[str]) -> list[Statement]:
    """The inference statements of claims ``ids`` (the book's decision zones)."""
    return [statement_of(book, c) for c in ids]


def sample_evidence(
    x: np.ndarray, ref: float | None = None, h: float = 0.0
) -> dict[str, np.ndarray]:
    """Evidence of per-point samples ``x`` (N points, M plates each; NaN-free rows).

    ``value`` the median, ``low``/``high`` the 2.5 / 97.5 % spread of one plate; with ``ref``
    (a one-plate claim) also ``p = min(1, 2 min(P(X < ref + h), P(X > ref - h)))``, ``h``
    half a unit of the printed last decimal (:func:`plate_ref`), plates on an edge counted
    half: the book's one-plate rule (:func:`sim.claims.intervals.plate_p`), point by point."""
    x = np.asarray(x, float)
    med, lo, hi = spread_rows(x)
    n = np.sum(np.isfinite(x), axis=1)
    # ``plates``: fewer than MIN_PLATES decide nothing (sim.claims.inference.status)
    ev = {"value": med, "low": lo, "high": hi, "plates": n}
    if ref is not None:
        if not h >= 0:
            raise ValueError(f"the rounding half-unit h must be >= 0, not {h!r}")
        below = np.sum(x < ref + h, axis=1) + 0.5 * np.sum(x == ref + h, axis=1)
        above = np.sum(x > ref - h, axis=1) + 0.5 * np.sum(x == ref - h, axis=1)
        ev["p"] = np.minimum(1.0, 2 * np.minimum(below, above) / np.maximum(n, 1))
    return ev


def plate_ref(spec: Mapping) -> tuple[float | None, float]:
    """``(ref, h)`` for :func:`sample_evidence` from a claim's spec: the printed number and
    half a unit of its last decimal for a one-plate claim, ``(None, 0.0)`` otherwise."""
    if spec.get("form") != "one-plate":
        return None, 0.0
    h = 0.5 * 10.0 ** (-spec["decimals"]) if "decimals" in spec else 0.0
    return float(spec["ref"]), h


def region_rows(
    book: ClaimBook, region: Region, ids: Sequence[str], notes: Mapping[str, str] | None = None
) -> list[dict]:
    """The claims rows of ``ids`` decided over the region (their evidence is in
    ``region.outputs``): holds / fails / depends (where) / undecidable."""
    rows = []
    for cid in ids:
        rv = decide_over(region, statement_of(book, cid))
        ev = region.outputs[cid]
        v = np.asarray(ev["value"] if isinstance(ev, Mapping) else ev, float)
        va = v[region.accepted]
        if not np.isfinite(va).any():  # an empty region: the range over every explored vector
            va = v
        rows.append(region_row(book, cid, rv, va, (notes or {}).get(cid, "")))
    return rows


def write_region(path, region: Region, book: ClaimBook, predictions: Sequence[str], prov) -> None:
    """``consistent_region.parquet``: one row per accepted input vector, the inputs (named with
    their units), ``confirmed``, one outcome column per statement and prediction, and the
    predictions' per-point median (``<id>__value``); beside it
    ``region_inputs.parquet`` (the columns brown's studies write): per input why and its
    declared range, the region's projection, the design's resolution (interior, boundary),
    the projection of the points where every prediction holds together, and the counts."""
    cols = region_table(region, statements(book, predictions), predictions)
    write_table(path, cols, prov)
    inp = inputs_table(region, statements(book, predictions))
    write_table(Path(path).with_name("region_inputs.parquet"), inp, prov)


def write_explored(path, region: Region, prov, predictions: Sequence[Statement] = ()) -> None:
    """``<name>.parquet``: one row per *explored* input vector (the region's and the others:
    an empty region still shows what was tried), the inputs (named with their units),
    ``accepted`` (no statement contradicted), ``confirmed``, and per statement its outcome
    (holds / fails / undecided) and its per-point value (``<id>__value``, the median for
    Monte-Carlo evidence); beside it ``<name>_inputs.parquet`` (the columns of
    ``region_inputs.parquet``: per input its declared range, the region's projection, the
    design's resolution). ``predictions`` (evaluated by the same model) add the same two
    columns each."""
    cols: dict[str, list] = {k: v.tolist() for k, v in region.x.items()}
    cols["accepted"] = region.accepted.tolist()
    cols["confirmed"] = region.confirmed.tolist()
    status = [region.status[:, j] for j in range(len(region.statements))]
    status += [outcomes(region, p) for p in predictions]
    for st, o in zip([*region.statements, *predictions], status):
        cols[st.id] = [OUTCOME_NAMES[int(k)] for k in o]
        ev = region.outputs[st.id]
        v = np.asarray(ev["value"] if isinstance(ev, Mapping) else ev, float)
        cols[f"{st.id}__value"] = v.reshape(region.n, -1)[:, 0].tolist()
    p = Path(path)
    write_table(p, cols, prov)
    write_table(p.with_name(f"{p.stem}_inputs.parquet"), inputs_table(region, []), prov)


def region_summary(region: Region) -> str:
    """One sentence: where the region lies, how many points, its resolution."""
    if region.empty:
        conf = "; ".join(" + ".join(c) for c in region.conflicts)
        return (
            f"No input vector of the {region.n} explored is consistent with the printed "
            f"statements (conflicting: {conf})."
        )
    res = ", ".join(
        f"{k} {_g(a)} ({_g(b)} at the boundary)"
        for k, (a, b) in region.resolution.items()
        if not any(i.name == k and i.low == i.high for i in region.inputs)
    )
    return (
        f"The printed statements leave {int(region.accepted.sum())} of the {region.n} explored "
        f"input vectors: {region.describe()} (resolution: {res})."
    )


def _g(x: float) -> str:
    return f"{x:.3g}"
