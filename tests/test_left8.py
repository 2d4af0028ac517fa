"""A run off the paper's design is off the paper's setup (issue 26, left8).

brown_table1 on a 5 x 5 grid at 30 mm (``--set plate.spacing_mm=30``), or on 25 random
points, has the paper's 2(25) - 7 = 43 degrees of freedom and no exact input row that fails:
it was not marked off the paper's setup and its Table 1 predictions were scored as tests of
the paper. A key whose default is a number the paper prints for its own setup is now marked
``printed`` in the study's schema (:func:`sim.mc.schema_helpers.printed`); a run whose value
differs is off the paper's setup (:func:`sim.claims.rules.printed_differs`, applied by
:func:`sim.claims.book.write_claims` with the study's schema): predictions are findings, a
``paper_setup`` self-check is not applicable, the note names the key, its value and the paper's;
``sim check`` marks the printed keys and says so before the run. (left12: a prediction the
study decides on the paper's own setup whatever the run's design, Brown's region rows on
Table 1's plate, keeps its verdict, the paper's, with a note saying so: tests/test_left12.py.)

The survey (:data:`SURVEY`: every paper study's keys that a user can change with ``--set`` or
``[sweep]``, read against its seed):

* brown_table1 (seed 004, Results): the format (245 X 245 mm), the 261 mm scale and the 1 mm
  micrometer, Table 1's plate (pattern grid, 5 x 5, 45 mm), the double settings, the 1.7 um
  setting and the comparator's 1.1 um. Not marked: the station offset, alpha, beta (unprinted,
  the region's), a constant bias (not printed).
* brown_dilution (seed 004, The Concept): the format, the scale, the micrometer. Not marked:
  the layout of the "about 25 well-distributed points" (not printed; the region decides the
  Concept over the extent of a 5 x 5), the unit range sigma, the dilution grids (a sweep).
* brown_design (seed 004): the format, scale, micrometer, the comparator's 1.1 um, the timed
  plate (30 images, 60 and 90 min), Table 1's design (``paper.positions/grid/extent_mm/
  settings/setting_sigma_um``), the budget's printed sources, the Zeiss grid's 33 points at
  0.8 um, the operation's 100 um offset and gap, the calibration's 1 um and 15 arcsec. Not
  marked: the design space (``design.*``, ``coverage.*``), the labelled examples of unprinted
  inputs (offset, beta, pitch, Zeiss layout, ``time.pass_min``), brown_dilution's example
  geometry (``datum.*``).
* wolf_polynomial (seed 000): the 100 x 200 mm area, the 20 mm quadrille, the grid's 1 um,
  line ab's 100 mm, the count's 4 um, three readings, three sets over a month, the cubic,
  Table 1's ten marks, the approach from the lower right, the P-30's 100 by 150 mm format.
  Not marked: the field amplitudes (set so that the simulated "before" discrepancies match
  the printed ones), the region's inputs, the trade-offs' lists.
* gridplate_two_plates (seed 001): two plates, the reading's 1.5 um, the comparator's 1.2 um,
  the stated 0.7 um, the first weighting 1:2. Not marked: grid, spacing, readings per point
  (not printed), the region's inputs, the sweeps.
* salsig_encoders (seed 002): the B8's scales and non-perpendicularity (FIG. 3), the
  comparator's (FIG. 2), the z scale's 12.500, the 5 by 5 marks at 50 mm. Not marked: the
  error sigmas set to reproduce printed unit-weight errors, the region's inputs, the sweeps.
* agnard_block (seed 003): the x-parallax error (half a pixel, 22 cm in height); the block,
  scan, pointing and weights were already exact input rows (``agnard.input.*``), so a run
  with another block is off the paper's setup as ``agnard_block_104`` is. Not marked: the
  format, overlaps and pass rows (not printed), the regions' inputs.
* the network kind: a user's own network, no paper: nothing to mark.

Every shipped study file is on the paper's setup (no printed key differs), so every shipped
verdict stands; no claim book gained a row.
"""

