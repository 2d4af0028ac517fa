"""Doors sweep 46h: a finished results directory touched by hand (in a file manager, a
spreadsheet, an editor), each touch followed by every reader (``sim show``, ``sim report``,
``python -m sim.report.verify``, ``sim.Results``, ``python -m sim.batch --stale-only``, a re-run
into the same ``--out``), one case per class found; each failed on the code before its fix.

* ``README.md`` of a run made a FIFO (a named pipe nobody writes to): ``sim report`` hung for
  good (and a re-run into the directory with it) while it read the README's first line to
  see whether the suite wrote it. A README.md that is not a regular file is now the user's,
  never opened, and kept, as ``REPORT.md``'s check already kept one
  (:func:`sim.report.run_summary._ours`).
* ``run.json`` left broken by an editor (invalid JSON, cut short), or replaced by a FIFO, a
  directory, a file that is no JSON object: every reader took the directory as results of a
  version that recorded no table shapes and read its tables unchecked, so a value edited by
  hand beside it (``mean_ratio`` 1.007 made 2.007, outside its own interval) was printed by
  ``sim show`` and ``sim report`` and returned by ``Results.table`` as the run's, exit 0. Each
  reader now refuses with one line naming the ``run.json`` and what is wrong with it
  (:func:`sim.mc.table_shape.record_problem`). A ``run.json`` saved with an editor's UTF-8
  signature (Notepad's BOM) is read as the record it is (it was taken as none, its tables
  unchecked).

Held (tried on a tiny network run and a tiny brown_table1 run, every reader after each):
tables re-saved by pandas (refused: no provenance) or by pyarrow with another compression or
format version (read), columns reordered, one value edited, an int column made float, rows
sorted, a row added or removed, a column added, removed or renamed (each refused naming the
file and the column); a table truncated, empty, a CSV, a directory, a FIFO, mode 000 ...
(refused); ``run.json`` fields removed or retyped (refused or stale); editors' and file
managers' litter (``claims.parquet~``, ``.claims.parquet.swp``, ``.~lock.claims.parquet#``,
``.DS_Store``, ``__pycache__/``, ``Thumbs.db``, ``._claims.parquet``) ignored by the readers
and carried by a re-run; a figure deleted, emptied or replaced (named).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

import sim
from sim.batch_checks import why_stale
from sim.cli import main
from sim.report.verify.rerun import verify
from tests.conftest import tiny_overrides
from tests.hand_edits import copy_of_tiny as _copy
from tests.hand_edits import edit_first_value
from tests.oneline import one_line
from tests.within import within

PLATE = Path(__file__).resolve().parents[1] / "studies" / "network_plate.toml"


def test_a_readme_made_a_fifo_is_kept_and_never_opened(tiny_run, tmp_path, capsys):
    """A FIFO in a run's README.md: ``sim report`` blocked for good opening it to read the
    suite's mark; it is the user's file now, kept as it is."""
    d = _copy(tiny_run, tmp_path)
    readme = d / "README.md"
    readme.unlink()
    os.mkfifo(readme)
    assert within(60, main, ["report", "--results", str(d.parent)]) == 0
    capsys.readouterr()
    assert readme.is_fifo() and (d.parent / "REPORT.md").is_file()


@pytest.mark.parametrize(
    ("touch", "words"),
    [
        (lambda p: p.write_text(p.read_text()[:-40]), "not JSON: "),  # an editor cut it short
        (lambda p: (p.unlink(), os.mkfifo(p)), "not a regular file"),
        (lambda p: (p.unlink(), p.mkdir()), "not a regular file"),
        (lambda p: p.write_text("[]"), "not an object holding its config and code_hash"),
    ],
    ids=["invalid-json", "fifo", "directory", "a-list"],
)
def test_a_broken_run_record_is_named_not_taken_as_none(tiny_run, tmp_path, capsys, touch, words):
    """``run.json`` broken by hand beside a value edited by hand: the readers took the
    directory as an older version's results (no shapes recorded) and printed the edited value
    as the run's, exit 0; each now refuses naming the run.json."""
    d = _copy(tiny_run, tmp_path)
    edited = edit_first_value(d)
    touch(d / "run.json")
    rec = str(d / "run.json")
    one_line(capsys, within(60, main, ["show", str(d)]), rec, words, "run the study again")
    one_line(capsys, within(60, main, ["report", "--results", str(d.parent)]), rec, words)
    with pytest.raises(sim.ConfigError, match=f"{rec} is not a run record") as e:
        sim.Results(d, "network").claims()
    assert str(edited) not in str(e.value)


