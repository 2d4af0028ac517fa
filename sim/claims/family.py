"""Families of one-plate claims decided as one test: Holm's step-down correction.

A paper may print several statistics of the *same* plate or block (Agnard's X and Y rms of
one set of check points; Wolf's eight plate means of one table). Scored row by row they are
correlated tests without a multiplicity correction; read together they are one statement
("the block gives these numbers"), decided here by one test over the family:

* the members' one-plate p values (:func:`sim.claims.intervals.plate_p`, the printed rounding
  honoured) are adjusted by **Holm's step-down rule** (:func:`holm`, valid under any
  dependence between the members); the family's value is the smallest adjusted p;
* the family **fails** iff that p is below :data:`sim.claims.rules.P_FAIL` (0.05);
  it **holds** iff it does not fail and every member holds by the book's one-plate rule (the
  simulation sharp enough to decide each); otherwise it is **inconclusive** (over a region:
  undecided at that point). This is the book's one-plate rule (:func:`sim.claims.rules.decide`)
  with the family's Holm p in place of one plate's p and "every member's spread inside its
  zone" in place of one spread inside one zone.

:func:`family_row` scores a family at the run's configured inputs from its members' rows,
:func:`family_over` over a consistent region (per point, then
:func:`sim.claims.region.region_verdict`). A family's claim is declared in the claim book as a
``lower`` bound ``ref = 0.05``, ``tol = 0`` on its Holm p.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Mapping, Sequence

import numpy as np

from sim.claims.inference import FAILS, HOLDS, UNDECIDED, Region
from sim.claims.region import decide_over, outcomes, region_row, statement_of
from sim.claims.rules import P_FAIL

__all__ = [
    "holm",
    "family_status",
    "family_evidence",
    "family_row",
    "family_outcomes",
    "family_over",
]


def holm(p) -> np.ndarray:
    """Holm's step-down adjusted p values (valid under any dependence between the tests)."""
    p = np.asarray(p, float)
    m = p.size
    order = np.argsort(p)
    adj = np.minimum(1.0, np.maximum.accumulate((m - np.arange(m)) * p[order]))
    out = np.empty(m)
    out[order] = adj
    return out


def family_status(p: np.ndarray, member: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per point, the family's smallest Holm-adjusted p and its HOLDS / FAILS / UNDECIDED.

    p : (N, K) the K members' one-plate p at N points; member : (N, K) their statuses
    (:data:`~sim.claims.inference.HOLDS`, ...). FAILS iff the Holm p < 0.05; HOLDS iff not
    and every member HOLDS; UNDECIDED otherwise (a NaN p is UNDECIDED)."""
    p, member = np.atleast_2d(np.asarray(p, float)), np.atleast_2d(member)
    if p.shape != member.shape:
        raise ValueError(f"p {p.shape} and member statuses {member.shape} differ in shape")
    hp = np.array([holm(row).min() if np.isfinite(row).all() else np.nan for row in p])
    st = np.where((member == HOLDS).all(axis=1), HOLDS, UNDECIDED).astype(np.int8)
    st[hp < P_FAIL] = FAILS
    st[np.isnan(hp)] = UNDECIDED  # a member without a p decides nothing
    return hp, st


def family_evidence(p: np.ndarray, member: np.ndarray) -> dict[str, np.ndarray]:
    """The family's evidence at N points for a region explored by
    :func:`sim.claims.inference.explore`, whose per-point status of the family's claim (a
    ``lower`` bound 0.05 on its Holm p) is :func:`family_status`: ``value`` and ``high`` the
    smallest Holm-adjusted p, ``low`` the same where every member holds and -inf elsewhere
    (so: fails iff the Holm p < 0.05, holds iff not and every member holds, else undecided).
    p, member : (N, K) as in :func:`family_status`."""
    hp, st = family_status(p, member)
    return {"value": hp, "low": np.where(st == HOLDS, hp, -np.inf), "high": hp}


def _members_note(rows: Sequence[Mapping[str, Any]], adj: np.ndarray) -> str:
    return "; ".join(
        f"{r['claim']}: p {r['p_plate']:.3f} ({r['outcome']}), Holm-adjusted {a:.3f}"
        for r, a in zip(rows, adj)
    )


def family_row(book, cid: str, members: Sequence[Mapping[str, Any]], note: str = "") -> dict:
    """The claims row of family ``cid`` from its members' scored one-plate rows (at the
    run's configured inputs): value the smallest Holm-adjusted p, the rule of the module doc."""
    p = np.array([r["p_plate"] for r in members], float)
    ok = np.array([HOLDS if r["outcome"] == "holds" else UNDECIDED for r in members])
    hp, st = family_status(p[None], ok[None])
    text = (
        f"one test of {len(members)} one-plate rows (Holm's step-down correction): "
        + _members_note(members, holm(p))
    )
    row = book.score(
        cid, float(hp[0]), interval="exact", note="; ".join(x for x in (text, note) if x)
    )
    outcome = {HOLDS: "holds", FAILS: "fails", UNDECIDED: "inconclusive"}[int(st[0])]
    if outcome != row["outcome"]:  # the lower bound on p alone cannot see an unsharp member
        row.update(outcome=outcome, verdict=outcome, holds=None)
    return row


def family_outcomes(book, region: Region, members: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """Per explored point of ``region``, the family's smallest Holm-adjusted p and its
    HOLDS / FAILS / UNDECIDED (:func:`family_status`) from its members' evidence in
    ``region.outputs`` (each with its one-plate ``p``)."""
    p = np.stack([np.asarray(region.outputs[m]["p"], float) for m in members], axis=1)
    st_m = np.stack([outcomes(region, statement_of(book, m)) for m in members], axis=1)
    return family_status(p, st_m)


def family_over(book, region: Region, cid: str, members: Sequence[str], note: str = "") -> dict:
    """The claims row of family ``cid`` decided over ``region``: per point the family's
    status (:func:`family_outcomes`), then the region verdict over the accepted points
    (:func:`sim.claims.region.decide_over`, the rule of every prediction)."""
    hp, st = family_outcomes(book, region, members)
    acc = region.accepted
    why = ""
    if acc.any():
        why = (
            f"no point of the region decides it: the Holm p is {np.nanmin(hp[acc]):.2f}-"
            f"{np.nanmax(hp[acc]):.2f} (never below 0.05), and at every point some member's "
            "one-block spread reaches outside its zone (the block neither confirms nor "
            "contradicts it)"
        )
    rv = decide_over(region, replace(statement_of(book, cid), decide=why), outcome=st)
    text = f"one test of {', '.join(members)} per point (Holm's step-down correction)"
    return region_row(book, cid, rv, hp[acc], "; ".join(x for x in (text, note) if x))
