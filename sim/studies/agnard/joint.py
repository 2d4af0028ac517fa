"""Table 3's 5-control rows decided over the lost layout AND the scanner's unprinted inputs
together (seed ``003_5ce730a990a7ebc5.txt``, issue 21).

Two regions hold what the paper leaves open for these rows: the lost five-point layout with
the projection-centres option (``region.toml``, :func:`.region.explore_region`: 16 insets x
2 options, 150 blocks each at the configured scanner) and the scanner (``scanner.toml``,
:func:`.region.explore_scanner`: 16 vectors, Table 1 set aside as not comparable so every
vector stays). The scanner moves the 5-control rows well beyond their Monte-Carlo noise
(check X / Y / Z up to +18 / +26 / +54 %), so a row is decided over *joint* points
(layout, scanner): it holds if it holds at every one, fails if it fails at every one,
otherwise depends, with where (:func:`sim.claims.region.region_verdict`).
The paper names its program, SPACE-M, which carries each model's projection centres as
model points (Blais's description of the program): the predictions are decided over the
joint points *with* the centres only, and those without them decide the finding rows
(what the rows would be had the program not carried them; :func:`with_option`,
:func:`sim.studies.agnard.decide.over_joint`).

The design: a balanced joint design, not the full product. The full product (32 layout
points x 16 vectors, each pair on the scanner region's 48 paired blocks) costs one 5-control
adjustment of 48 blocks per (scanner, layout point), measured 0.12 s each: 17 x 32 of them
(the configured scanner too, for the pairing) is about 65 s of CPU, against the ~10 s
``make rerun`` can spare. The joint design keeps every explored scanner vector and both
options, and spreads the insets: :data:`JOINT_INSETS` insets of the layout region spanning
its range (its smallest and largest among them) with and without centres, 16 layout points;
vector ``j`` is paired with two of them, without centres at inset ``j mod L`` and with centres
at inset ``(j + L/2) mod L`` (:func:`pairs_of`), so each vector sees both options at two
insets half the range apart and each layout point two vectors: 32 joint points (16 with
centres, deciding the predictions, 16 without, deciding the findings), 48
adjustments (the configured scanner's 16 and the vectors' 32), about 6 s of CPU (measured
with the digital snooping of :mod:`.paired_count` on the same blocks: the scanner part
grows from 7.6-8.3 s to 18.7-19.1 s of CPU, main and this code back to back). Each
joint point is a whole (layout, scanner) input vector; the region's resolution along each
input is that of its own region.

The evidence at a joint point (layout ``l``, vector ``j``) is :mod:`.paired`'s: the layout
point's 150 configured-scanner blocks (the layout region's) moved by the paired shift of the
vector from the configured scanner on the 48 paired blocks *at that layout* (both adjusted
with the same five control points, the same centres' errors: common random numbers), over
the shift's interval, always stretched (the spread's scale over its interval at every joint
point, :func:`.paired.paired_evidence` ``stretch``: the 5-control spreads are wide and
skewed, and checked against 150 blocks simulated directly at each of the 32 joint points
the unstretched map decided 4 of 288 row x point decisions the direct blocks leave
undecided, the stretched one none, with none opposite). So a joint point is decided only
where the shift's own uncertainty does not straddle the decision, and the configured scanner's layout region remains the
example (the layout region's own table, ``consistent_region.parquet``).
"""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import plate_ref
from sim.claims.inference import Region
from sim.studies.agnard.paired import paired_evidence
from sim.studies.agnard.region import CENTRES, CONFIGURED

__all__ = ["JOINT_INSETS", "layout_points", "pairs_of", "joint_region", "with_option"]

#: insets of the layout region in the joint design (each with and without centres)
JOINT_INSETS = 8
INSET = "five_inset_1"


def layout_points(layout: Region, n: int = JOINT_INSETS) -> tuple[tuple[float, bool], ...]:
    """The joint design's layout points: ``n`` of the layout region's explored insets evenly
    spread over their sorted order (the smallest and the largest among them), first each
    without the projection centres, then each with them (``(inset, with centres)``)."""
    u = np.unique(np.asarray(layout.x[INSET], float))
    pick = u[np.unique(np.round(np.linspace(0, u.size - 1, min(n, u.size))).astype(int))]
    return tuple((float(a), c) for c in (False, True) for a in pick)


