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

from sim.studies import Part, Study, names_from
from sim.studies.wolf.checks import check
from sim.studies.wolf.schema import SCHEMA, SEED

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
]

#: the package's functions, imported when first asked for (:func:`sim.studies.names_from`)
__getattr__ = names_from(
    {
        **dict.fromkeys(
            ("degree_chunk", "main_chunk", "stability_chunk"), "sim.studies.wolf.chunks"
        ),
        **dict.fromkeys(("grid_nodes", "mid_cells", "node_index"), "sim.studies.wolf.grid"),
        "reading_error_rms": "sim.studies.wolf.model",
        "run": "sim.studies.wolf.run",
        "report": "sim.studies.wolf.report",
        **dict.fromkeys(
            ("load_table1", "load_table3", "summary", "table1_discrepancies"),
            "sim.studies.wolf.tables",
        ),
    }
)

STUDIES = {
    "wolf_polynomial": Study(
        "wolf_polynomial",
        "Wolf & Pearsall: the Kern PG-2 as a monocomparator",
        SEED,
        SCHEMA,
        Part("sim.studies.wolf.run", "run"),
        Part("sim.studies.wolf.report", "report"),
        check,
        order=40,
        data=Part("sim.studies.wolf.data_checks", "DATA"),
    ),
}
