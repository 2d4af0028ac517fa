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

from sim.studies import Study, data_check
from sim.studies.design.cells import geometry_eval, measuring_time, pareto_front, time_model
from sim.studies.design.checks import check
from sim.studies.design.claims import load_book, scored_ids
from sim.studies.design.report import report
from sim.studies.design.run import run
from sim.studies.design.schema import SCHEMA, SEED

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
        run,
        report,
        check,
        order=12,
        data=data_check(load_book, scored=scored_ids),
    ),
}
