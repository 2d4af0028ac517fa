"""salsig_encoders' size for the work and memory estimate (:mod:`sim.mc.estimate`): its
trials (the calibration chain, the power grid, the relief sweep and the consistency checks),
adjustments, and the memory of a chunk (bytes a trial and a point of the most points) or of
the region's models, all held at once, with the keys that set it. Memory in bytes; see
:func:`salsig_estimate`."""

from __future__ import annotations

from typing import Mapping

from sim.mc.workunits import max_of as _max
from sim.mc.workunits import n_of as _n

__all__ = ["salsig_estimate", "SALSIG_TRIAL_BYTES", "SALSIG_POINT_BYTES"]


def salsig_estimate(c: Mapping) -> tuple:
    """``(trials, adjustments, unknowns, bytes, "", (0, "", ""), keys)``: ``keys`` set the
    memory, ``chunk`` and the key of the most points, or ``region.trials``."""
    T, ch = c["trials"], min(c["chunk"], c["trials"])
    marks = c.get("marks.grid", 5) ** 2
    grid = c.get("grid.points", 5) ** 2
    pm = _max(c.get("power.marks"), 5) ** 2
    cells = _n(c.get("power.marks", [])) * _n(c.get("power.sigma_um", []))
    pT = c.get("power.trials", 0)
    relief = _n(c.get("vertical.relief_sweep_mm", [])) * min(T, 5000) + c.get(
        "consistency.trials", 0
    ) * sum(_n(v) for k, v in c.items() if k.startswith("consistency.") and isinstance(v, list))
    trials = 3 * T + cells * pT + relief
    adj = 6 * T + 3 * cells * pT + 2 * relief
    counts = {
        "marks.grid": marks,
        "grid.points": grid,
        "power.marks": pm,
        "zscale.points": c.get("zscale.points", 9),
        "vertical.control": c.get("vertical.control", 6),
    }
    most = max(counts, key=counts.get)  # the key of the most points
    b = ch * (SALSIG_TRIAL_BYTES + counts[most] * SALSIG_POINT_BYTES)
    # the region: region.trials models at each of region.points input vectors, all of them in
    # memory at once (measured, one core: 2.6 ms + 24 us a model a vector, 7.7 s for 1,024 x
    # 200 and 6.5 s for 128 x 2,000; 617 MB for 100,000 models of up to 20 control points)
    rT = c.get("region.trials", 0)
    adj += c.get("region.points", 0) * (51.0 + 0.47 * rT)
    if rT * SALSIG_REGION_MODEL_BYTES > b:  # the region's models, all at once
        return trials, adj, 7, rT * SALSIG_REGION_MODEL_BYTES, "", (0.0, "", ""), ("region.trials",)
    return trials, adj, 7, b, "", (0.0, "", ""), ("chunk", most)


#: bytes a trial of a salsig chunk holds, and per point (marks, grid intersections, elevations
#: or control points, the most of them): measured with tracemalloc, chunks of 1,000, the
#: calibration chain 34 kB a trial at the paper's 5 x 5 marks and 97 kB at 20 x 20, the
#: vertical fit 30 kB at 100 control points. The model before, 2,304 bytes a point with
#: ``vertical.control`` (a count of points) squared, refused 100 control points at 21.5 GiB for
#: a chunk of 30 MiB
SALSIG_TRIAL_BYTES, SALSIG_POINT_BYTES = 4.0e4, 200.0
#: bytes of one simulated model of salsig's region (6.2 kB measured, with copies' headroom)
SALSIG_REGION_MODEL_BYTES = 1.0e4
