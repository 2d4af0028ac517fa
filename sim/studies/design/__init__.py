"""Brown's comparator as a design problem (seed ``004_f5bd9e86c308241f.txt``, Brown 1968):
study ``brown_design``.

Modules: :mod:`.schema` (config and checks), :mod:`.cells` (the analytic design trade-off),
:mod:`.chunks` (picklable chunk functions), :mod:`.adaptive` (adaptive trial counts through the
runner), :mod:`.errbudget` (error budget), :mod:`.dilution` (datum), :mod:`.formal` (coverage),
:mod:`.posterior` (emcee), :mod:`.external` (tolerances and external comparisons, linearised),
:mod:`.region` (the unprinted inputs explored jointly), :mod:`.claims` with ``claims.toml`` (the claim
book), :mod:`.run`, :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Part, Study, names_from
from sim.studies.design.checks import check
from sim.studies.design.schema import SCHEMA, SEED

#: the package's functions, imported when first asked for (:func:`sim.studies.names_from`)
__getattr__ = names_from(
    {
        n: "sim.studies.design.cells"
        for n in ("geometry_eval", "measuring_time", "pareto_front", "time_model")
    }
    | {"run": "sim.studies.design.run", "report": "sim.studies.design.report"}
)

__all__ = [
    "STUDIES",
    "SCHEMA",
    "check",
    "geometry_eval",
    "measuring_time",
    "pareto_front",
    "time_model",
]

STUDIES = {
    "brown_design": Study(
        "brown_design",
        "Brown: design trade-offs, calibration tolerances, error "
        "budget, datum, coverage, Bayesian check",
        SEED,
        SCHEMA,
        Part("sim.studies.design.run", "run"),
        Part("sim.studies.design.report", "report"),
        check,
        order=12,
        data=Part("sim.studies.design.data_checks", "DATA"),
    ),
}
