"""Study ``salsig_encoders``: Salsig 1985, *Calibrating Stereo Plotter Encoders* (seed
``002_fb81c7b0481438c4.txt``).

Modules: :mod:`.schema` (config and checks), :mod:`.printed` (the paper's printed data),
:mod:`.model` (simulation, chunk functions), :mod:`.run`, :mod:`.sweep` (unprinted inputs,
consistent set), ``claims.toml`` + :mod:`.claims` (scoring), :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Part, Study, names_from
from sim.studies.salsig.schema import SCHEMA

SEED = "002_fb81c7b0481438c4.txt"

#: the package's functions, imported when first asked for (:func:`sim.studies.names_from`)
__getattr__ = names_from(
    {
        n: "sim.studies.salsig.model"
        for n in ("decompositions", "simulate_chain", "simulate_vertical", "simulate_zscale")
    }
    | {"check": "sim.studies.salsig.schema"}
)


STUDIES = {
    "salsig_encoders": Study(
        "salsig_encoders",
        "Salsig: calibrating stereo plotter encoders",
        SEED,
        SCHEMA,
        Part("sim.studies.salsig.run", "run"),
        Part("sim.studies.salsig.report", "report"),
        Part("sim.studies.salsig.data_checks", "check"),
        order=30,
        data=Part("sim.studies.salsig.data_checks", "DATA"),
    ),
}
