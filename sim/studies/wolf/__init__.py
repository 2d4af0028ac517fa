"""Wolf & Pearsall, the Kern PG-2 as a monocomparator (seed ``000_668e60e68f004f98.txt``).

Study ``wolf_polynomial``. A grid plate (66 intersections, 20 mm quadrille over 100 x 200 mm,
coordinates known to about 1 um) is read in a plotter whose measuring system carries a
smooth systematic error field (:mod:`sim.instruments.plotter.errorfields`), in counts of about 4 um, three
readings per intersection averaged; each set is reduced with the paper's non-redundant
two-point transformation and the ten-term cubic is fitted to the pooled sets
(:mod:`sim.instruments.plotter.polynomial`) and applied to check points, an independent plate and photographs.
The paper's Tables 1-3 are recomputed from their printed coordinates (paper checks).
Coordinates in mm, discrepancies in um.

Modules: :mod:`.schema` (the config's keys), :mod:`.checks` (cross-key rules),
:mod:`.grid` (the quadrille), :mod:`.tables` (the transcribed tables),
:mod:`.model` (instrument, readings, reductions), :mod:`.chunks` (picklable chunk functions),
:mod:`.consistent` (sweeps of the unprinted inputs), :mod:`.claims` with ``claims.toml``,
:mod:`.run`, :mod:`.figures`, :mod:`.report`.
"""

from __future__ import annotations

from sim.studies import Study, data_check
from sim.studies.wolf.checks import check
from sim.studies.wolf.chunks import degree_chunk, main_chunk, stability_chunk
from sim.studies.wolf.claims import load_book, scored_ids
from sim.studies.wolf.grid import grid_nodes, mid_cells, node_index
from sim.studies.wolf.model import reading_error_rms
from sim.studies.wolf.region import CELL, DECLARATION, nominal
from sim.studies.wolf.report import report
from sim.studies.wolf.run import run
from sim.studies.wolf.schema import SCHEMA, SEED
from sim.studies.wolf.tables import load_table1, load_table3, summary, table1_discrepancies

__all__ = [
    "STUDIES",
    "SCHEMA",
    "check",
    "run",
    "report",
    "grid_nodes",
    "mid_cells",
    "main_chunk",
    "degree_chunk",
    "stability_chunk",
    "reading_error_rms",
    "load_table1",
    "load_table3",
    "table1_discrepancies",
    "summary",
    "node_index",
    "_index",
]

#: the name the tests knew :func:`node_index` by
_index = node_index

STUDIES = {
    "wolf_polynomial": Study(
        "wolf_polynomial",
        "Wolf & Pearsall: the Kern PG-2 as a monocomparator",
        SEED,
        SCHEMA,
        run,
        report,
        check,
        order=40,
        data=data_check(
            load_book,
            (DECLARATION, nominal, {k: v for k, v in CELL.items() if "." in v}),
            scored=scored_ids,
        ),
    ),
}
