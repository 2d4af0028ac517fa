"""How every interval and verdict of a claims table was made, written into the table's
provenance (``claims.parquet``'s metadata ``intervals``): the interval methods, the decision
thresholds and the sample-size rule of region verdicts. Read by :func:`sim.claims.book.write_claims`."""

from __future__ import annotations

from typing import Any

from sim.claims.intervals import LEVEL, METHODS, MIN_CHUNKS
from sim.claims.region import REGION_LEVEL, REGION_MIN_POINTS, REGION_SHARE
from sim.claims.rules import MIN_CHAIN_TAU, MIN_PLATES, P_FAIL

__all__ = ["interval_provenance"]


def interval_provenance() -> dict[str, Any]:
    """How every interval and verdict of a claims table was made, for its provenance: the
    interval methods (:data:`sim.claims.intervals.METHODS`) and the decision thresholds,
    with the sample-size rule of region verdicts (:mod:`sim.claims.region`)."""
    return {
        "level": LEVEL,
        "methods": dict(METHODS),
        "min_chunks": MIN_CHUNKS,
        "one_plate_p_fail": P_FAIL,
        "one_plate_min_plates": MIN_PLATES,
        "region_min_points": REGION_MIN_POINTS,
        "region_share": REGION_SHARE,
        "region_level": REGION_LEVEL,
        "chain_min_tau": MIN_CHAIN_TAU,
        "interval_column": {
            "ci": "a Monte-Carlo confidence interval (mean, sd, share, bootstrap or jackknife)",
            "spread": "the one-plate 2.5-97.5 % range over simulated plates",
            "exact": "a deterministic value (or its range over the rounding of printed inputs)",
            "region": "decided over the consistent region of unprinted inputs (sim.claims.region)",
        },
    }
