"""The classes of the sweep doors40v (brief V40: a finished results directory touched by hand
-- a table's rows reordered or a value changed, a column retyped, a table re-saved by another
tool, README.md or run.json edited, a figure deleted, a chunk touched, modes read-only, the
directory renamed -- read by every reader: ``sim show``, ``sim report``, ``make verify``,
``sim.Results``, ``--stale-only`` and a resume), one case each; each failed on the code before
its fix.

* A value edited by hand in a table that kept its shape (a claim's verdict turned from
  ``holds`` to ``fails``, a number changed, the rows reordered; pandas, DuckDB or pyarrow
  keeping the schema metadata) was read by ``sim show``, ``sim report`` (every README.md and
  REPORT.md rewritten with it) and ``sim.Results.table`` as the run's, exit 0: only ``make
  verify`` and ``--stale-only`` (the file's sha256) knew. ``table_shape`` now holds a digest of
  each column's values in their order (:func:`sim.mc.table_shape.values_digest`, the same for
  a faithful rewrite: other row groups, a dictionary encoding, another text type), and each
  reader names the file and the column whose values are not the run's.
* The same command again (``sim run`` with the same ``--out``: a resume of finished results,
  ``make reproduce``'s ``--overwrite``) replaced a table edited by hand with the run's, exit 0,
  without a word. One note now names the tables changed after their run, replaced
  (:func:`sim.execute._say_edits_replaced`); a file of the user's is carried over as before.
* A figure removed by hand from results whose run drew it was "not drawn (``table1.png`` is
  missing: a run with ``--no-figures``?)" in the README that ``sim report`` writes, a guess
  that the run record (``figure_sha256``, ``"figures"``) contradicts: it now says the run drew
  it and it was removed since.
* ``sim.Results(d, study).table("points")`` of a table its run wrote and that was removed by
  hand said "brown_table1 has no table 'points'; it has ..." (the study has it: its run wrote
  it): the file is named as missing, its run having written it.

Held (found right): a column retyped (float64 to float32), renamed, a row deleted, a pandas
index column added, the schema metadata dropped (each named by every reader, exit 2, or
FAILED by verify); text as ``large_string``, a dictionary encoding, row groups of one or two
rows (read as the run's); ``run.json`` with its keys reordered or pretty-printed again; a
README.md edited (one with the mark is rewritten, as its mark says; one without is the
user's, kept); files and the directory read-only (every reader, nothing written into a
results directory by ``sim show``); a chunk touched (same bytes: read) or its row groups
split (``Results.table("chunks")`` names it; a resume reads it by its identity).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import ROOT, tiny_command
from oneline import one_line

import sim
from sim.cli import main
from sim.mc.config import ConfigError


def _copy(tiny_run, tmp_path: Path) -> Path:
    d = tmp_path / "results" / "brown_table1"
    shutil.copytree(tiny_run("brown_table1"), d)
    return d


def _edit(p: Path, change, **write) -> None:
    """Rewrite the table ``p`` as ``change`` makes it, its schema metadata kept."""
    t = pq.read_table(p)
    pq.write_table(change(t).replace_schema_metadata(t.schema.metadata), p, **write)


def _verdict_turned(t: pa.Table) -> pa.Table:
    v = t.column("verdict").to_pylist()
    i = next(k for k, x in enumerate(v) if x in ("holds", "depends"))
    v[i] = "fails" if v[i] == "holds" else "holds"
    return t.set_column(t.schema.get_field_index("verdict"), "verdict", pa.array(v, pa.string()))


@pytest.mark.parametrize(
    "change, column",
    [
        (_verdict_turned, "verdict"),
        (lambda t: t.take(list(reversed(range(t.num_rows)))), None),  # the rows reordered
    ],
    ids=["verdict", "reordered"],
)
def test_a_value_edited_in_a_table_of_the_same_shape_is_named(
    tiny_run, tmp_path, capsys, change, column
):
    d = _copy(tiny_run, tmp_path)
    _edit(d / "claims.parquet", change)
    needles = ("claims.parquet", "the values of column", "not those its run wrote")
    needles += (f"'{column}'",) if column else ()
    for argv in (["show", str(d)], ["show", str(d), "--markdown"]):
        one_line(capsys, main(argv), *needles)
    one_line(capsys, main(["report", "--results", str(d.parent)]), *needles)
    assert not (d.parent / "REPORT.md").exists()
    with pytest.raises(ConfigError, match="the values of column"):
        sim.Results(d, "brown_table1").table("claims")


def test_a_faithful_rewrite_still_reads_as_the_run(tiny_run, tmp_path, capsys):
    d = _copy(tiny_run, tmp_path)

    def rewrite(t: pa.Table) -> pa.Table:
        for name in ("claim", "note"):
            i = t.schema.get_field_index(name)
            t = t.set_column(i, name, t.column(i).cast(pa.large_string()))
        i = t.schema.get_field_index("verdict")
        return t.set_column(i, "verdict", t.column(i).dictionary_encode())

    _edit(d / "claims.parquet", rewrite, row_group_size=2)
    assert main(["show", str(d)]) == 0
    assert main(["report", "--results", str(d.parent)]) == 0
    capsys.readouterr()
    assert sim.Results(d, "brown_table1").table("claims").num_rows > 0


@pytest.mark.long
def test_the_same_command_again_says_which_edited_tables_it_replaces(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    _edit(d / "points.parquet", lambda t: t.take(list(reversed(range(t.num_rows)))))
    (d / "notes.txt").write_text("mine\n")
    r = subprocess.run(tiny_command("brown_table1", d), cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    note = [ln for ln in r.stderr.splitlines() if ln.startswith("sim: note:")]
    assert len(note) == 1 and "points.parquet" in note[0] and "replaced" in note[0], r.stderr
    assert str(d) in note[0] and "claims.parquet" not in note[0]
    assert (d / "notes.txt").read_text() == "mine\n"  # the user's own file: carried over
    r = subprocess.run(tiny_command("brown_table1", d), cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0 and "note" not in r.stderr, r.stderr  # nothing edited: no note


def test_a_figure_removed_by_hand_is_not_called_a_run_without_figures(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    (d / "table1.png").unlink()
    assert main(["report", "--results", str(d.parent)]) == 0
    text = (d / "README.md").read_text("utf-8")
    assert "`table1.png` is missing: its run drew it; removed since?" in text
    assert "no-figures" not in text


def test_a_table_removed_by_hand_is_named_by_the_api_as_removed(tiny_run, tmp_path):
    d = _copy(tiny_run, tmp_path)
    (d / "points.parquet").unlink()
    with pytest.raises(ConfigError, match="points.parquet is missing: its run wrote it"):
        sim.Results(d, "brown_table1").table("points")
    with pytest.raises(ConfigError, match="has no table 'pointz'"):  # a name of no table
        sim.Results(d, "brown_table1").table("pointz")
