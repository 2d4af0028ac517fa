"""Families of one-plate claims decided as one test: Holm's step-down correction.

A paper may print several statistics of the *same* plate or block (Agnard's X and Y rms of
one set of check points; Wolf's eight plate means of one table). Scored row by row they are
correlated tests without a multiplicity correction; read together they are one statement
("the block gives these numbers"), decided here by one test over the family:

* the members' one-plate p values (:func:`sim.claims.intervals.plate_p`, the printed rounding
  honoured), each the plug-in ``2 k / n`` of ``n`` simulated plates, enter as the Monte-Carlo
  test's p ``2 (k + 1) / (n + 1)`` (:func:`mc_p`, never 0: one rule for every family, Wolf's
  and Agnard's) and are adjusted by **Holm's step-down rule** (:func:`holm`, valid under any
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
    "mc_p",
    "holm",
    "family_status",
    "family_evidence",
    "family_row",
    "family_outcomes",
    "family_over",
]


def mc_p(p: np.ndarray, n: int) -> np.ndarray:
    """The Monte-Carlo p value of a one-plate ``p`` estimated from ``n`` simulated plates.

    ``p = 2 k / n`` counts the ``k`` plates at least as extreme on the rarer side; the
    Monte-Carlo test's own p is ``2 (k + 1) / (n + 1)`` (the paper's plate counted among the
    simulated ones: Davison & Hinkley 1997, eq. 4.11; Phipson & Smyth 2010), never 0, and a
    test rejecting when it is below 0.05 keeps its level with the Monte-Carlo noise included.
    Holm multiplies the smallest p by the family's size (2 for Agnard's X, Y; 8, 24 for Wolf's
    Table 2), and so the plug-in's discreteness: at ``n = 400`` one plate in 400 (``k = 1``,
    0.005) gave 0.04 over eight and failed a family, two plates (0.08) did not: the region's
    fail/undecided boundary was drawn by single simulated plates (docs/referee-reading.md,
    third reading). Arrays in, arrays out (any shape); ``n`` >= 1."""
    if not n >= 1:
        raise ValueError(f"the number of simulated plates n must be >= 1, not {n!r}")
    return np.minimum(1.0, (np.asarray(p, float) * n + 2.0) / (n + 1.0))


def holm(p) -> np.ndarray:
    """Holm's step-down adjusted p values (valid under any dependence between the tests)."""
    p = np.asarray(p, float)
    m = p.size
    order = np.argsort(p)
    adj = np.minimum(1.0, np.maximum.accumulate((m - np.arange(m)) * p[order]))
    out = np.empty(m)
    out[order] = adj
    return out


def family_status(
    p: np.ndarray, member: np.ndarray, n: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Per point, the family's smallest Holm-adjusted p and its HOLDS / FAILS / UNDECIDED.

    p : (N, K) the K members' one-plate p at N points; member : (N, K) their statuses
    (:data:`~sim.claims.inference.HOLDS`, ...); n : the simulated plates behind each plug-in
    p, which then enter Holm as the Monte-Carlo test's (:func:`mc_p`); ``None`` where ``p``
    already are (Wolf's, :mod:`sim.studies.wolf.region`). FAILS iff the Holm p < 0.05; HOLDS
    iff not and every member HOLDS; UNDECIDED otherwise (a NaN p is UNDECIDED)."""
    p, member = np.atleast_2d(np.asarray(p, float)), np.atleast_2d(member)
    if p.shape != member.shape:
        raise ValueError(f"p {p.shape} and member statuses {member.shape} differ in shape")
    if n is not None:
        p = mc_p(p, n)
    hp = np.array([holm(row).min() if np.isfinite(row).all() else np.nan for row in p])
    st = np.where((member == HOLDS).all(axis=1), HOLDS, UNDECIDED).astype(np.int8)
    st[hp < P_FAIL] = FAILS
    st[np.isnan(hp)] = UNDECIDED  # a member without a p decides nothing
    return hp, st


def family_evidence(
    p: np.ndarray, member: np.ndarray, n: int | None = None
) -> dict[str, np.ndarray]:
    """The family's evidence at N points for a region explored by
    :func:`sim.claims.inference.explore`, whose per-point status of the family's claim (a
    ``lower`` bound 0.05 on its Holm p) is :func:`family_status`: ``value`` and ``high`` the
    smallest Holm-adjusted p, ``low`` the same where every member holds and -inf elsewhere
    (so: fails iff the Holm p < 0.05, holds iff not and every member holds, else undecided).
    p, member, n : as in :func:`family_status`."""
    hp, st = family_status(p, member, n)
    return {"value": hp, "low": np.where(st == HOLDS, hp, -np.inf), "high": hp}


def _members_note(rows: Sequence[Mapping[str, Any]], mc: np.ndarray, adj: np.ndarray) -> str:
    return "; ".join(
        f"{r['claim']}: p {r['p_plate']:.3f}, Monte-Carlo p {m:.3f} ({r['outcome']}), "
        f"Holm-adjusted {a:.3f}"
        for r, m, a in zip(rows, mc, adj)
    )


def family_row(
    book, cid: str, members: Sequence[Mapping[str, Any]], note: str = "", *, n: int
) -> dict:
    """The claims row of family ``cid`` from its members' scored one-plate rows (at the
    run's configured inputs, each over ``n`` simulated plates): value the smallest
    Holm-adjusted Monte-Carlo p, the rule of the module doc."""
    p = np.array([r["p_plate"] for r in members], float)
    ok = np.array([HOLDS if r["outcome"] == "holds" else UNDECIDED for r in members])
    hp, st = family_status(p[None], ok[None], n)
    mc = mc_p(p, n)
    text = (
        f"one test of {len(members)} one-plate rows over {n} simulated plates each (the "
        "Monte-Carlo p 2(k+1)/(n+1), Holm's step-down correction): "
        + _members_note(members, mc, holm(mc))
    )
    row = book.score(
        cid, float(hp[0]), interval="exact", note="; ".join(x for x in (text, note) if x)
    )
    outcome = {HOLDS: "holds", FAILS: "fails", UNDECIDED: "inconclusive"}[int(st[0])]
    if outcome != row["outcome"]:  # the lower bound on p alone cannot see an unsharp member
        row.update(outcome=outcome, verdict=outcome, holds=None)
    return row


def family_outcomes(
    book, region: Region, members: Sequence[str], *, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """Per explored point of ``region``, the family's smallest Holm-adjusted p and its
    HOLDS / FAILS / UNDECIDED (:func:`family_status`) from its members' evidence in
    ``region.outputs`` (each with its plug-in one-plate ``p`` over ``n`` simulated plates)."""
    p = np.stack([np.asarray(region.outputs[m]["p"], float) for m in members], axis=1)
    st_m = np.stack([outcomes(region, statement_of(book, m)) for m in members], axis=1)
    return family_status(p, st_m, n)


def family_over(
    book, region: Region, cid: str, members: Sequence[str], note: str = "", *, n: int
) -> dict:
    """The claims row of family ``cid`` decided over ``region`` (its members' p each over
    ``n`` simulated plates): per point the family's status (:func:`family_outcomes`), then
    the region verdict over the accepted points (:func:`sim.claims.region.decide_over`, the
    rule of every prediction)."""
    hp, st = family_outcomes(book, region, members, n=n)
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
    text = (
        f"one test of {', '.join(members)} per point (the Monte-Carlo p 2(k+1)/(n+1) of {n} "
        "simulated plates each, Holm's step-down correction)"
    )
    return region_row(book, cid, rv, hp[acc], "; ".join(x for x in (text, note) if x))
