"""The Brown claims decided over the consistent region of the paper's unprinted inputs.

The instrument and its unprinted inputs with their hardware ranges are declared once in
:mod:`sim.instruments.ranges.brown`; the inference is :mod:`sim.claims.inference`. This module
only supplies Brown's model (analytic cofactors, :mod:`.values`; no Monte-Carlo noise, so
every value is exact) and which printed statements constrain the inputs:

* every study: the 261 mm scale plus the 1 mm micrometer reads every range of the plate,
  from its zero mark: 0 to 262 mm (``hardware.scale_reads``). A point nearer a station than
  the pivot offset beta has no real range (``(r + alpha)^2 + beta^2 = d^2`` with ``d < beta``)
  and a negative range is not on the scale: such a geometry is not buildable and is excluded,
  not left undecided;
* ``brown_table1``: the plate's printed rms error of closure, 1.6 um (the sigma0 that
  scales all 50 printed standard deviations; its rounding 1.55-1.65 um).

The predictions are then decided over the region (:mod:`sim.claims.region`): holds, fails,
depends (with where it holds) or undecidable. Inputs (mm, um): ``station_offset_mm``,
``beta_mm`` (both studies), ``half_extent_mm`` (the Concept's 25 points), ``sigma0_um``
(Table 1). Seed paper 004 (Brown 1968).
"""

from __future__ import annotations

import numpy as np

from sim.claims.inference import (
    FAILS,
    HOLDS,
    Region,
    Statement,
    evaluate,
    explore,
    parse_declaration,
    status,
)
from sim.claims.region import (
    decide_over,
    holds_together,
    outcomes,
    region_row,
    region_table,
    statement_of,
)
from sim.claims.region import inputs_table as region_inputs
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import multilateration as ml
from sim.mc.runner import chunk_rng
from sim.studies.brown import values as V
from sim.studies.brown.claim_ids import (  # noqa: F401 - the region's ids, named from here too
    CONCEPT_ON_PAPER,
    CONCEPT_PREDICTIONS,
    T1,
    T1_JOINT,
    T1_PREDICTIONS,
    TABLE1_ON_PAPER,
)

SCALE = Statement(
    "hardware.scale_reads",
    (0.0, B.REACH_MM),
    "range",
    paper="graduated at one-millimeter intervals over a length of 261 mm ... the micrometer "
    "limits this translation to at most one millimeter (the shortest and the longest range, "
    "mm: both on the scale)",
    source="004, Implementation of the Concept",
)
CLOSURE = "brown.table1_closure.rms_um"
#: the Concept region's outputs for the notes: the points at Table 1's stations, and the
#: known-station ratio on the outer ring of Table 1's plate there
T1_STATIONS = "table1_stations"
RING = "brown.known_edge.ratio@table1_ring"
#: points per side of the format's edge at which "points near the edges" are evaluated
EDGE_POINTS = 25
#: grids of the "more points, less dilution" prediction over the region (same extent)
MONOTONE_GRIDS = (3, 5, 7)


def scale_evidence(P: np.ndarray, TH: np.ndarray) -> np.ndarray:
    """The shortest and the longest range of each geometry ``(G, 2)`` (mm); a range that is
    not real (a point nearer its station than beta) counts as -1 mm, off the scale."""
    with np.errstate(invalid="ignore"):
        r = np.nan_to_num(ml.ranges(P, TH), nan=-1.0)
    return np.stack([r.min(axis=(1, 2)), r.max(axis=(1, 2))], -1)


def inputs(names):
    """The declared inputs ``names`` of the Brown comparator (hardware ranges)."""
    ins, _ = parse_declaration(B.INPUTS)
    by = {i.name: i for i in ins}
    return [by[n] for n in names]


def _edge_points() -> np.ndarray:
    """Points on the format's edge ``(4 EDGE_POINTS - 4, 2)``."""
    h = B.FORMAT_MM / 2
    t = np.linspace(-h, h, EDGE_POINTS)
    ring = [np.column_stack([t, np.full_like(t, s)]) for s in (-h, h)]
    ring += [np.column_stack([np.full_like(t[1:-1], s), t[1:-1]]) for s in (-h, h)]
    return np.concatenate(ring)


# ----------------------------------------------------------------------------- Table 1
def table1_statements() -> dict[str, Statement]:
    """Table 1's printed statements (the closure and the four about the point sigmas) from
    their one declaration, :data:`sim.instruments.ranges.brown.TABLE1` (the claim book's
    rows take the same zones from it)."""
    return {s.id: s for s in parse_declaration(B.TABLE1)[1]}