def test_a_run_record_saved_with_a_utf8_signature_is_read(tiny_run, tmp_path, capsys):
    """``run.json`` saved by an editor that writes a UTF-8 signature (a BOM): it was taken as
    no record, its tables read unchecked (an edited value printed as the run's); it is read
    as the record it is, and the edit is named."""
    d = _copy(tiny_run, tmp_path)
    rec = d / "run.json"
    args = ["--quiet", *tiny_overrides("network")]
    assert why_stale(PLATE, d, args) is None
    rec.write_bytes(b"\xef\xbb\xbf" + rec.read_bytes())
    assert json.loads(rec.read_text("utf-8-sig"))["code_hash"]
    assert sim.Results(d, "network").claims().num_rows > 0  # the run's tables: read
    assert why_stale(PLATE, d, args) is None  # was "its run record or study file does not load"
    edit_first_value(d)
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "value")
    with pytest.raises(sim.ConfigError, match="is not the table its run wrote"):
        sim.Results(d, "network").claims()


def test_a_copy_of_a_table_beside_the_run_is_not_one_of_its_tables(tiny_run, tmp_path):
    """A copy kept beside the tables (``claims_old.parquet``, a file manager's ``points
    (copy).parquet``): ``Results.names()`` listed both as the run's tables (the second no
    name ``table()`` takes) and ``table("claims_old")`` returned the copy, edited or not,
    unchecked (the run recorded no shape for it). The run's record lists its tables: only
    those are its names, and a table of another name is refused naming the file."""
    d = _copy(tiny_run, tmp_path)
    shutil.copyfile(d / "claims.parquet", d / "claims_old.parquet")
    shutil.copyfile(d / "points.parquet", d / "points (copy).parquet")
    res = sim.Results(d, "network")
    assert "claims_old" not in res.names() and "points (copy)" not in res.names()
    assert {"claims", "points"} <= set(res.names())
    with pytest.raises(sim.ConfigError, match=r"claims_old.parquet is not a table its run wrote"):
        res.table("claims_old")
    assert (d / "claims_old.parquet").is_file()  # the user's copy, kept


def test_a_record_without_shapes_checks_the_tables_by_their_sha256(tiny_run, tmp_path, capsys):
    """``table_shape`` removed from ``run.json`` (as a record of the versions that held the
    tables' sha256 but no shapes): the tables were read unchecked, a value edited by hand
    printed and returned as the run's. A table whose sha256 is not the recorded one is
    refused there, naming the file."""
    d = _copy(tiny_run, tmp_path)
    rec = json.loads((d / "run.json").read_text("utf-8"))
    del rec["table_shape"]
    (d / "run.json").write_text(json.dumps(rec), "utf-8")
    assert sim.Results(d, "network").claims().num_rows > 0  # the run's own: read
    edit_first_value(d)
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "sha256")
    with pytest.raises(sim.ConfigError, match="claims.parquet is not the table its run wrote"):
        sim.Results(d, "network").claims()


def test_verify_leaves_out_a_copy_kept_beside_the_tables(tiny_run, tmp_path):
    """``make verify`` of results with a copy kept beside their tables (``claims_old.parquet``)
    failed the study, "claims_old.parquet: only in the committed results", a reproduction
    failure for a file the run never wrote; it compares the tables the run's record lists."""
    d = _copy(tiny_run, tmp_path)
    shutil.copyfile(d / "claims.parquet", d / "claims_old.parquet")
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("network_plate"), scratch / "network_plate")
    [comp] = verify(d.parent, scratch, rerun=False)
    assert comp.ok and not comp.failures, comp.failures
    (d / "points.parquet").unlink()  # one of the run's: still a failure
    [comp] = verify(d.parent, scratch, rerun=False)
    assert not comp.ok and "points.parquet: only in the re-run results" in comp.failures
