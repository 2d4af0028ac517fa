"""Brown's multilaterative comparator (seed ``004_f5bd9e86c308241f.txt``): two studies.

``brown_dilution``: the design simulations of the paper's "Concept" section -- accuracy with
known stations (0.71 sigma centre, 0.85 sigma edges), dilution when the stations are recovered
(5-15 % for 25 points, falling with more points), the pivot offsets alpha and beta ("essentially
no further dilution"), and the immunity to a constant personal bias.

``brown_table1``: the production test of the "Results" section -- a 5 x 5 array at 45 mm,
double settings of 1.7 um, about 1.1 um from the comparator: rms closure 1.6 um on 43 degrees
of freedom; point standard deviations mostly 1.1-1.3 um, two points up to 1.5 um.

The numerics live in :mod:`sim.instruments.ranges.multilateration`; this module simulates, tabulates, draws and
reports. Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

from sim.studies import Study, data_check
from sim.studies.brown.claims import load_book, scored_by
from sim.studies.brown.region import (
    CONCEPT_ON_PAPER,
    T1_JOINT,
    T1_PREDICTIONS,
    TABLE1_ON_PAPER,
)
from sim.studies.brown.report import report_dilution, report_table1
from sim.studies.brown.run import run_dilution, run_table1
from sim.studies.brown.schema import DILUTION, MODEL_NAMES, SEED, TABLE1, as_printed, check


def _dilution_ids(cfg: dict, book) -> list[str]:
    """The ids brown_dilution builds (:func:`.claims.score_dilution`)."""
    return [f"brown.mc_agreement.{m}.mean_ratio" for m in MODEL_NAMES]


def _table1_ids(cfg: dict, book) -> list[str]:
    """The ids brown_table1 builds: Table 1's statements over the region (:mod:`.region`)."""
    return [*T1_PREDICTIONS, T1_JOINT]


STUDIES = {
    "brown_dilution": Study(
        "brown_dilution",
        "Brown: known stations, dilution, pivot offsets",
        SEED,
        DILUTION,
        run_dilution,
        report_dilution,
        check,
        order=10,
        data=data_check(
            lambda: load_book("brown_dilution"),
            scores=scored_by("brown_dilution"),
            scored=_dilution_ids,
        ),
        paper_design=CONCEPT_ON_PAPER,
    ),
    "brown_table1": Study(
        "brown_table1",
        "Brown: the production test (Table 1)",
        SEED,
        TABLE1,
        run_table1,
        report_table1,
        check,
        order=11,
        data=data_check(
            lambda: load_book("brown_table1"), scores=scored_by("brown_table1"), scored=_table1_ids
        ),
        paper_design=TABLE1_ON_PAPER,
        as_printed=as_printed,
    ),
}