def table1_model(x: dict) -> dict:
    """Evidence and predictions at ``N`` input vectors (exact, analytic cofactors)."""
    o, b, s0 = x["station_offset_mm"], x["beta_mm"], x["sigma0_um"]
    N = len(o)
    P = np.broadcast_to(B.table1_points(), (N, 25, 2)).copy()
    cof = B.table1_cofactors(o, b)  # (N, 25, 2) sigma / sigma0
    return {
        SCALE.id: scale_evidence(P, B.thetas(o, b)),
        "brown.table1_closure.rms_um": s0,
        **B.table1_statement_evidence(cof, s0),
    }


#: step (um) of the sigma0 grid over the printed closure's rounding on which
#: :func:`table1_stations` looks for a sigma0 at which Table 1's statements hold
SIGMA0_STEP_UM = 0.001


def table1_stations(o: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N,)`` True where the stations (offset, beta; mm) are those of the comparator that
    measured Table 1: the scale reads Table 1's plate and, at some sigma0 within the printed
    closure's rounding (a grid of :data:`SIGMA0_STEP_UM`), no statement of Table 1 is
    contradicted (brown_table1's region with sigma0 projected out; exact cofactors). The
    grid is tried only where the two statements that bound each point's sigmas leave room
    (all below the closure; the largest within the printed 1.5 at some sigma0)."""
    printed = table1_statements()
    lo, hi = printed[CLOSURE].zone
    N = len(o)
    P = np.broadcast_to(B.table1_points(), (N, 25, 2)).copy()
    out = status(SCALE, scale_evidence(P, B.thetas(o, b)), N) != FAILS
    j = np.flatnonzero(out)
    cof = B.table1_cofactors(o[j], b[j])
    top = cof.reshape(len(j), -1).max(axis=1)
    span = {"low": top * lo, "high": top * hi}  # the largest sigma over the closure's rounding
    room = (status(printed[T1 + "below_closure"], cof.reshape(len(j), -1), len(j)) != FAILS) & (
        status(printed[T1 + "max_um"], span, len(j)) != FAILS
    )
    j, cof = j[room], cof[room]
    preds = [printed[c] for c in T1_PREDICTIONS[:3]]  # below_closure: no sigma0, above
    some = np.zeros(len(j), bool)
    for s0 in np.arange(lo, hi + SIGMA0_STEP_UM / 2, SIGMA0_STEP_UM):
        ev = B.table1_statement_evidence(cof, np.full(len(j), s0))
        some |= (evaluate(preds, ev, len(j)) != FAILS).all(axis=1)
    out[:] = False
    out[j[some]] = True
    return out


def _joint(region: Region, preds: list[Statement]) -> np.ndarray:
    ok = np.ones(region.n, bool)
    for p in preds:
        ok &= outcomes(region, p) == HOLDS
    return ok.astype(float)


def table1_region(cfg: dict, book):
    """``(region, predictions, verdicts)`` of Table 1's statements over the region of
    (station offset, beta, sigma0) allowed by the hardware and the printed closure."""
    printed = table1_statements()
    cons = [SCALE, printed[CLOSURE]]
    preds = [printed[c] for c in T1_PREDICTIONS]
    names = ("station_offset_mm", "beta_mm", "sigma0_um")
    rng = chunk_rng(cfg["region.seed"], 97, 0)
    n, rounds = cfg["region.points"], cfg["region.rounds"]
    reg = explore(inputs(names), cons, table1_model, rng, n=n, rounds=rounds, refine_on=preds)
    reg.outputs[T1_JOINT] = _joint(reg, preds)
    joint = statement_of(book, T1_JOINT)
    verdicts = {p.id: decide_over(reg, p) for p in preds + [joint]}
    return reg, preds + [joint], verdicts


# ----------------------------------------------------------------------------- Concept
def concept_model(x: dict) -> dict:
    """Evidence and predictions of the Concept at ``N`` input vectors (25 points, a 5 x 5
    grid reaching the half extent; exact, analytic cofactors). The known-station ratios are
    the idealised Figure-1 system: the edge one over points on the format's edge."""
    o, b, e = x["station_offset_mm"], x["beta_mm"], x["half_extent_mm"]
    N = len(o)
    P = B.grid_of_extent(5, e)
    TH = B.thetas(o, b)
    kn, st, pv = (V.sigmas(P, TH, m) for m in ("known", "stations", "pivot"))
    E = np.broadcast_to(_edge_points(), (N,) + _edge_points().shape).copy()
    edge = V.sigmas(E, TH, "known").max(axis=(1, 2))
    dil = (V.pooled(st) / V.pooled(kn) - 1) * 100
    extra = (V.pooled(pv) / V.pooled(st) - 1) * 100
    return {
        SCALE.id: scale_evidence(P, TH),
        "brown.known_center.ratio": V.pooled(kn[:, 12]),
        "brown.known_edge.ratio": edge,
        "brown.dilution.range_pct": dil,
        "brown.pivot_extra_dilution.typical_pct": np.median(extra, axis=1),
        "edge_reads": B.max_range_mm(E, TH) <= B.REACH_MM,
    }


def ring_ratio(o: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest sigma / sigma_range (x or y), stations known, over the outer ring of Table 1's
    own plate (the 16 points at +-90 mm of its 5 x 5: its points near the edges) ``(N,)``."""
    P = B.table1_points()
    ring = P[np.abs(P).max(axis=1) == np.abs(P).max()]
    R = np.broadcast_to(ring, (len(o),) + ring.shape).copy()
    return V.sigmas(R, B.thetas(o, b), "known").max(axis=(1, 2))


def monotone_at(x: dict) -> np.ndarray:
    """1 where the mean and the largest per-point dilution fall at every step of
    :data:`MONOTONE_GRIDS` (same extent), else 0 ``(N,)``."""
    o, b, e = x["station_offset_mm"], x["beta_mm"], x["half_extent_mm"]
    TH = B.thetas(o, b)
    curve = {}
    for k in MONOTONE_GRIDS:
        P = B.grid_of_extent(k, e)
        kn, st = (V.pooled(V.sigmas(P, TH, m)) for m in ("known", "stations"))
        curve[k] = (st / kn - 1) * 100
    return V.monotone(curve).astype(float)


def concept_region(cfg: dict, book):
    """``(region, predictions, verdicts)`` of the Concept over (station offset, beta, half
    extent of the 25 points) allowed by the hardware."""
    preds = [statement_of(book, c) for c in CONCEPT_PREDICTIONS]
    names = ("station_offset_mm", "beta_mm", "half_extent_mm")
    rng = chunk_rng(cfg["region.seed"], 97, 0)
    n, rounds = cfg["region.points"], cfg["region.rounds"]
    reg = explore(
        inputs(names), [SCALE], concept_model, rng, n=n, rounds=rounds, refine_on=preds[:4]
    )
    mono = np.full(reg.n, np.nan)
    acc = reg.accepted
    mono[acc] = monotone_at(reg.points())
    reg.outputs["brown.dilution_falls_with_points.monotone"] = mono
    t1 = np.zeros(reg.n, bool)  # the built comparator's stations, for the notes
    t1[acc] = table1_stations(reg.x["station_offset_mm"][acc], reg.x["beta_mm"][acc])
    ring = np.full(reg.n, np.nan)
    ring[t1] = ring_ratio(reg.x["station_offset_mm"][t1], reg.x["beta_mm"][t1])
    reg.outputs[T1_STATIONS], reg.outputs[RING] = t1, ring
    verdicts = {p.id: decide_over(reg, p) for p in preds}
    return reg, preds, verdicts


def _counts(st: Statement, v: np.ndarray) -> str:
    o = status(st, v, len(v))
    n, h, f = len(v), int((o == HOLDS).sum()), int((o == FAILS).sum())
    if h == n or f == n:
        return f"{'holds' if h == n else 'fails'} at all {n}"
    return f"holds at {h}, fails at {f}, undecided at {n - h - f}"


def known_edge_lead(reg: Region, st: Statement) -> str:
    """What the paper's own comparator gives, before the Concept's idealised verdict: at the
    region's points whose stations are Table 1's (:func:`table1_stations`), the ratio on
    the format's edge (the row's points) and on the outer ring of Table 1's plate."""
    t1 = reg.accepted & reg.outputs[T1_STATIONS]
    if not t1.any():
        return "no point of the region has the stations of the comparator that measured Table 1; "
    off = reg.x["station_offset_mm"][t1]
    edge, ring = np.asarray(reg.outputs[st.id], float)[t1], reg.outputs[RING][t1]
    return (
        "the comparator that measured Table 1 (stations where Table 1's statements hold, "
        f"{off.min():.3g}-{off.max():.3g} mm out: {int(t1.sum())} of the "
        f"{int(reg.accepted.sum())} region points) gives on the outer ring of Table 1's own "
        f"plate (5 x 5 to +-90 mm: its points near the edges) {_span(ring)}, "
        f"{_counts(st, ring)}; on the format's edge {_span(edge)}, {_counts(st, edge)}. "
        "The Concept's idealised system over every station its 25 points allow (the verdict): "
    )


def _span(v: np.ndarray) -> str:
    return f"{v.min():.3g}-{v.max():.3g}"


_T1_AT = (
    "; analytic (sigma0 x sqrt(cofactor), pivot model, printed to one decimal) over the region "
    "of station offset, beta and sigma0 that the 261 + 1 mm scale and the printed closure "
    "(1.6 um: 1.55-1.65) allow"
)
TABLE1_NOTES = {
    T1 + "share_1p1_1p3": "share of the 50 sigmas printing as 1.1-1.3 um" + _T1_AT,
    T1 + "points_ge_1p45": "points whose larger sigma prints >= 1.5 um (the model's four "
    "stations are symmetric, so its points come in fours: 'two points' read as 2-4)" + _T1_AT,
    T1 + "max_um": "largest of the 50 sigmas (um)" + _T1_AT,
    T1 + "below_closure": "every sigma / sigma0 = sqrt(cofactor) below 1" + _T1_AT,
    T1_JOINT: "1 where the four statements above hold at the same input vector" + _T1_AT,
}
TABLE1_PAIRS = (
    ("station_offset_mm", "sigma0_um"),
    ("station_offset_mm", "beta_mm"),
    ("beta_mm", "sigma0_um"),
)
_C_AT = (
    "; analytic, over the region of station offset, beta and the half extent of a 5 x 5 grid "
    "('about 25 well-distributed points') whose every range the 261 + 1 mm scale reads"
)
CONCEPT_NOTES = {
    "brown.known_center.ratio": "sigma / sigma_range at the centre point, stations known "
    "(rms of x and y)" + _C_AT,
    "brown.known_edge.ratio": "largest sigma / sigma_range (x or y) over points on the "
    "format's edge, stations known (the idealised Figure-1 system: the scale reads those edge "
    "points nowhere in the region)" + _C_AT,
    "brown.dilution.range_pct": "per-point dilution of 'stations' over 'known' (rms of "
    "sigma_x, sigma_y): every one of the 25 points must lie in 5-15 %" + _C_AT,
    "brown.pivot_extra_dilution.typical_pct": "median over the 25 points of the extra "
    "dilution of 'pivot' (alpha and beta free) over 'stations' (%)" + _C_AT,
    "brown.dilution_falls_with_points.monotone": "1 where the mean and the largest per-point "
    f"dilution fall at every step of k x k grids k = {list(MONOTONE_GRIDS)} (same extent)" + _C_AT,
}
CONCEPT_PAIRS = (
    ("station_offset_mm", "half_extent_mm"),
    ("station_offset_mm", "beta_mm"),
    ("half_extent_mm", "beta_mm"),
)


# ----------------------------------------------------------------------------- rows, table
def _values(reg: Region, cid: str) -> np.ndarray:
    v = np.asarray(reg.outputs[cid], float)
    v = v[reg.accepted]
    return v.reshape(len(v), -1)


def rows_of(book, reg: Region, preds, verdicts, notes: dict) -> list[dict]:
    """Claim rows of the predictions over the region (value: the range over the region; for
    element predictions the smallest and largest element)."""
    out = []
    for p in preds:
        v = _values(reg, p.id)
        row = region_row(book, p.id, verdicts[p.id], v.ravel(), notes.get(p.id, ""))
        if p.id in LEADS:  # what the paper's own comparator gives, first
            row["note"] = LEADS[p.id](reg, p) + row["note"]
        out.append(row)
    return out


#: predictions whose note opens with a reading of the built comparator (id -> lead)
LEADS = {"brown.known_edge.ratio": known_edge_lead}


def table_of(reg: Region, preds) -> dict:
    """``consistent_region.parquet``: one row per accepted input vector, a column per input,
    the statements' and predictions' outcomes, the scalar predictions' values, and
    ``together`` (every prediction holds)."""
    scalar = [p.id for p in preds if np.asarray(reg.outputs[p.id]).ndim == 1]
    cols = region_table(reg, preds, values=scalar)
    cols["together"] = together(reg, preds)[reg.accepted].tolist()
    return cols


def together(reg: Region, preds) -> np.ndarray:
    """Accepted points where every prediction holds."""
    return holds_together(reg, preds)


def inputs_table(reg: Region, preds, verdicts) -> dict:
    """``region_inputs.parquet`` (:func:`sim.claims.region.inputs_table`)."""
    return region_inputs(reg, preds)
