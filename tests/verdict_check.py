"""Helpers for the study tests that decide something (issue 28): the verdict over a region
recomputed from the per-point outcomes a run wrote, and a paper's printed tables read with the
csv module alone (not through the study's own reader)."""

from __future__ import annotations

import csv
from pathlib import Path

from sim.mc.storage import read_table

#: the fewest region points a holds / fails needs: 1 - 0.05**(1/29) = 9.8 % is the first
#: 95 % bound on the disagreeing share at most 10 % (1 - 0.05**(1/28) = 10.1 %)
MIN_POINTS = 29


def region_verdict(outcomes) -> str:
    """The rule of docs/verdict-rules.md 'Over a region', written out here independently of
    sim.claims.region: holds / fails at every point (inconclusive at fewer than 29 points),
    undecidable when no point decides it, depends where it holds at some points and fails at
    others, 'holds or undecided' ('fails or undecided') where it holds (fails) at some points
    and is undecided at the rest. ``None`` or "" marks a row of another part of the region
    table."""
    pts = [o for o in outcomes if o]
    s = set(pts)
    assert s <= {"holds", "fails", "undecided"}, s
    if not s:  # an empty region decides nothing
        return "undecidable"
    if s in ({"holds"}, {"fails"}) and len(pts) < MIN_POINTS:
        return "inconclusive"
    if s == {"holds"}:
        return "holds"
    if s == {"fails"}:
        return "fails"
    if s == {"undecided"}:
        return "undecidable"
    if {"holds", "fails"} <= s:
        return "depends"
    return "holds or undecided" if "holds" in s else "fails or undecided"


def check_region_rows(out: Path) -> int:
    """Every claim decided over the region has the verdict that its per-point outcomes in
    consistent_region.parquet give; returns how many rows were checked."""
    claims = read_table(out / "claims.parquet").to_pylist()
    reg = read_table(out / "consistent_region.parquet").to_pydict()
    rows = [c for c in claims if c["interval"] == "region"]
    for c in rows:
        assert c["claim"] in reg, c["claim"]
        assert c["outcome"] == region_verdict(reg[c["claim"]]), c["claim"]
    return len(rows)


def read_csv(path: Path) -> list[dict]:
    """The rows of a transcribed table (``#`` lines are comments)."""
    lines = [ln for ln in Path(path).read_text().splitlines() if not ln.startswith("#")]
    return list(csv.DictReader(lines))
