"""The classes of the sweep doors35t (brief T35: results directories touched by hand, every
reader of a results table), one case each; each failed on the code before its fix. The
harness that found them (a copy of every committed results directory and of a sweep, each
table mutated, seeded: a column retyped among text, numbers, true/false, dictionary, large
text and list, renamed or given another unit, a value made null, NaN or infinite, a row
duplicated, the rows reversed or removed, row groups of one row, the schema metadata removed;
each read by ``sim show``, ``sim show --markdown``, ``sim report``, ``sim.Results``,
``--stale-only`` and ``make verify``) lives outside the project.

* A table edited by hand that still parses was read as its run's: a text column retyped as
  true/false printed ``True`` where the paper's source stood, a null printed ``None``, a
  number column rewritten as text printed as that text, a column renamed from ``_mm`` to
  ``_um`` printed in the wrong unit, a row duplicated listed twice, a table emptied left its
  section out; ``sim.Results.table`` returned it as the run's. ``run.json`` now records every
  table's shape (``table_shape``: rows, each column's kind, its null, NaN and infinite
  counts; :mod:`sim.mc.table_shape`), and each reader names the file and the column that
  differ from it.
* The claims table without its schema metadata was "not a claims table written by sim",
  naming nothing: the line says it carries no provenance.
* A value a report failed on was named by its column only ("column 'kind': KeyError: 'x'" of
  a table of 15 rows): the line names its record too. A value read by ``row.get(column)`` was
  not remembered, and the failure was blamed on the column read before it. A number column
  as text in results of a version that recorded no shape is named by what its tolerance
  declares (a rule for numbers).
* agnard_block's ``trials.parquet`` with an ``<adjustment>.converged`` column as text
  (``"False"``, which numpy reads as true) lost its "not converged" line without a word; the
  network kind's ``summary.parquet`` with its counts as text did the same. Both are named.
* ``--stale-only`` (``make reproduce``) called results whose table was edited after its run
  current (only a figure replaced by hand was re-made): the table's sha256 is the one
  ``run.json`` records, or the results are stale, named by the table.
* ``make verify`` passed a committed number column rewritten as text (or true/false): the
  comparison took it for a text column whose changes are not failures. A column of another
  kind than the re-run's fails, naming the file and column.
* ``make verify`` of a table whose tolerance declarations were edited (schema metadata
  ``sim.tolerances`` not JSON, or a list) ended in a JSONDecodeError or TypeError traceback:
  the table fails, naming the metadata.
* ``sim report`` read a claims table whole (every row as Python objects) before checking it:
  a table of a million rows (its rows repeated) took a minute to be named, and a claims table
  whose provenance names another study than its ``run.json`` was read as that study's
  results, and blamed on "another version of the suite's code" for the tables that study
  has. It is checked as ``sim show`` checks it, first.
* A sweep's ``sweep.parquet`` rewritten without its schema metadata was listed by ``sim show``
  without the swept values of its cells (the keys are in its provenance), and ``--markdown``
  said "a table under DIR is not as sim wrote it (KeyError: 'study')", naming no file.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import tiny_overrides
from oneline import one_line

import sim
from sim.batch_checks import why_stale
from sim.cli import main
from sim.mc.config import ConfigError
from sim.report.verify.rerun import verify

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


def _copy(tiny_run, tmp_path: Path) -> Path:
    d = tmp_path / "results" / "brown_table1"
    shutil.copytree(tiny_run("brown_table1"), d)
    return d


def _edit(p: Path, change) -> None:
    """Rewrite the table ``p`` as ``change`` makes it, its schema metadata kept."""
    t = pq.read_table(p)
    pq.write_table(change(t).replace_schema_metadata(t.schema.metadata), p)


def _column(t: pa.Table, name: str, values, type_=None) -> pa.Table:
    return t.set_column(t.schema.get_field_index(name), name, pa.array(values, type_))


def _refused_by_every_reader(capsys, d: Path, table: str, *needles: str) -> None:
    """``sim show --markdown``, ``sim report`` and ``sim.Results.table`` refuse ``d``'s
    ``table`` in one line naming it and the needles."""
    one_line(capsys, main(["show", str(d), "--markdown"]), table, *needles)
    one_line(capsys, main(["report", "--results", str(d.parent)]), table, *needles)
    assert not (d.parent / "REPORT.md").exists()
    with pytest.raises(ConfigError, match=needles[0]):
        sim.Results(d, "brown_table1").table(table.removesuffix(".parquet"))


def test_a_column_retyped_by_hand_is_named_with_its_file_and_column(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    f = d / "not_reproduced.parquet"
    _edit(f, lambda t: _column(t, "source", [True] * t.num_rows))  # was printed "| True |"
    _refused_by_every_reader(capsys, d, "not_reproduced.parquet", "column 'source' is bool")
    shutil.copy(tiny_run("brown_table1") / f.name, f)
    assert main(["show", str(d), "--markdown"]) == 0  # a faithful rewrite (other row groups,
    t = pq.read_table(f)  # the text dictionary-encoded) is read as it is
    t = t.set_column(0, t.column_names[0], t.column(0).dictionary_encode())
    pq.write_table(t, f, row_group_size=1)
    assert main(["show", str(d), "--markdown"]) == 0
    assert sim.Results(d, "brown_table1").table("not_reproduced").num_rows > 0
    record = json.loads((d / "run.json").read_text("utf-8"))  # a record edited into no shape
    record["table_shape"]["not_reproduced.parquet"]["rows"] = 10**400  # (was printed whole)
    (d / "run.json").write_text(json.dumps(record), "utf-8")
    _edit(f, lambda t: _column(t, "source", [True] * t.num_rows))
    rc = main(["show", str(d), "--markdown"])  # the edited table: its sha256 (doors46h)
    assert len(one_line(capsys, rc, "not_reproduced.parquet", "sha256")) < 400


@pytest.mark.parametrize(
    "table, column, value",
    [("not_reproduced.parquet", "source", None), ("claims.parquet", "ref_low", math.nan)],
    ids=["null", "nan"],
)
def test_a_value_blanked_by_hand_is_named(tiny_run, tmp_path, capsys, table, column, value):
    d = _copy(tiny_run, tmp_path)

    def blank(t):
        values = t.column(column).to_pylist()
        values[0] = value
        return _column(t, column, values, t.schema.field(column).type)

    _edit(d / table, blank)  # printed "| None |", a decision zone of "nan"
    _refused_by_every_reader(capsys, d, table, f"column '{column}' holds 1 ")


def test_a_column_renamed_to_another_unit_is_named(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    _edit(
        d / "consistent_region.parquet",  # its inputs were listed "station_offset_um 12-20"
        lambda t: t.rename_columns(
            [c.replace("station_offset_mm", "station_offset_um") for c in t.column_names]
        ),
    )
    _refused_by_every_reader(
        capsys, d, "consistent_region.parquet", "has no column 'station_offset_mm'", "_um'"
    )


@pytest.mark.parametrize(
    "rows", [lambda t: pa.concat_tables([t, t.slice(0, 1)]), lambda t: t.slice(0, 0)]
)
def test_rows_added_or_removed_by_hand_are_named(tiny_run, tmp_path, capsys, rows):
    d = _copy(tiny_run, tmp_path)
    _edit(d / "not_reproduced.parquet", rows)  # a row listed twice, or the section left out
    _refused_by_every_reader(capsys, d, "not_reproduced.parquet", "rows where its run wrote 4")


def test_a_claims_table_without_its_provenance_says_so(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    f = d / "claims.parquet"
    pq.write_table(pq.read_table(f).replace_schema_metadata(None), f)
    line = one_line(capsys, main(["show", str(d)]), "claims.parquet", "'sim.provenance'")
    assert line.endswith("rewritten by a tool?)")
    one_line(capsys, main(["report", "--results", str(d.parent)]), "no provenance")


def test_a_failing_value_is_named_with_its_record(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    record = json.loads((d / "run.json").read_text("utf-8"))  # a record without the values'
    del record["table_shape"]["claims.parquet"]["values"]  # digests (doors40v names the edit)
    (d / "run.json").write_text(json.dumps(record), "utf-8")
    _edit(d / "claims.parquet", lambda t: _column(t, "kind", ["x"] * t.num_rows))  # same shape
    one_line(
        capsys,
        main(["report", "--results", str(d.parent)]),
        "claims.parquet",
        "column 'kind' of record 0 (from 0): KeyError",
    )


def test_a_convergence_column_as_text_is_named(tmp_path, capsys):
    d = tmp_path / "agnard_block"
    shutil.copytree(ROOT / "results" / "agnard_block", d, ignore=shutil.ignore_patterns("*.png"))
    f = d / "trials.parquet"
    t = pq.read_table(f)
    flags = t.column("first.converged").to_pylist()
    flags[0] = False
    t = _column(t, "first.converged", flags)
    pq.write_table(t.replace_schema_metadata(pq.read_schema(f).metadata), f)
    record = json.loads((d / "run.json").read_text("utf-8"))  # a record without the values'
    del record["table_shape"]["trials.parquet"]["values"]  # digests (doors40v names the edit)
    (d / "run.json").write_text(json.dumps(record), "utf-8")
    assert main(["show", str(d)]) == 0
    assert "not converged: 1 of" in capsys.readouterr().out  # as the run wrote it: said
    _edit(f, lambda t: _column(t, "first.converged", [str(v) for v in flags]))
    one_line(capsys, main(["show", str(d)]), "trials.parquet", "'first.converged'")
    n = tmp_path / "network_plate"
    shutil.copytree(ROOT / "results" / "network_plate", n, ignore=shutil.ignore_patterns("*.png"))
    _edit(n / "summary.parquet", lambda t: _column(t, "converged", ["31"]))  # of 40: not said
    one_line(capsys, main(["show", str(n)]), "summary.parquet", "'converged'")


def test_stale_only_calls_a_table_edited_by_hand_stale(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    tiny = tiny_overrides("brown_table1")
    assert why_stale(BROWN, d, tiny) is None
    _edit(d / "points.parquet", lambda t: t.take(list(range(t.num_rows))[::-1]))
    assert why_stale(BROWN, d, tiny).startswith("points.parquet changed after its run")


def test_verify_fails_a_number_column_committed_as_text(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("brown_table1"), scratch / "brown_table1")
    [comp] = verify(d.parent, scratch, rerun=False)
    assert comp.ok, comp.failures
    text = [str(v) for v in pq.read_table(d / "points.parquet")["sigma_x_um"].to_pylist()]
    _edit(d / "points.parquet", lambda t: _column(t, "sigma_x_um", text))
    [comp] = verify(d.parent, scratch, rerun=False)
    assert not comp.ok and "points.parquet:sigma_x_um: string committed, double re-run" in str(
        comp.failures
    ), comp.failures


def test_verify_names_tolerance_declarations_edited_by_hand(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("brown_table1"), scratch / "brown_table1")
    f = d / "claims.parquet"
    t = pq.read_table(f)
    for raw in (b"{{", b"[1]"):
        pq.write_table(t.replace_schema_metadata({**t.schema.metadata, b"sim.tolerances": raw}), f)
        [comp] = verify(d.parent, scratch, rerun=False)  # was a traceback
        assert not comp.ok and "'sim.tolerances'" in str(comp.failures), comp.failures


def test_report_names_a_claims_table_of_another_study_than_its_run(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)
    f = d / "claims.parquet"
    t = pq.read_table(f)
    prov = json.loads(t.schema.metadata[b"sim.provenance"])
    meta = {**t.schema.metadata, b"sim.provenance": json.dumps({**prov, "study": "brown_dilution"})}
    pq.write_table(t.replace_schema_metadata(meta), f)
    line = one_line(capsys, main(["report", "--results", str(d.parent)]), "claims.parquet")
    assert "a table of 'brown_dilution', not of this run's 'brown_table1'" in line, line


SWEEP = """study = "network"
trials = 40
chunk = 2
[network]
name = "n"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
  { name = "C", x_mm = 400.0, y_mm = 700.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
[sweep]
"network.scale_ppm" = [0.0, 10.0]
"""


def test_a_sweep_table_without_its_provenance_is_named(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(SWEEP, "utf-8")
    out = tmp_path / "R" / "s"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert main(["show", str(out)]) == 0 and "network.scale_ppm" in capsys.readouterr().out
    p = out / "sweep.parquet"
    pq.write_table(pq.read_table(p).replace_schema_metadata(None), p)
    for args in (["show", str(out)], ["show", str(out), "--markdown"]):
        one_line(capsys, main(args), "sweep.parquet under", "'sim.provenance'")
