"""Study ``salsig_encoders``: Salsig 1985, *Calibrating Stereo Plotter Encoders* (seed
``002_fb81c7b0481438c4.txt``).

Modules: :mod:`.schema` (config and checks), :mod:`.printed` (the paper's printed data),
:mod:`.model` (simulation, chunk functions), :mod:`.run`, :mod:`.sweep` (unprinted inputs,
consistent set), ``claims.toml`` + :mod:`.claims` (scoring), :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Study, data_check
from sim.studies.salsig.claims import load_book, scored_ids
from sim.studies.salsig.model import (  # noqa: F401
    decompositions,
    simulate_chain,
    simulate_vertical,
    simulate_zscale,
)
from sim.studies.salsig.region import _KEYS, DECLARATION, check_vertical, nominal
from sim.studies.salsig.report import report
from sim.studies.salsig.run import run
from sim.studies.salsig.schema import SCHEMA, check

SEED = "002_fb81c7b0481438c4.txt"


def _check(cfg: dict) -> None:
    """The schema's cross-key rules, then the control errors the region explores."""
    check(cfg)
    check_vertical(cfg)


STUDIES = {
    "salsig_encoders": Study(
        "salsig_encoders",
        "Salsig: calibrating stereo plotter encoders",
        SEED,
        SCHEMA,
        run,
        report,
        _check,
        order=30,
        data=data_check(
            load_book,
            (DECLARATION, nominal, {**_KEYS, "control_1": "vertical.control"}),
            scored=scored_ids,
        ),
    ),
}
