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
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
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
