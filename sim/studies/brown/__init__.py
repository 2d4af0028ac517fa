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

from sim.studies import Part, Study
from sim.studies.brown.claim_ids import CONCEPT_ON_PAPER, TABLE1_ON_PAPER
from sim.studies.brown.schema import DILUTION, SEED, TABLE1, as_printed, check

STUDIES = {
    "brown_dilution": Study(
        "brown_dilution",
        "Brown: known stations, dilution, pivot offsets",
        SEED,
        DILUTION,
        Part("sim.studies.brown.run", "run_dilution"),
        Part("sim.studies.brown.report", "report_dilution"),
        check,
        order=10,
        data=Part("sim.studies.brown.data_checks", "DILUTION_DATA"),
        paper_design=CONCEPT_ON_PAPER,
    ),
    "brown_table1": Study(
        "brown_table1",
        "Brown: the production test (Table 1)",
        SEED,
        TABLE1,
        Part("sim.studies.brown.run", "run_table1"),
        Part("sim.studies.brown.report", "report_table1"),
        check,
        order=11,
        data=Part("sim.studies.brown.data_checks", "TABLE1_DATA"),
        paper_design=TABLE1_ON_PAPER,
        as_printed=as_printed,
    ),
}
