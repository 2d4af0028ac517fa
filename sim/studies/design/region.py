"""brown_design's tolerances and external comparisons decided over the consistent region of
the paper's unprinted inputs (seed 004; replaces the one-input-at-a-time sweep).

The comparator is the one instrument of the Brown studies
(:mod:`sim.instruments.ranges.brown`: 261 + 1 mm scale, stations on the axes, the station
offset and beta with their hardware ranges). Two parts, each explored jointly by
:func:`sim.claims.inference.explore` and decided by :mod:`sim.claims.region`:

* ``tolerances`` (analytic, dense): station offset x beta x screw pitch x sigma0; the
  constraints are that the scale reads every range of Table 1's plate (5 x 5 at 45 mm) and
  that Table 1's printed statements about the same comparator hold at once (sigma0 at the
  printed closure's rounding, :data:`SIGMA0`; 80 % of the sigmas 1.1-1.3 um; two points at
  1.5 um; all below the closure: :data:`TABLE1`, declared once in
  :data:`sim.instruments.ranges.brown.TABLE1` for brown_table1's claim rows too; analytic
  pivot-model cofactors). The
  tolerances are statements about the built comparator ("Operation of the Comparator",
  "Calibration"), the instrument that measured Table 1, so they are decided where Table 1
  puts its stations (6.6-19.1 mm out), not over every offset the scale allows (fifth
  reading: the station offsets where the lateral-offset error exceeds 0.15 um, under 4 mm,
  and where the linearity tolerance exceeds 350 um, over 30 mm, contradict Table 1).
  Predictions: the lateral-offset error, the microscope's linearity tolerance, the drum
  graduation error (:func:`.external.tolerances`).
* ``plates`` (Monte-Carlo plates per point): station offset x beta x sigma0 x the half extent
  of the Zeiss grid's 33 calibrated points (layout not printed) x the error of the
  conventional two-screw comparator the plates were also measured on (not printed). The
  plates are the same built comparator's, so this part has the tolerance part's constraints
  (the scale reads Table 1's plate and Table 1's printed statements hold: the stations Table
  1 puts 6.6-19.1 mm out, the closure 1.55-1.59 um) and the scale must read the Zeiss points
  (:data:`PLATE_STATEMENTS`). Those are analytic, so they are evaluated first at every
  point of a Sobol design and plates are simulated only at the points they leave in the
  region (Table 1 accepts about 3 % of the box, so the design is large and the plates few),
  with the point's sigma0 as the plates' range sigma (the labelled model's 1.63 um
  contradicts Table 1 at every station). Predictions: the two-screw agreement and the two
  Zeiss rows (:func:`.external.external_at`; their interval is the spread over
  ``unprinted.plates`` plates, so the Monte-Carlo noise is part of each point's decision).
  The two-screw agreement is the plate's error plus the other comparator's, after the
  rigid fit: the paper's equal attribution ("if one were to assume that the discrepancies
  ... are equally attributable to both comparators") is the hypothesis by which Brown reads
  his own accuracy off the agreement, not a printed error of the other comparator, so that
  error is explored, not pinned at the simulated comparator's own (third reading). Over the
  region it is that error, not the station, that decides the row (:func:`decided_by`).
"""

from __future__ import annotations

import numpy as np

from sim.claims.inference import (
    FAILS,
    HOLDS,
    Input,
    Statement,
    evaluate,
    explore,
    parse_declaration,
)
from sim.claims.region import (
    decide_over,
    evidence_of_row,
    holds_together,
    inputs_table,
    outcomes,
    region_row,
    region_table,
    statement_of,
)
from sim.instruments.ranges import brown as B
from sim.mc.runner import chunk_rng
from sim.studies.design.claims import verdict_of
from sim.studies.design.external import external_at, paper_points, tolerances, zeiss_points

__all__ = [
    "TOLERANCES",
    "PLATES",
    "TABLE1",
    "SIGMA0",
    "table1_evidence",
    "tolerance_region",
    "plates_region",
    "region_rows",
]

