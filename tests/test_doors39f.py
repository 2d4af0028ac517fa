"""Fuzz, seeds 3901.. and the doors fuzzer's 39001126/7 and 39011126/7 (brief F39), and a new
mutation kind, SPLICE (tests/fuzz_splice.py): bad inputs made by crossing valid ones -- a table
of one study pasted into another's file, a key moved into a sibling or parent table, a table
given twice through dotted keys and a header, an inline table where an array of tables is
expected and back, a network's record with another record's field, a sweep of one study in
another's file; a GNU Gama element under another parent or after another element, the
attributes of one element on another, a ``run.json`` or a table of one run beside another
run's tables. The TOML splices, the attribute splices and the run splices were all refused in
one line naming the file and the key or element (or read as the same document: TOML's dotted
keys and headers are one table); the classes below were found. The seeds' cases of the earlier
kinds found no new class (seed 3901: 300 cases; 3902, 3903, 3910-3912: 60 each, SPLICE among
them). One case each, each failed on the code before its fix.

* A ``<point>`` after the ``<cov-mat>`` of a ``<coordinates>`` (or a ``<vec>`` after that of a
  ``<vectors>``) was read as if before it: with a ``dim`` counting it, the file ran (exit 0),
  where ``gama-local`` refuses any element after a ``<cov-mat>`` ("no observations after
  cov-mat"); with the ``dim`` of the points before it, the line was ``dim 2 for 4
  observations``, counting a point the matrix does not follow. Only ``<obs>`` had the rule.
  Any element after the ``<cov-mat>`` of its parent is now refused naming it (``<cov-mat>:
  one <cov-mat>, the last element of its <coordinates>``).
* A sweep's cell (``cells/<label>/``, which has no ``run.json`` of its own) holding the tables
  of another cell (two cells renamed), of another sweep or of a single run (its ``run.json``
  left out) was shown as the label's cell: ``sim show SWEEP/cells/cell0000_r0`` printed cell
  1's verdicts (``plate.grid = 5``) for the cell that ``sweep.parquet`` says is ``plate.grid =
  4``, and ``Results.table`` read them so. Only the sweep's own tables were checked against
  its ``run.json``. A cell's tables must now be of its row of ``sweep.parquet`` (its seed and
  swept values) and its sweep's code, or they are named (``... is not a table of the cell
  cell0000_r0 of its sweep (seed = 1527215459, the cell's 3175683270) ...``).
* ``--set 'sweep={plate.grid=[4,5]}'`` (or ``sim.load(..., sweep={...})``), the inline-table
  form of ``--set sweep.plate.grid=[4,5]`` (the same in TOML), was ``sweep: unknown key``: the
  user was told the reserved table is unknown, where the dotted form says that a sweep is not
  set by an override and where to write it. Both now say so.
* The doors fuzzer's ``run(workers=2.0)`` was listed as a bad argument, which it is no longer
  (it is 2, as ``trials=400.0`` is 400): seed 39001126's case 11 failed on a valid call. The
  list now holds 2.5.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
TABLE1 = ROOT / "studies" / "brown_table1.toml"
GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
END = "    </points-observations>\n"


def _gama_check(tmp_path, capsys, text: str, *needles: str) -> str:
    x = tmp_path / "net.xml"
    x.write_text(text)
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{x}"\n')
    return one_line(capsys, main(["check", str(study)]), str(x), *needles, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "block, parent",
    [
        (
            '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="4" band="0">1 1 1 1'
            '</cov-mat><point id="C" x="240.0" y="260.0"/></coordinates>',
            "coordinates",
        ),
        (
            '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="2" band="0">1 1'
            '</cov-mat><point id="C" x="240.0" y="260.0"/></coordinates>',
            "coordinates",
        ),
        (
            '<vectors><vec from="A" to="B" dx="250" dy="10" dz="0"/><cov-mat dim="6" band="0">'
            '1 1 1 1 1 1</cov-mat><vec from="A" to="C" dx="1" dy="1" dz="0"/></vectors>',
            "vectors",
        ),
    ],
)
def test_an_element_after_the_cov_mat_of_coordinates_is_refused(tmp_path, capsys, block, parent):
    text = GAMA.read_text()
    assert END in text
    line = _gama_check(
        tmp_path, capsys, text.replace(END, block + "\n" + END), "<cov-mat>: one <cov-mat>, the "
    )
    assert f"the last element of its <{parent}>" in line and "observations" not in line
    ok = '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="2" band="0">1 1</cov-mat>'
    (tmp_path / "net.xml").write_text(text.replace(END, ok + "</coordinates>\n" + END))
    assert main(["check", str(tmp_path / "net.toml")]) == 0, capsys.readouterr().err


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    """A finished tiny sweep of brown_table1 over plate.grid = [4, 5] (two cells, seconds)."""
    d = tmp_path_factory.mktemp("f39")
    text = TABLE1.read_text()
    for key, value in (("trials", 40), ("chunk", 2), ("points", 256), ("rounds", 1)):
        text = re.sub(rf"(?m)^{key} = \S+", f"{key} = {value}", text, count=1)
    (f := d / "sweep.toml").write_text(text + "\n[sweep]\nplate.grid = [4, 5]\n")
    assert main(["run", str(f), "--no-figures", "--quiet", "--out", str(d / "sw")]) == 0
    return d / "sw"


def test_a_sweep_cell_holding_another_cells_tables_is_named(sweep, tmp_path, capsys):
    d = tmp_path / "sw"
    shutil.copytree(sweep, d)
    a, b = d / "cells" / "cell0000_r0", d / "cells" / "cell0001_r0"
    a.rename(tmp_path / "x"), b.rename(a), (tmp_path / "x").rename(b)  # two cells renamed
    capsys.readouterr()
    assert main(["show", str(sweep / "cells" / "cell0000_r0")]) == 0, capsys.readouterr().err
    capsys.readouterr()
    want = "cell0000_r0/claims.parquet is not the table its cell's run wrote"  # its sha256 (S39)
    line = one_line(capsys, main(["show", str(a)]), want, "run the sweep again", prefix=SIM_ERROR)
    with pytest.raises(ConfigError, match="cell0001_r0/claims.parquet is not the table its cell"):
        sim.Results(b, "brown_table1").table("claims")
    _forget_cell_shas(d)  # a sweep recorded before its cells' sha256: the seed tells them apart
    want = "claims.parquet is not a table of the cell cell0000_r0 of its sweep (seed = "
    line = one_line(capsys, main(["show", str(a)]), want, "run the sweep again", prefix=SIM_ERROR)
    assert "plate.grid = 4" not in line
    with pytest.raises(ConfigError, match="is not a table of the cell cell0001_r0 of its sweep"):
        sim.Results(b, "brown_table1").table("claims")
    assert sim.Results(sweep / "cells" / "cell0001_r0", "brown_table1").table("claims").num_rows


def _forget_cell_shas(d):
    """Drop the cells' tables from the sweep's ``table_sha256`` and their values' digests from
    its ``table_shape``, as a sweep recorded before that record had them (its cells then
    checked by their provenance alone)."""
    rec = json.loads((d / "run.json").read_text())
    rec["table_sha256"] = {k: v for k, v in rec["table_sha256"].items() if "/" not in k}
    for k, v in rec["table_shape"].items():  # and the digests of their values (V40's, later)
        if "/" in k:
            v.pop("values", None)
    (d / "run.json").write_text(json.dumps(rec, indent=1, sort_keys=True) + "\n")


@pytest.mark.parametrize("value", ["{plate.grid=[4,5]}", "{ plate = { grid = [4, 5] } }", "3"])
def test_a_sweep_given_inline_by_an_override_is_told_where_it_goes(capsys, value):
    rc = main(["check", str(TABLE1), "--set", f"sweep={value}"])
    want = "sweep: unknown key: a sweep is not set by an override; write its keys in the study"
    one_line(capsys, rc, want, "[sweep] table", prefix=SIM_ERROR)
    with pytest.raises(ConfigError, match="a sweep is not set by an override"):
        sim.load(TABLE1, sweep={"plate.grid": [4, 5]})


@pytest.mark.parametrize("splice", ["table", "provenance", "sweep_provenance"])
def test_a_sweep_cell_with_a_table_or_metadata_of_another_is_named(sweep, tmp_path, capsys, splice):
    """The same class, one table or its Parquet metadata spliced: cell 1's points.parquet in
    cell 0, cell 1's (or the sweep table's) provenance on cell 0's claims.parquet."""
    d = tmp_path / "sw"
    shutil.copytree(sweep, d)
    a, b = d / "cells" / "cell0000_r0", d / "cells" / "cell0001_r0"
    if splice == "table":
        shutil.copy(b / "points.parquet", a / "points.parquet")
    else:
        src = b / "claims.parquet" if splice == "provenance" else d / "sweep.parquet"
        meta = dict(pq.read_schema(a / "claims.parquet").metadata)
        meta[b"sim.provenance"] = pq.read_schema(src).metadata[b"sim.provenance"]
        t = pq.read_table(a / "claims.parquet")
        pq.write_table(t.replace_schema_metadata(meta), a / "claims.parquet")
    capsys.readouterr()
    name = "points" if splice == "table" else "claims"
    want = f"cell0000_r0/{name}.parquet is not the table its cell's run wrote"  # sha256 (S39)
    one_line(capsys, main(["show", str(a)]), want, prefix=SIM_ERROR)
    _forget_cell_shas(d)  # a sweep recorded before its cells' sha256: provenance tells them apart
    want = f"{name}.parquet is not a table of the cell cell0000_r0 of its sweep (seed = "
    one_line(capsys, main(["show", str(a)]), want, prefix=SIM_ERROR)
