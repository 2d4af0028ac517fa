"""Verdicts of predictions over a consistent region (issue 21 item 2), not at a nominal input.

With the region of :func:`sim.claims.inference.explore` (the input vectors no printed
statement contradicts) and a prediction evaluated at each of its points (per point HOLDS /
FAILS / UNDECIDED by the decision zone of :class:`~sim.claims.inference.Statement`):

* **holds**       it holds at every point of the region;
* **fails**       it fails at every point (no feasible input makes it true);
* **depends**     it holds at some points and fails at others (undecided points may remain);
                  ``holds_where`` gives the projections of the points where it holds
                  ("offset_mm 5-27.5") and ``fails_where`` those where it fails;
* **holds or undecided**  it holds at some points, fails at none, and is undecided at the
                  rest: no feasible input contradicts it, but not every one confirms it;
* **fails or undecided**  it fails at some points, holds at none, and is undecided at the
                  rest: no feasible input confirms it (it is never shown to hold);
* **undecidable** no point of the region decides it (its interval covers values on both sides
                  of the zone everywhere), or the region is empty; ``note`` says what would
                  decide it (the statement's ``decide`` text, or the conflicting statements);
* **inconclusive** it holds (fails) at every point, but the region was sampled at fewer than
                  :data:`REGION_MIN_POINTS` accepted points: too few to say it holds (fails)
                  over the region (the sample-size rule below; the word the claims layer
                  uses for an interval that cannot exclude the alternative,
                  :mod:`sim.claims.rules`).

The rule in one line: the verdict names the set of per-point outcomes over the region
({holds}, {fails}, {holds, fails[, undecided]}, {holds, undecided}, {fails, undecided},
{undecided}); "depends" is kept for a prediction that really turns on the inputs (it holds
somewhere *and* fails somewhere). See :func:`region_verdict`.

The sample-size rule (issues 26/28 follow-up). "holds at all k points" says little when k is
small: read the k accepted points as k independent draws from the region (the exploration's
design measure: a scrambled Sobol design, denser at the boundary after refinement), if the
prediction fails on a share q of the region, all k points hold with probability
``(1 - q)**k``; the exact one-sided 95 % upper bound on q is therefore
``1 - 0.05**(1/k)`` (:func:`share_bound`; the Clopper-Pearson bound for 0 of k, about 3/k,
"the rule of three"). A region verdict **holds** or **fails** needs
``k >= REGION_MIN_POINTS`` accepted points, the smallest k whose bound is at most
:data:`REGION_SHARE` (10 %: k = 29); with fewer it is **inconclusive**, and the note says
"region sampled at k points, ...: a region verdict needs 29 (bounds the share where it fails
under 10 %)". A held (failed) row's note states its bound: "holds at all 35 points of the
region (fails on under 8.2 % of it, 95 %)". "depends" needs no minimum: a point on each
side proves it. The two constants are one rule for every study (no per-study setting).

Nominal input values have no place in these verdicts; they survive only as labelled examples
in figures. :func:`region_table` gives the rows of ``consistent_region.parquet``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from sim.claims.inference import FAILS, HOLDS, UNDECIDED, Region, Statement, status

__all__ = [
    "RegionVerdict",
    "decide_over",
    "region_table",
    "region_row",
    "statement_of",
    "evidence_of_row",
    "REGION_VERDICTS",
    "region_verdict",
    "OUTCOME_NAMES",
    "REGION_LEVEL",
    "REGION_SHARE",
    "REGION_MIN_POINTS",
    "share_bound",
    "points_needed",
    "too_few_note",
    "bound_phrase",
]

REGION_VERDICTS = (
    "holds",
    "fails",
    "depends",
    "holds or undecided",
    "fails or undecided",
    "undecidable",
    "inconclusive",
)
OUTCOME_NAMES = {HOLDS: "holds", FAILS: "fails", UNDECIDED: "undecided"}
#: the confidence of the bound on the disagreeing share of a region verdict
REGION_LEVEL = 0.95
#: the largest share of the region where a "holds" ("fails") region verdict may be wrong
#: (bounded at REGION_LEVEL)
REGION_SHARE = 0.10


@dataclass(frozen=True)
class RegionVerdict:
    """A prediction's verdict over the region, with where it holds and fails."""

    id: str
    verdict: str
    n_points: int
    n_holds: int
    n_fails: int
    holds_where: str
    fails_where: str
    note: str

    @property
    def text(self) -> str:
        if self.verdict == "depends":
            return f"depends: holds for {self.holds_where}; fails for {self.fails_where}"
        if self.verdict == "holds or undecided":
            return f"holds or undecided: holds for {self.holds_where}, fails nowhere"
        if self.verdict == "fails or undecided":
            return f"fails or undecided: holds nowhere; fails for {self.fails_where}"
        return self.verdict + (f" ({self.note})" if self.note else "")


def share_bound(k: int, level: float = REGION_LEVEL) -> float:
    """The exact one-sided ``level`` upper bound on the share of the region where a
    prediction disagrees, when it agrees at all ``k`` accepted points (read as independent
    draws): ``1 - (1 - level)**(1/k)``, the q with ``(1 - q)**k = 1 - level`` (the
    Clopper-Pearson bound for 0 of k; about 3/k at 95 %). 1 for k = 0 (nothing sampled)."""
    if k <= 0:
        return 1.0
    return 1.0 - (1.0 - level) ** (1.0 / k)