TOLERANCES = (
    "brown.operation.lateral_offset_error_um",
    "brown.calibration.linearity_tolerance_um",
    "brown.calibration.drum_graduation_um",
)
PLATES = (
    "brown.results.two_screw_agreement_um",
    "brown.results.zeiss_discrepancy_um",
    "brown.results.zeiss_comparator_um",
)
PITCH = Input(
    "screw_pitch_mm",
    0.1,
    1.0,
    "pitch of the 2 cm micrometer screw (not printed): fine to coarse micrometer screws",
)
TWO_SCREW = Input(
    "two_screw_sigma_um",
    0.5,
    2.5,
    "error per coordinate of the conventional two-screw comparator of the comparisons (not "
    "printed): 'conventional, one-micron comparators' (Results), from half a micron to "
    "beyond the 2.1 um the paper's equal attribution would give it",
)
ZEISS = Input(
    "zeiss_half_extent_mm",
    40.0,
    115.0,
    "half extent of the 33 calibrated intersections on the 23 x 23 cm Zeiss grid (layout not "
    "printed): at most the grid's +-115 mm",
)
SCALE = Statement(
    "hardware.scale_reads",
    (B.REACH_MM, B.REACH_MM),
    "upper",
    paper="graduated over a length of 261 mm; the micrometer translates the scale by at most "
    "one millimeter (the longest range of Table 1's plate, mm)",
    source="004, Implementation of the Concept",
)
ZEISS_READS = Statement(
    "hardware.scale_reads_zeiss",
    (B.REACH_MM, B.REACH_MM),
    "upper",
    paper="(the longest range to the Zeiss grid's 33 points, mm)",
    source="004, Implementation of the Concept; Results",
)

#: Table 1's printed statements about the comparator the tolerances are stated for, from their
#: one declaration (:data:`sim.instruments.ranges.brown.TABLE1`, whose zones brown_table1's
#: claim rows take too): the closure bounds sigma0 (:data:`SIGMA0`), the four statements about
#: the 50 printed point sigmas (:data:`TABLE1`) are constraints
_PRINTED = {s.id: s for s in parse_declaration(B.TABLE1)[1]}
_CLOSURE = _PRINTED.pop("brown.table1_closure.rms_um")
#: Table 1's printed closure, 1.6 um at its rounding: the range of sigma0 (the closure is a
#: statement about sigma0 alone, so it bounds the input rather than thinning the design)
SIGMA0 = Input(
    "sigma0_um",
    *(round(z, 12) for z in _CLOSURE.zone),  # 1.6 +- 0.05 to the decimal it stands for
    "the plate's rms error of closure: 'the rms error of closure turned out to be 1.6 "
    "microns (Table 1)', at its rounding (brown_table1's input row)",
)
TABLE1 = tuple(_PRINTED.values())
#: the plates part's constraints: the tolerance part's (the scale reads Table 1's plate, Table
#: 1's printed statements hold: the built comparator that measured Table 1, fifth reading)
#: and the scale reads the Zeiss grid's points
PLATE_STATEMENTS = (SCALE, *TABLE1, ZEISS_READS)


def table1_evidence(o, b, s0, alpha_mm: float = B.ALPHA_MM) -> dict:
    """Table 1's statements at ``N`` input vectors (station offset, beta, sigma0; mm, um):
    the 50 printed sigmas are sigma0 x sqrt(cofactor) of the pivot model on Table 1's plate,
    printed to one decimal (exact, analytic; the instrument's rule,
    :func:`sim.instruments.ranges.brown.table1_sigma_stats`, as brown_table1's)."""
    o, b, s0 = (np.asarray(v, float) for v in (o, b, s0))
    cof = B.table1_cofactors(o, b, alpha_mm)  # (N, 25, 2)
    return B.table1_statement_evidence(cof, s0)


def _comparator_inputs():
    ins, _ = parse_declaration(B.INPUTS)
    by = {i.name: i for i in ins}
    return [by["station_offset_mm"], by["beta_mm"]]


def _longest(pts: np.ndarray, o, b) -> np.ndarray:
    P = np.broadcast_to(pts, (len(o),) + pts.shape).copy()
    return B.max_range_mm(P, B.thetas(o, b))


def tolerance_model(cfg: dict):
    pts = paper_points(cfg)

    def model(x):
        o, b, pitch = x["station_offset_mm"], x["beta_mm"], x["screw_pitch_mm"]
        P = np.broadcast_to(pts, (len(o),) + pts.shape).copy()
        TH = B.thetas(o, b, cfg["comparator.alpha_mm"])
        t = tolerances(cfg, B.min_range_mm(P, TH), pitch)
        t1 = table1_evidence(o, b, x["sigma0_um"], cfg["comparator.alpha_mm"])
        return {
            **t1,
            SCALE.id: B.max_range_mm(P, TH),
            TOLERANCES[0]: t["lateral_error_um"],
            TOLERANCES[1]: t["linearity_tol_um"],
            TOLERANCES[2]: t["drum_graduation_um"],
            "r_min_mm": B.min_range_mm(P, TH),
        }

    return model