from __future__ import annotations

import ast
import inspect
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import off_paper, printed_differs
from sim.cli import main
from sim.mc.config import Field
from sim.mc.schema_helpers import count, printed
from sim.mc.storage import read_provenance
from sim.studies import get_study, load_study
from sim.studies.brown.schema import TABLE1

ROOT = Path(__file__).resolve().parents[1]

#: every paper study's keys marked printed (the module doc says why each, and why not others)
SURVEY = {
    "brown_table1": {
        "plate.format_mm",
        "plate.pattern",
        "plate.grid",
        "plate.spacing_mm",
        "comparator.scale_length_mm",
        "comparator.micrometer_mm",
        "errors.setting_sigma_um",
        "errors.settings",
        "errors.comparator_sigma_um",
    },
    "brown_dilution": {"plate.format_mm", "comparator.scale_length_mm", "comparator.micrometer_mm"},
    "brown_design": {
        "plate.format_mm",
        "scale.graduated_mm",
        "scale.micrometer_mm",
        "comparator.sigma_um",
        "time.images",
        "time.single_min",
        "time.double_min",
        "paper.positions",
        "paper.grid",
        "paper.extent_mm",
        "paper.settings",
        "paper.setting_sigma_um",
        "budget.graduation_um",
        "budget.scale_spec_um",
        "budget.screw_um",
        "budget.drum_periodic_um",
        "budget.wobble_um",
        "budget.sphericity_um",
        "zeiss.points",
        "zeiss.grid_sigma_um",
        "operation.lateral_offset_um",
        "operation.gap_um",
        "calibration.accuracy_um",
        "calibration.drum_dividing_arcsec",
    },
    "wolf_polynomial": {
        "plate.area_mm",
        "plate.spacing_mm",
        "plate.grid_sigma_um",
        "reduce.ab_mm",
        "reading.count_um",
        "reading.n",
        "calib.n_sets",
        "calib.span_weeks",
        "calib.degree",
        "repeat.n_points",
        "reading.approach",
        "repeat.format_mm",
    },
    "gridplate_two_plates": {
        "plate.count",
        "readings.sigma_um",
        "comparator.coord_sigma_um",
        "grid.sigma_stated_um",
        "analysis.ratio_start",
    },
    "salsig_encoders": {
        "b8.sx_mm_per_digit",
        "b8.sy_mm_per_digit",
        "b8.e_arcsec",
        "marks.grid",
        "marks.extent_mm",
        "comparator.sx",
        "comparator.sy",
        "comparator.e_arcsec",
        "zscale.s_mm_per_digit",
    },
    "agnard_block": {"measure.parallax_px"},
}


def test_the_survey_of_printed_keys():
    found = {n: {k for k, f in get_study(n).schema.items() if f.printed} for n in SURVEY}
    assert found == SURVEY
    # every marked key is one the user can set: a value of the schema with a default
    for n, keys in SURVEY.items():
        schema = get_study(n).schema
        assert all(schema[k].default is not None for k in keys)


def _defaults(schema) -> dict:
    return {k: f.default for k, f in schema.items()}


@pytest.mark.parametrize(
    "changes, named",
    [
        ({"plate.spacing_mm": 30.0}, ["plate.spacing_mm = 30 (paper: 45)"]),
        ({"plate.pattern": "random"}, ["plate.pattern = 'random' (paper: 'grid')"]),
        ({"plate.grid": 4}, ["plate.grid = 4 (paper: 5)"]),
        ({"errors.settings": 1}, ["errors.settings = 1 (paper: 2)"]),
        (
            {"comparator.scale_length_mm": 0.0, "plate.format_mm": 300.0},
            ["plate.format_mm = 300 (paper: 245)", "comparator.scale_length_mm = 0 (paper: 261)"],
        ),
        ({}, []),
        ({"comparator.station_offset_mm": 9.0, "errors.bias_um": 2.0}, []),  # unprinted keys
    ],
)
def test_brown_table1_names_each_printed_key_that_differs(changes, named):
    cfg = {**_defaults(TABLE1), **changes}
    assert printed_differs(TABLE1, cfg) == named


