"""The ``network`` study kind: a user's plane measuring set-up declared as data.

Points, stations, observations (distances with Brown's additive constant and offset,
directions, angles, coordinate differences, weighted coordinates), the datum and the outputs
are all in the study file (:mod:`.schema`, :mod:`.definition`); the adjustment runs on the one
engine (:mod:`sim.lsq`). Outputs: per point analytic and Monte-Carlo precision and 95 %
ellipses with their coverage, per observation redundancy numbers, minimal detectable biases
and their effect on the coordinates, the false-alarm rate of the global test, the dilution
against a second parameterisation, other datums by S-transformation, and the network in
GNU Gama's ``gama-local`` XML (:mod:`.gama`). Examples: ``studies/network_*.toml``.

Modules: :mod:`.schema`, :mod:`.definition` (the network from the study file), :mod:`.model`
and :mod:`.kernel` (observation model), :mod:`.analysis` and :mod:`.sparse_analysis`
(pre-analysis and Monte-Carlo chunks), :mod:`.run` (the steps), :mod:`.estimates`
(Monte-Carlo estimates from the chunk sums), :mod:`.tables` (one writer per table),
:mod:`.claims` (self-checks and findings), :mod:`.gama` and :mod:`.gama_read`,
:mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Part, Study
from sim.studies.network.bias_checks import bias_notes
from sim.studies.network.schema import SCHEMA, check, unread

STUDIES = {
    "network": Study(
        "network",
        "Network design study (your own instrument as data)",
        "",
        SCHEMA,
        Part("sim.studies.network.run", "run"),
        Part("sim.studies.network.report", "report"),
        check,
        order=90,
        unread=unread,
        notes=bias_notes,
    ),
}