def _plates_at(cfg: dict, book, x: dict, live: np.ndarray) -> dict:
    """The plate predictions' evidence ``{id: {value, low, high, p}}`` with plates simulated
    at the ``live`` points only (NaN elsewhere: a point a printed statement contradicts is
    outside the region, and its verdict is never read)."""
    n = len(live)
    rows = {c: [] for c in PLATES}
    for j in np.flatnonzero(live):
        e = external_at(
            cfg,
            float(x["station_offset_mm"][j]),
            float(x["beta_mm"][j]),
            float(x[ZEISS.name][j]),
            cfg["budget.pitch_mm"],
            two_screw_um=float(x[TWO_SCREW.name][j]),
            sigma0_um=float(x[SIGMA0.name][j]),
        )
        for c in PLATES:
            rows[c].append(evidence_of_row(verdict_of(book, c, e)))
    out = {}
    for c, r in rows.items():
        ev = {}
        for k in ("value", "low", "high", "p"):
            if book.spec(c)["form"] != "one-plate" and k == "p":
                ev[k] = None  # the one-plate p exists for one-plate rows only
                continue
            v = np.full(n, np.nan)
            v[live] = [np.nan if e[k] is None else e[k] for e in r]
            ev[k] = v
        out[c] = ev
    return out


def plates_model(cfg: dict, book):
    """The plates part: the hardware and Table 1's printed statements first (analytic), then
    ``unprinted.plates`` simulated plates at each point they leave in the region, with the
    point's sigma0 as the plates' range sigma (the plates of the comparator that measured
    Table 1, at a closure at which Table 1's statements hold)."""
    pts = paper_points(cfg)
    alpha = cfg["comparator.alpha_mm"]

    def model(x):
        o, b, z = x["station_offset_mm"], x["beta_mm"], x[ZEISS.name]
        out = table1_evidence(o, b, x[SIGMA0.name], alpha)
        out[SCALE.id] = _longest(pts, o, b)
        out[ZEISS_READS.id] = np.array(
            [_longest(zeiss_points(cfg, zi), [oi], [bi])[0] for oi, bi, zi in zip(o, b, z)]
        )
        live = (evaluate(PLATE_STATEMENTS, out, len(o)) != FAILS).all(axis=1)
        out.update(_plates_at(cfg, book, x, live))
        return out

    return model


def tolerance_region(cfg: dict, book):
    preds = [statement_of(book, c) for c in TOLERANCES]
    reg = explore(
        _comparator_inputs() + [SIGMA0, PITCH],
        [SCALE, *TABLE1],
        tolerance_model(cfg),
        chunk_rng(cfg["region.seed"], 95, 0),
        n=cfg["region.points"],
        rounds=cfg["region.rounds"],
        refine_on=preds,
    )
    return reg, preds, {p.id: decide_over(reg, p) for p in preds}


def plates_region(cfg: dict, book):
    preds = [statement_of(book, c) for c in PLATES]
    reg = explore(
        _comparator_inputs() + [SIGMA0, ZEISS, TWO_SCREW],
        PLATE_STATEMENTS,
        plates_model(cfg, book),
        chunk_rng(cfg["region.seed"], 96, 0),
        n=cfg["region.plate_points"],
        rounds=0,
    )
    return reg, preds, {p.id: decide_over(reg, p) for p in preds}


def _notes(cfg: dict) -> dict[str, str]:
    """How each prediction is computed, with the run's Zeiss points and grid sigma
    (``zeiss.*``) and the accuracy its tolerances are stated for (``calibration.accuracy_um``)."""
    return {
        TOLERANCES[0]: "d^2 / (2 r_min) at the plate's shortest range",
        TOLERANCES[1]: "lateral offset d with d^2 / (2 r_min) = the accuracy "
        f"({cfg['calibration.accuracy_um']:g} um)",
        TOLERANCES[2]: "the dividing error as a fraction of one turn of the screw",
        PLATES[0]: (
            "one plate's rms discrepancy with a two-screw comparator of error "
            "two_screw_sigma_um per coordinate added, after translation and rotation; central "
            "half of the plates of Table 1's plate at the stations and closure sigma0_um where "
            "Table 1's statements hold"
        ),
        PLATES[1]: f"{cfg['zeiss.points']}-point stand-in layout within the half extent, plus "
        f"the grid's {cfg['zeiss.grid_sigma_um']:g} um, at the stations and closure where "
        "Table 1's statements hold",
        PLATES[2]: "the comparator's part of the Zeiss comparison alone",
    }


