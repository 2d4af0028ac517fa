"""The ids of Brown's predictions decided over the region (:mod:`.region`), and those decided
on the paper's own setup whatever the run's design (:attr:`sim.studies.Study.paper_design`):
data, read by the package's description without loading the region's code."""

from __future__ import annotations

__all__ = [
    "T1",
    "T1_PREDICTIONS",
    "T1_JOINT",
    "CONCEPT_PREDICTIONS",
    "TABLE1_ON_PAPER",
    "CONCEPT_ON_PAPER",
]

T1 = "brown.table1_point_sigma."
T1_PREDICTIONS = (
    T1 + "share_1p1_1p3",
    T1 + "points_ge_1p45",
    T1 + "max_um",
    T1 + "below_closure",
)
T1_JOINT = T1 + "together"
CONCEPT_PREDICTIONS = (
    "brown.known_center.ratio",
    "brown.known_edge.ratio",
    "brown.dilution.range_pct",
    "brown.pivot_extra_dilution.typical_pct",
    "brown.dilution_falls_with_points.monotone",
)
#: the predictions decided over a region on the paper's own setup (Table 1's plate, the
#: built comparator's format and scale: :mod:`sim.instruments.ranges.brown`), which read no key
#: of the run's design (only the region's seed and sizes): on a run off the paper's setup they
#: stay the paper's verdicts (:func:`sim.claims.rules.off_paper`)
TABLE1_ON_PAPER = frozenset((*T1_PREDICTIONS, T1_JOINT))
CONCEPT_ON_PAPER = frozenset(CONCEPT_PREDICTIONS)