def test_a_key_left_out_of_the_config_has_its_default_and_lists_compare_whole():
    schema = {
        "a": printed(count(5, "a", lo=1)),
        "b": printed(Field([1.0, 2.0], "list[float]", "b")),
        "c": count(3, "c", lo=1),
    }
    assert printed_differs(schema, {"c": 9}) == []
    assert printed_differs(schema, {"a": 5, "b": [1.0, 2.5]}) == ["b = [1, 2.5] (paper: [1, 2])"]


BASE = {"source": "s", "paper": "p", "tol": 0.0}
SPECS = [
    {**BASE, "id": "t.dof", "kind": "self-check", "form": "count", "ref": 43, "paper_setup": True},
    {**BASE, "id": "t.identity", "kind": "self-check", "form": "upper", "ref": 1e-6},
    {**BASE, "id": "t.pred", "kind": "prediction", "form": "value", "ref": 2.0, "tol": 0.5},
]


def _book_rows():
    b = ClaimBook([dict(s) for s in SPECS], [], "<t>")
    return b, [
        b.score("t.dof", 43, interval="exact"),
        b.score("t.identity", 0.0, interval="exact"),
        b.score("t.pred", 2.1, (2.0, 2.2)),
    ]


def test_a_differing_printed_key_makes_the_run_off_the_papers_setup(tmp_path):
    b, rows = _book_rows()
    assert off_paper(rows, b.paper_setup, []) == rows  # on the paper's setup: unchanged
    out = off_paper(rows, b.paper_setup, ["plate.spacing_mm = 30 (paper: 45)"])
    dof, ident, pred = out
    assert (dof["verdict"], dof["outcome"]) == ("not applicable", "holds")
    assert (ident["verdict"], ident["outcome"]) == ("self-check", "holds")
    assert (pred["verdict"], pred["outcome"], pred["holds"]) == ("finding", "holds", None)
    assert "(plate.spacing_mm = 30 (paper: 45))" in pred["note"]
    # write_claims reads the run's configuration from the provenance, with the schema given
    schema = {"plate.spacing_mm": printed(count(45, "spacing", lo=1))}
    for spacing, verdict in ((30, "finding"), (45, "holds")):
        path = tmp_path / f"{spacing}.parquet"
        write_claims(path, rows, {"config": {"plate.spacing_mm": spacing}}, b, schema)
        assert pq.read_table(path).to_pydict()["verdict"][2] == verdict
    write_claims(tmp_path / "none.parquet", rows, {"config": {"plate.spacing_mm": 30}}, b)
    assert pq.read_table(tmp_path / "none.parquet").to_pydict()["verdict"][2] == "holds"