def decided_by(reg, pred: Statement, name: str) -> str:
    """The sentence saying that the input ``name`` alone separates the points where ``pred``
    fails from those where it holds (every failing point below every holding one, the
    undecided between), and at which stations each lies; "" when it does not."""
    acc, o, x = reg.accepted, outcomes(reg, pred), reg.x[name]
    f, h = acc & (o == FAILS), acc & (o == HOLDS)
    if not (f.any() and h.any()):
        return ""
    a, b = x[f].max(), x[h].min()
    if not (a < b and (o[acc & (x >= b)] == HOLDS).all() and (o[acc & (x <= a)] == FAILS).all()):
        return ""
    off = reg.x["station_offset_mm"]
    fo, ho = (off[f].min(), off[f].max()), (off[h].min(), off[h].max())
    same = fo[0] <= ho[1] and ho[0] <= fo[1]  # the failing and holding stations overlap
    return (
        f"what decides it is {name}{', not the station' if same else ''}: it fails exactly "
        f"where {name} <= {a:.3g} (stations {fo[0]:.3g}-{fo[1]:.3g} mm out) and holds "
        f"exactly where {name} >= {b:.3g} (stations {ho[0]:.3g}-{ho[1]:.3g} mm out), "
        "undecided between; "
    )


#: per prediction, the input whose split :func:`decided_by` reports in the row's note
_DECIDED_BY = {PLATES[0]: TWO_SCREW.name}


def region_rows(book, parts, cfg: dict) -> tuple[list[dict], dict, dict]:
    """Claim rows of every part's predictions, ``consistent_region.parquet`` (the parts'
    tables stacked, ``part`` naming each; an input a part does not have is NaN) and
    ``region_inputs.parquet`` (per part and input: the declared range, the region's
    projection, where every prediction of the part holds, the resolution)."""
    rows, tables, ins, notes = [], [], {k: [] for k in _INPUT_COLS}, _notes(cfg)
    for name, (reg, preds, verdicts) in parts.items():
        where = f" (part '{name}': " + ", ".join(i.name for i in reg.inputs) + ")"
        for p in preds:
            v = np.asarray(
                reg.outputs[p.id]["value"]
                if isinstance(reg.outputs[p.id], dict)
                else reg.outputs[p.id],
                float,
            )
            rows.append(
                region_row(
                    book,
                    p.id,
                    verdicts[p.id],
                    v[reg.accepted],
                    (decided_by(reg, p, _DECIDED_BY[p.id]) if p.id in _DECIDED_BY else "")
                    + notes[p.id]
                    + where,
                )
            )
        t = region_table(reg, preds)
        t["together"] = holds_together(reg, preds)[reg.accepted].tolist()
        t["part"] = [name] * int(reg.accepted.sum())
        tables.append(t)
        part_ins = inputs_table(reg, preds)  # the columns every region study writes
        part_ins["part"] = [name] * len(part_ins["input"])
        for k in _INPUT_COLS:
            ins[k] += part_ins[k]
    keys = list(dict.fromkeys(k for t in tables for k in t))
    numeric = {i.name for reg, _, _ in parts.values() for i in reg.inputs}  # NaN where absent
    table = {k: [] for k in keys}
    for t in tables:
        n = len(t["part"])
        for k in keys:
            table[k] += t.get(k, [float("nan") if k.endswith("_mm") or k in numeric else ""] * n)
    return rows, table, ins


#: columns of ``region_inputs.parquet``: ``part``, then those of
#: :func:`sim.claims.region.inputs_table` in the order this study has always written them
_INPUT_COLS = (
    "part",
    "input",
    "why",
    "declared_low",
    "declared_high",
    "region_low",
    "region_high",
    "together_low",
    "together_high",
    "resolution_interior",
    "resolution_boundary",
    "n_points",
    "n_region",
    "n_together",
)