def pairs_of(j: int, n_points: int) -> tuple[int, ...]:
    """The layout points (indices into :func:`layout_points`, ``n_points`` of them: ``L``
    insets without centres, then the same with) paired with scanner vector ``j``: without
    centres at inset ``j mod L``, with centres at ``(j + L // 2) mod L``."""
    L = n_points // 2
    if L < 1:
        return ()
    return (j % L, L + (j + L // 2) % L)


def _layout_index(layout: Region, inset: float, centres: bool) -> int:
    ok = (np.asarray(layout.x[INSET], float) == inset) & (
        (np.asarray(layout.x[CENTRES], float) > 0.5) == centres
    )
    if not ok.any():
        raise ValueError(f"layout point ({inset}, centres {centres}) was not explored")
    return int(np.flatnonzero(ok)[0])


def joint_region(
    book: ClaimBook,
    layout: Region,
    layout_stats: list[dict],
    scanner: Region,
    scanner_stats: list[dict],
    five: tuple[tuple[float, bool], ...],
    preds: list[str],
) -> Region:
    """The joint points (layout point ``l``, scanner vector ``j``) of the design, every
    ``l`` that vector ``j``'s statistics carry (keys ``five<l>:<claim id>``, the configured
    scanner's beside them, :func:`.region.explore_scanner`): the inputs of both regions,
    the statuses of both regions' statements at the point, and each prediction's evidence
    (:func:`.paired.paired_evidence`, base: the layout point's blocks ``layout_stats``)."""
    pts = [
        (lay, j)
        for j, st in enumerate(scanner_stats)
        for lay in range(len(five))
        if f"five{lay}:{preds[0]}" in st
    ]
    if not pts:
        raise ValueError("no scanner vector carries a 5-control pass: no joint point")
    idx = [_layout_index(layout, *five[lay]) for lay, _ in pts]
    vec = [j for _, j in pts]
    ev: dict[str, dict] = {}
    for cid in preds:
        one = [
            paired_evidence(
                layout_stats[i][cid],
                scanner_stats[j][CONFIGURED + f"five{lay}:{cid}"],
                scanner_stats[j][f"five{lay}:{cid}"][None],
                *plate_ref(book.spec(cid)),
                stretch=True,
            )
            for i, (lay, j) in zip(idx, pts)
        ]
        ev[cid] = {q: np.concatenate([o[q] for o in one]) for q in one[0]}
    x = {k: np.asarray(v)[idx] for k, v in layout.x.items()}
    x.update({k: np.asarray(v)[vec] for k, v in scanner.x.items()})
    return Region(
        [*layout.inputs, *scanner.inputs],
        [*layout.statements, *scanner.statements],
        x,
        np.concatenate([layout.status[idx], scanner.status[vec]], axis=1),
        scanner.level,
        {**layout.resolution, **scanner.resolution},
        ev,
    )


def with_option(region: Region, centres: bool) -> Region:
    """The points of ``region`` (a layout or joint region) with the projection centres
    (``centres`` true: the paper's program, SPACE-M, carries them, so the predictions are
    decided over these) or without them (the finding rows): the same inputs, statements and
    resolution; the status and each evidence array (leading axis the points) of those
    points only."""
    keep = (np.asarray(region.x[CENTRES], float) > 0.5) == centres
    n = region.n

    def cut(v):
        if isinstance(v, dict):
            return {q: cut(a) for q, a in v.items()}
        a = np.asarray(v) if v is not None else None
        return a[keep] if a is not None and a.ndim >= 1 and a.shape[0] == n else v

    return Region(
        region.inputs,
        region.statements,
        {k: np.asarray(v)[keep] for k, v in region.x.items()},
        region.status[keep],
        region.level,
        region.resolution,
        {k: cut(v) for k, v in region.outputs.items()},
    )