@pytest.mark.parametrize("path", sorted((ROOT / "studies").glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_study_file_is_on_the_papers_printed_setup(path):
    study, cfg = load_study(path)[:2]
    assert printed_differs(study.schema, cfg) == []


def _tiny(name: str) -> list[str]:
    lines = (ROOT / "tests" / "data" / "tiny" / f"{name}.txt").read_text().splitlines()
    return [x for kv in lines for x in ("--set", kv)]


@pytest.mark.parametrize(
    "sets, named",
    [
        (["plate.spacing_mm=30"], "plate.spacing_mm = 30 (paper: 45)"),
        (
            ['plate.pattern="random"', "plate.n_random=25", "plate.random_half_extent_mm=90"],
            "plate.pattern = 'random' (paper: 'grid')",
        ),
    ],
    ids=["grid_at_30mm", "random_25"],
)
def test_brown_table1_on_another_plate_of_25_points_is_off_the_papers_setup(tmp_path, sets, named):
    out = tmp_path / "bt1"
    args = [x for kv in sets for x in ("--set", kv)]
    study = str(ROOT / "studies" / "brown_table1.toml")
    assert main(["run", study, "--out", str(out), *_tiny("brown_table1"), *args]) == 0
    rows = {r["claim"]: r for r in pq.read_table(out / "claims.parquet").to_pylist()}
    dof = rows["brown.table1_closure.dof"]  # 2(25) - 7 = 43, as the paper's
    assert (dof["value"], dof["outcome"], dof["verdict"]) == (43.0, "holds", "not applicable")
    preds = [r for r in rows.values() if r["kind"] == "prediction"]
    # Table 1's five predictions are decided on the paper's own plate (left12): the paper's
    # verdicts, kept, with a note that names the differing key
    assert len(preds) == 5 and all(r["verdict"] != "finding" for r in preds)
    assert all(
        f"independent of this run's design, whose printed inputs differ ({named})" in r["note"]
        for r in preds
    )


def test_another_papers_study_off_its_printed_setup_scores_findings(tmp_path):
    """The same wiring in a second study (gridplate: the paper's first weighting 1:2)."""
    out = tmp_path / "gp"
    study = str(ROOT / "studies" / "gridplate_two_plates.toml")
    sets = [*_tiny("gridplate_two_plates"), "--set", "analysis.ratio_start=3.0"]
    assert main(["run", study, "--out", str(out), *sets]) == 0
    rows = pq.read_table(out / "claims.parquet").to_pylist()
    preds = [r for r in rows if r["kind"] == "prediction"]
    assert preds and all(r["verdict"] == "finding" for r in preds)
    assert all("(analysis.ratio_start = 3 (paper: 2))" in r["note"] for r in preds)


@pytest.mark.parametrize("claims", sorted((ROOT / "results").glob("*/claims.parquet")))
def test_every_shipped_result_was_run_on_the_papers_printed_setup(claims):
    """The runs shipped in results/ keep every verdict: their recorded configuration differs
    from the paper's in no printed key (agnard_block_104 is off the paper's setup by its exact
    input rows, as before)."""
    cfg = read_provenance(claims)["config"]
    assert printed_differs(get_study(cfg["study"]).schema, cfg) == []


def test_sim_check_says_before_the_run_that_it_is_off_the_papers_setup(capsys):
    study = str(ROOT / "studies" / "brown_table1.toml")
    assert main(["check", study, "--set", "plate.spacing_mm=30"]) == 0
    out = capsys.readouterr().out.splitlines()
    spacing = next(x for x in out if x.startswith("plate.spacing_mm = 30.0"))
    assert "printed by the paper: another value is off its setup" in spacing
    assert out[-2].startswith(
        "# off the paper's setup (plate.spacing_mm = 30 (paper: 45)): its predictions will be "
        "findings"
    )
    assert out[-1].startswith("# work: ")
    assert main(["check", study]) == 0
    assert "off the paper's setup" not in capsys.readouterr().out


@pytest.mark.parametrize("name", sorted(SURVEY))
def test_each_papers_study_gives_write_claims_its_schema(name):
    """Each paper study's run hands its own schema to write_claims (read from the run's source:
    a study that left it out would score any printed key's change as the paper's)."""
    study = get_study(name)
    run = getattr(study.run, "function", study.run)  # a Part: the function it names
    module = sys.modules[run.__module__]
    tree = ast.parse(inspect.getsource(module))
    fn = next(
        n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == run.__name__
    )
    calls = [
        c
        for c in ast.walk(fn)
        if isinstance(c, ast.Call) and getattr(c.func, "id", None) == "write_claims"
    ]
    assert len(calls) == 1 and len(calls[0].args) == 5
    assert getattr(module, calls[0].args[4].id) is study.schema