def points_needed(share: float = REGION_SHARE, level: float = REGION_LEVEL) -> int:
    """The fewest accepted points whose :func:`share_bound` is at most ``share`` (0 < share
    < 1): 29 for 10 % at 95 %."""
    if not 0 < share < 1 or not 0 < level < 1:
        raise ValueError(f"need 0 < share < 1 and 0 < level < 1, not {share!r}, {level!r}")
    k = 1
    while share_bound(k, level) > share:  # exact, no rounding of log(1 - level) / log(1 - share)
        k += 1
    return k


#: the fewest accepted region points a "holds" or "fails" region verdict needs (29)
REGION_MIN_POINTS = points_needed(REGION_SHARE, REGION_LEVEL)


def region_verdict(
    n_points: int, n_holds: int, n_fails: int, min_points: int = REGION_MIN_POINTS
) -> str:
    """The region verdict from the counts of accepted points where a prediction holds and
    fails (the rest are undecided): the rule of the module doc, in one place. "holds" and
    "fails" need ``n_points >= min_points``; with fewer they are "inconclusive"."""
    if n_points <= 0 or n_holds + n_fails == 0:
        return "undecidable"
    if n_holds == n_points or n_fails == n_points:
        if n_points < min_points:
            return "inconclusive"
        return "holds" if n_holds == n_points else "fails"
    if n_holds and n_fails:
        return "depends"
    return "holds or undecided" if n_holds else "fails or undecided"


def _pct(share: float) -> str:
    return f"{100 * share:.2g} %"


def too_few_note(n_points: int, side: str) -> str:
    """Why a prediction that ``side`` ("holds" / "fails") at all ``n_points`` accepted
    points is inconclusive over the region (fewer than :data:`REGION_MIN_POINTS`)."""
    other = "fails" if side == "holds" else "holds"
    return (
        f"region sampled at {n_points} points, {side} at all of them: a region verdict needs "
        f"{REGION_MIN_POINTS} (bounds the share where it {other} under {_pct(REGION_SHARE)}, "
        f"{_pct(REGION_LEVEL)})"
    )


def bound_phrase(rv: RegionVerdict) -> str:
    """The region-verdict phrase of a claims row that holds (fails) at every accepted point,
    with its :func:`share_bound`: "holds at all 35 points of the region (fails on under
    8.2 % of it, 95 %)"."""
    other = "fails" if rv.verdict == "holds" else "holds"
    return (
        f"{rv.verdict} at all {rv.n_points} points of the region ({other} on under "
        f"{_pct(share_bound(rv.n_points))} of it, {_pct(REGION_LEVEL)})"
    )


def statement_of(book, cid: str, form: str | None = None) -> Statement:
    """A claim-book row (:class:`sim.claims.book.ClaimBook`) as a statement: its printed
    reference, rounding and tol give the same decision zone as the book's rule."""
    s = book.spec(cid)
    ref = s["ref"] if isinstance(s["ref"], list) else [s["ref"], s["ref"]]
    return Statement(
        cid,
        (float(ref[0]), float(ref[1])),
        form or s["form"],
        s.get("decimals"),
        float(s["tol"]),
        s["paper"],
        s["source"],
    )


def evidence_of_row(row: dict) -> dict:
    """A scored claims row as evidence at one point: its interval (and p for one-plate)."""
    p = row.get("p_plate")
    return {
        "value": row["value"],
        "low": row["ci_low"],
        "high": row["ci_high"],
        "p": p if row.get("form") == "one-plate" else None,
    }


def outcomes(region: Region, spec: Statement, evidence: Any = None) -> np.ndarray:
    """The prediction's HOLDS/FAILS/UNDECIDED at every evaluated point of the region
    (``evidence`` defaults to the model's output for ``spec.id``)."""
    ev = region.outputs[spec.id] if evidence is None else evidence
    return status(spec, ev, region.n, region.level)


def decide_over(
    region: Region, spec: Statement, evidence: Any = None, outcome: np.ndarray | None = None
) -> RegionVerdict:
    """The verdict of one prediction over the region (see the module doc); ``outcome``: its
    HOLDS/FAILS/UNDECIDED per point when decided otherwise (a family of rows,
    :mod:`sim.claims.family`), else :func:`outcomes` of ``evidence``."""
    acc = region.accepted
    if not acc.any():
        conf = "; ".join(" + ".join(c) for c in region.conflicts)
        return RegionVerdict(
            spec.id, "undecidable", 0, 0, 0, "nowhere", "nowhere",
            f"none of the {acc.size} explored inputs is consistent with the printed statements"
            f" (conflicting: {conf})",
        )  # fmt: skip
    o = outcomes(region, spec, evidence) if outcome is None else np.asarray(outcome)
    h, f = acc & (o == HOLDS), acc & (o == FAILS)
    nh, nf, n = int(h.sum()), int(f.sum()), int(acc.sum())
    hw = region.describe(h) if nh else "nowhere"
    fw = region.describe(f) if nf else "nowhere"
    v = region_verdict(n, nh, nf)
    if v in ("holds", "fails"):
        note = ""
    elif v == "inconclusive":
        note = too_few_note(n, "holds" if nh else "fails")
    elif v == "undecidable":
        note = spec.decide or "no input of the region decides it"
    else:
        note = f"holds at {nh} of {n} region points, fails at {nf}, undecided at {n - nh - nf}"
    return RegionVerdict(spec.id, v, n, nh, nf, hw, fw, note)


