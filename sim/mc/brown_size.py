"""The two Brown studies' size for the work and memory estimate (:mod:`sim.mc.estimate`).

A trial adjusts the plate's n points with each model by the reduced normals (each point's
2 x 2 block eliminated, the 7 comparator parameters left), so its work and its arrays grow
with n, not with n times the unknowns: a trial costs :data:`BROWN_POINTS_PER_UNIT` points a
unit adjustment (at least one unit), and each of its 4 n ``errors.settings`` simulated
settings :data:`BROWN_DRAW_UNITS`; a chunk holds :data:`BROWN_POINT_BYTES` a point and trial
besides :data:`BROWN_SETTING_BYTES` a setting, and the run keeps every chunk's error sums of
each model and point (:data:`BROWN_SUM_BYTES` a point) to its end. Sizes in points, work in
unit adjustments, memory in bytes; see :func:`brown_estimate`.
"""

from __future__ import annotations

import math
from typing import Mapping

from sim.mc.workunits import COPIES, F8, REGION_MAX_NEW, region_points
from sim.mc.workunits import n_of as _n

__all__ = [
    "brown_estimate",
    "BROWN_POINTS_PER_UNIT",
    "BROWN_POINT_BYTES",
    "BROWN_REGION_UNITS",
    "BROWN_REGION_BYTES",
    "region_bytes",
]

#: points of a plate one unit adjustment's work adjusts (measured, one core, the reduced
#: normals of 400 to 40,000 points: 0.85 us a point and adjustment, 125 ms a trial of
#: brown_dilution's four adjustments at 200 x 200 points). Counted as one unit a trial
#: whatever the plate, a 200 x 200 grid was estimated 400 times under its time: 4,000 trials
#: (about 8 minutes) passed as 2.4e4 adjustments, a million trials (35 hours) too
BROWN_POINTS_PER_UNIT = 60.0
#: adjustments' worth of a trial of brown_table1: its three models and the a-posteriori
#: covariance of the pivot model's points (measured as two more: 0.083 units a point and trial
#: against brown_dilution's 0.067 for its three models and the bias check's pivot)
BROWN_TABLE1_SOLVES = 5
#: adjustments' worth of a trial of brown_dilution's bias-invariance check
#: (``checks.bias_shift_um``): the shifted pivot adjustment and two restarts of each of the
#: check's two adjustments from their own solutions (:func:`sim.studies.brown.core._polished`),
#: measured as 3.7 of a model's adjustments at 60 points (0.021 s of a trial's 0.038 s, its
#: three models 0.017 s). Counted as the one shifted adjustment, a trial's work was estimated
#: at a quarter of its CPU time once the restarts came
BROWN_BIAS_SOLVES = 4
#: adjustments of brown_dilution's self-check reference under ``errors.bias_um`` (its three
#: models' derivatives of the points by each of the 4 n ranges, two adjustments each:
#: :func:`sim.studies.brown.core.spread_sigma`), each of the plate's n points at
#: :data:`BROWN_POINTS_PER_UNIT`. Left out, 3,600 points with a bias took 150 s (and 11.6 GB)
#: past an estimate of 59 s for the whole run: 7.8 s at 900 points, counted 16 s here
BROWN_SPREAD_ADJUSTMENTS = 3 * 2 * 4
#: unit adjustments of one simulated setting (a normal draw and its average; measured 7 to
#: 30 ns, Table 1 taking the settings' variance too)
BROWN_DRAW_UNITS = 4e-4
#: bytes a trial of a chunk holds per point (measured with tracemalloc: 360 in
#: brown_dilution, 1,100 in brown_table1 with the a-posteriori covariance) and per setting
#: of a point (its four positions' draws: 34 to 56). The model before, a dense Jacobian of
#: 4 n ranges x 2 n + 7 unknowns per trial, estimated a 80 x 80 plate in chunks of 10 at
#: 147 GiB, refused at any limit, for a run of 0.37 GiB
BROWN_POINT_BYTES = {"brown_table1": 1200.0, "brown_dilution": 400.0}
BROWN_SETTING_BYTES = 48.0
#: bytes of one chunk's error sums (first and second moments of 3 models x 2 coordinates) a
#: point, every chunk's kept to the end of the run and copied four times more as they are
#: concatenated, stacked and packed: measured, 200 chunks of a 200 x 200 plate, 3.2 GiB over
#: the interpreter's (400 bytes a point and chunk)
BROWN_SUM_BYTES = 3 * 2 * 2 * F8 * 5
#: unit adjustments of one input vector of brown's region, by study (measured: 16,384 points
#: and 8 rounds, 49,152 vectors, 6.2 s for Table 1's region, 31.5 s for the Concept's, which
#: adds the monotone curves over grids)
BROWN_REGION_UNITS = {"brown_table1": 2.5, "brown_dilution": 13.0}
#: bytes of one input vector of brown's region (tracemalloc peak of the region part, 1,024 to
#: 16,384 points and 0 to 8 rounds): the Concept's keeps every vector's cofactors of its
#: evidence and monotone curves, 24 to 27 kB a vector of the whole region (1.1 GiB at 16,384
#: points and 8 rounds, 49,152 vectors; the run peaked at 1.5 GiB, estimated at 1.5 MiB);
#: Table 1's evaluates a batch at a time, 24 kB a vector of its largest batch (the Sobol
#: design, or a round's :data:`sim.mc.workunits.REGION_MAX_NEW` new ones)
BROWN_REGION_BYTES = 26e3


