"""gridplate_two_plates' size for the work and memory estimate (:mod:`sim.mc.estimate`).

A trial calibrates ``plate.count`` plates of ``plate.grid`` squared points, each read
``readings.count`` times (:data:`GP_READING_UNITS`, :data:`GP_POINT_UNITS` besides its
adjustments, one unit each); after the trials, the region (``region.*``) draws calibrations at
each of its input vectors without a trial on the bar. The bar fills by the trials' units
(:func:`gridplate_units`) and, once the region is done, by its units: counted one a trial and
the region not at all, its time left was short by the region (about 40 % of the work at the
study's defaults) and the bar stood at 100 % while it ran. Work in unit adjustments, memory in
bytes; see :func:`gridplate_estimate`.
"""

from __future__ import annotations

from typing import Mapping

from sim.mc.workunits import ADJUSTMENT_S
from sim.mc.workunits import n_of as _n

__all__ = [
    "gridplate_estimate",
    "gridplate_units",
    "GP_READING_UNITS",
    "GP_POINT_UNITS",
    "GP_READING_BYTES",
    "GP_POINT_BYTES",
]

#: gridplate_two_plates' trial, measured (one core, chunks of 100, tracemalloc): each reading
#: (plates x points x readings) 0.002 units and 32 bytes, each plate's point 0.04 units and 300
#: bytes besides the adjustments counted one a unit. From 10 units and 20 kB a trial at the
#: study's 2 plates of 5 x 5 points read 4 times to 134 units and 1.5 MB at 4 plates of 15 x 15
#: read 50 times: counted as the adjustments alone (20 units) and as 384 bytes a reading and
#: 4,608 a point, the largest plates were 6.7 times over their estimate in time and 14 times
#: under it in memory (a chunk of 400 refused at 8 GiB that holds 0.6 GiB)
GP_READING_UNITS, GP_POINT_UNITS = 2e-3, 0.04
GP_READING_BYTES, GP_POINT_BYTES = 32.0, 300.0


def gridplate_units(c: Mapping) -> tuple[float, float]:
    """``(a trial's unit adjustments, the region's)``: the bar counts each trial at the first
    and the region, once done, at the second."""
    N = c.get("plate.grid", 5) ** 2
    P, L = c.get("plate.count", 2), c.get("readings.count", 4)
    per = 3 + _n(c.get("analysis.ratios", [])) + _n(c.get("analysis.stated_sigmas_um", []))
    per += GP_READING_UNITS * P * N * L + GP_POINT_UNITS * P * N
    # the region: region.points input vectors, each round up to 4x as many at its boundary;
    # each vector draws region.draws calibrations (measured 0.85 ms + 1.25 us a draw) and
    # counts the iterations of region.iter_calibrations calibrations (a row of each plate each)
    pts = c.get("region.points", 0) * (1 + 4 * c.get("region.rounds", 0))
    draw_s = 0.85e-3 + 1.25e-6 * c.get("region.draws", 0)
    region = pts * (draw_s / ADJUSTMENT_S + c.get("region.iter_calibrations", 0) * 2 * P)
    return per, region


def gridplate_estimate(c: Mapping) -> tuple:
    """gridplate_two_plates' ``(trials, adjustments, unknowns, bytes, ..., bar units)``: the
    trials' and the region's work (:func:`gridplate_units`), a chunk's readings and points."""
    N = c.get("plate.grid", 5) ** 2
    P, L = c.get("plate.count", 2), c.get("readings.count", 4)
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    per, region = gridplate_units(c)
    b = ch * (P * N * L * GP_READING_BYTES + P * N * GP_POINT_BYTES)
    return T, T * per + region, 2 * N + 3, b, "", (0.0, "", ""), (), T * per + region, _keys(c)


def _keys(c: Mapping) -> tuple:
    """The region's keys a refusal over the work limit names when the region outweighs the
    trials (``region.points = 65536`` with ``region.draws = 1e6`` was told to "reduce trials
    or the lists in the study file", which hold no part of it): its points and rounds, and
    the larger of its draws' and its counted calibrations' work."""
    per, region = gridplate_units(c)
    if not region > c["trials"] * per:
        return ()
    draws = gridplate_units({**c, "region.iter_calibrations": 0})[1]
    more = "region.draws" if draws >= region - draws else "region.iter_calibrations"
    return ("region.points", "region.rounds", more)