def region_table(
    region: Region, predictions: Sequence[Statement] = (), values: Sequence[str] = ()
) -> dict[str, list]:
    """Rows of ``consistent_region.parquet``: one per accepted input vector; a column per input
    (named with its unit), ``confirmed`` (every printed statement holds, not only none
    contradicted), one ``<id>`` outcome column per printed statement and prediction
    (holds / fails / undecided), and a ``<id>__value`` column for the ids in ``values``."""
    acc = region.accepted
    cols: dict[str, list] = {k: v[acc].tolist() for k, v in region.x.items()}
    cols["confirmed"] = region.confirmed[acc].tolist()
    for j, s in enumerate(region.statements):
        cols[s.id] = [OUTCOME_NAMES[int(o)] for o in region.status[acc, j]]
    for p in predictions:
        cols[p.id] = [OUTCOME_NAMES[int(o)] for o in outcomes(region, p)[acc]]
    for vid in values:
        ev = region.outputs[vid]
        v = np.asarray(ev["value"] if isinstance(ev, dict) else ev, float)
        cols[f"{vid}__value"] = v[acc].tolist()
    return cols


def region_row(book, cid: str, rv: RegionVerdict, values, note: str = "") -> dict[str, Any]:
    """The claims row of prediction ``cid`` decided over the region: ``value``/``value_high``
    and the interval are the smallest and largest value over the region's points
    (``interval = "region"``), ``outcome``/``verdict`` the region verdict (holds / fails /
    depends / ... / inconclusive), and the note says where it holds and fails (a held or
    failed row with the bound on the share of the region where it is wrong)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    lo, hi = (float(v.min()), float(v.max())) if v.size else (np.nan, np.nan)
    if v.size:
        row = book.score(cid, lo, (lo, lo), "exact", value_high=hi)
    else:  # an empty region: no value (written as null), the verdict says why
        row = book.score(cid, 0.0, (0.0, 0.0), "exact")
        row.update(value_high=hi)
    where = {
        "holds": bound_phrase(rv),
        "fails": bound_phrase(rv),
        "inconclusive": f"inconclusive: {rv.note}",
        "depends": f"holds for {rv.holds_where}; fails for {rv.fails_where} ({rv.note})",
        "holds or undecided": (
            f"holds for {rv.holds_where}, fails nowhere in the region, undecided at the rest "
            f"({rv.note})"
        ),
        "fails or undecided": (
            f"holds nowhere in the region; fails for {rv.fails_where}, undecided at the rest "
            f"({rv.note})"
        ),
        "undecidable": f"undecidable: {rv.note}",
    }[rv.verdict]
    row.update(
        ci_low=lo,
        ci_high=hi,
        value=lo,
        interval="region",
        outcome=rv.verdict,
        verdict=rv.verdict if row["kind"] in ("prediction", "paper-check") else row["verdict"],
        holds={"holds": True, "fails": False}.get(rv.verdict),
        note="; ".join(x for x in (where, note) if x),
    )
    if row["kind"] == "paper-check" and rv.verdict == "fails":
        row["verdict"] = "erratum"  # holds is already False (the region fails)
    return row


#: columns of ``region_inputs.parquet``, in order
INPUT_COLUMNS = (
    "input",
    "why",
    "declared_low",
    "declared_high",
    "region_low",
    "region_high",
    "resolution_interior",
    "resolution_boundary",
    "together_low",
    "together_high",
    "n_points",
    "n_region",
    "n_together",
)


def holds_together(region: Region, statements: Sequence[Statement]) -> np.ndarray:
    """The accepted points of ``region`` where every one of ``statements`` holds."""
    ok = region.accepted.copy()
    for st in statements:
        ok &= outcomes(region, st) == HOLDS
    return ok


def inputs_table(region: Region, statements: Sequence[Statement]) -> dict[str, list]:
    """``region_inputs.parquet``: per input its declared range and why, the region's
    projection, the design's resolution (interior, boundary), the projection of the points
    where every one of ``statements`` holds together (NaN where nowhere), and the counts."""
    together = holds_together(region, statements)
    b, t = region.bounds(), region.bounds(together)
    cols: dict[str, list] = {k: [] for k in INPUT_COLUMNS}
    for i in region.inputs:
        values = (
            i.name,
            i.why,
            i.low,
            i.high,
            *b[i.name],
            *region.resolution[i.name],
            *t[i.name],
            region.n,
            int(region.accepted.sum()),
            int(together.sum()),
        )
        for k, v in zip(INPUT_COLUMNS, values):
            cols[k].append(v)
    return cols
