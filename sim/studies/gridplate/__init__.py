"""Study ``gridplate_two_plates``: comparator calibration with two grid plates (seed
``001_7e3a2951e7fed426.txt``, *Calibration of a Comparator*).

Modules: :mod:`.schema` (config and checks), :mod:`.model` (simulation and per-chunk
reduction), :mod:`.run` (the run), :mod:`.sweep` (unprinted inputs, consistent set),
``claims.toml`` + :mod:`.claims` (scoring), :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Study, data_check
from sim.studies.gridplate.beyond import scored_ids
from sim.studies.gridplate.claims import load_book
from sim.studies.gridplate.region import DECLARATION, SCALE_DIFF_KEYS, check_comparator, nominal
from sim.studies.gridplate.report import report
from sim.studies.gridplate.run import run
from sim.studies.gridplate.schema import SCHEMA, check

SEED = "001_7e3a2951e7fed426.txt"


def _check(cfg: dict) -> None:
    """The schema's cross-key rules, then the comparator the region explores."""
    check(cfg)
    check_comparator(cfg)


STUDIES = {
    "gridplate_two_plates": Study(
        "gridplate_two_plates",
        "Calibration of a comparator with two grid plates",
        SEED,
        SCHEMA,
        run,
        report,
        _check,
        order=20,
        data=data_check(
            load_book,
            (
                DECLARATION,
                nominal,
                {
                    "grid_points_1": "plate.grid",
                    "spacing_mm": "plate.spacing_mm",
                    "grid_sigma_true_um": "grid.sigma_true_um",
                    "scale_diff_at_100mm_um": SCALE_DIFF_KEYS,
                },
            ),
            scored=scored_ids,
        ),
    ),
}