#: the key that sets the plate's points, by ``plate.pattern``
PLATE_KEYS = {"grid": "plate.grid", "random": "plate.n_random"}


def plate_points(c: Mapping) -> float:
    """Points of the plate ``plate.pattern`` declares."""
    pat = c.get("plate.pattern", "grid")
    if pat == "grid":
        return c.get("plate.grid", 5) ** 2
    if pat == "random":
        return c.get("plate.n_random", 25)
    return max(len(c.get("plate.points", [])), 1)


def region_bytes(c: Mapping) -> float:
    """Bytes brown's region holds at its peak (:data:`BROWN_REGION_BYTES` a vector): every
    vector of the Concept's region (brown_dilution), the largest batch of Table 1's."""
    n, rounds = c.get("region.points", 0), c.get("region.rounds", 0)
    if c.get("study") == "brown_table1":
        return BROWN_REGION_BYTES * max(n, REGION_MAX_NEW if rounds > 0 else 0)
    return BROWN_REGION_BYTES * region_points(c)


def _memory_keys(
    c: Mapping, n: float, n_an: float, chunk_b: float, curves_b: float, region_b: float = 0.0
) -> tuple:
    """The keys that set a Brown run's memory: its chunk's (``chunk``, ``trials``: every
    chunk's sums are kept, the plate's points and ``errors.settings``), the analytic
    curves' (``dilution.grids``, when a grid there has more points than the plate), or the
    region's (``region.points``, ``region.rounds``)."""
    if region_b > max(chunk_b, curves_b):
        return ("region.points", "region.rounds")
    plate = PLATE_KEYS.get(c.get("plate.pattern", "grid"), "plate.points")
    if curves_b > chunk_b:
        return ("dilution.grids",) if n_an > n else (plate,)
    return ("chunk", "trials", plate, "errors.settings")


def brown_estimate(c: Mapping) -> tuple:
    """brown_dilution's or brown_table1's ``(trials, adjustments, unknowns, bytes)``: three
    model adjustments a trial (:data:`BROWN_BIAS_SOLVES` more with the bias check,
    :data:`BROWN_TABLE1_SOLVES` in
    Table 1), each :func:`plate_points` over
    :data:`BROWN_POINTS_PER_UNIT` units (at least one), the settings' draws, the analytic
    dilution curves (three a grid, offset and extent) and the region; the memory the largest
    of a chunk's arrays (:data:`BROWN_POINT_BYTES`, :data:`BROWN_SETTING_BYTES`) with every
    chunk's sums (:data:`BROWN_SUM_BYTES`), the analytic curves' point blocks and the
    region's vectors (:func:`region_bytes`), with the keys that set it
    (:func:`_memory_keys`)."""
    n = plate_points(c)
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    L = c.get("errors.settings", 1)
    U = 2 * n + 7
    per = (
        BROWN_TABLE1_SOLVES
        if c.get("study") == "brown_table1"
        else 3 + BROWN_BIAS_SOLVES * ("checks.bias_shift_um" in c)
    )
    trial = per * max(1.0, n / BROWN_POINTS_PER_UNIT) + 4 * n * L * BROWN_DRAW_UNITS
    grids = c.get("dilution.grids", [])
    n_an = max([n] + [g * g for g in grids])
    analytic = 3 * (
        len(grids) + _n(c.get("dilution.offsets_mm", [])) + _n(c.get("dilution.extents_mm", []))
    )
    point = BROWN_POINT_BYTES.get(c.get("study"), 1200.0) + L * BROWN_SETTING_BYTES
    chunks = math.ceil(T / max(ch, 1))
    chunk_b = ch * n * point + chunks * n * BROWN_SUM_BYTES
    curves_b = 4 * n_an * 7 * F8 * 3 * COPIES
    region = region_points(c) * BROWN_REGION_UNITS.get(c.get("study"), 13.0)
    region_b = region_bytes(c)
    keys = _memory_keys(c, n, n_an, chunk_b, curves_b, region_b)
    what = "the region's input vectors" if region_b > max(chunk_b, curves_b) else ""
    spread = 0.0
    if c.get("study") == "brown_dilution" and c.get("errors.bias_um", 0):
        spread = BROWN_SPREAD_ADJUSTMENTS * n * n / BROWN_POINTS_PER_UNIT
    adj = T * trial + analytic + region + spread
    b = max(chunk_b, curves_b, region_b)
    # the keys besides the trials that make the run costly, when the bias's reference is most
    work_keys = ("errors.bias_um", PLATE_KEYS.get(c.get("plate.pattern", "grid"), "plate.points"))
    wkeys = work_keys if spread > adj / 2 else ()
    return T, adj, max(U, 2 * n_an + 7), b, what, (0.0, "", ""), keys, T, wkeys
