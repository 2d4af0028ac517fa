"""Study ``gridplate_two_plates``: comparator calibration with two grid plates (seed
``001_7e3a2951e7fed426.txt``, *Calibration of a Comparator*).

Modules: :mod:`.schema` (config and checks), :mod:`.model` (simulation and per-chunk
reduction), :mod:`.run` (the run), :mod:`.sweep` (unprinted inputs, consistent set),
``claims.toml`` + :mod:`.claims` (scoring), :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Part, Study
from sim.studies.gridplate.schema import SCHEMA

SEED = "001_7e3a2951e7fed426.txt"


STUDIES = {
    "gridplate_two_plates": Study(
        "gridplate_two_plates",
        "Calibration of a comparator with two grid plates",
        SEED,
        SCHEMA,
        Part("sim.studies.gridplate.run", "run"),
        Part("sim.studies.gridplate.report", "report"),
        Part("sim.studies.gridplate.data_checks", "check"),
        order=20,
        data=Part("sim.studies.gridplate.data_checks", "DATA"),
    ),
}
