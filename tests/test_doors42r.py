"""A fresh reading of session 41's merges (doors42r, brief R42), decided: each class through a
real door; each test fails on the code before its fix:

* the output of a run stopped before it published (c41's ``sim.mc.unfinished``) is looked for
  by its staging name ``.<name>.partial``, nine bytes longer: a results directory named with
  247 to 255 bytes, not there, made ``sim show NAME`` say only "File name too long:
  .<name>.partial" (a file the user never named) and ``sim.Results(NAME, ...).names()`` raise
  pathlib's ``OSError``: each says the directory does not exist, as for a shorter name;
* a table pyarrow could not read for want of memory (l41's ``memory_failure``) was told by the
  word "thread" anywhere in pyarrow's message, which quotes the file's path: a damaged
  ``claims.parquet`` under a directory named ``threads`` was "cannot be read (not enough
  memory: ...)" from ``Results.table``: the quoted path is not searched, and the table is
  named unreadable;
* ``Results.table("trials")`` of a study that writes ``trials.parquet`` (wolf, agnard,
  gridplate), that file removed by hand, took the name for the chunk dataset: "trials is
  missing: its run wrote it (the committed results/ hold no chunks ...)" (d41's words for the
  committed chunks, of the committed results of wolf_polynomial, which hold trials.parquet):
  ``trials.parquet`` is named missing, as any table its run wrote;
* a key given twice after its inline table on a study file's last line, with no line break
  after it (``plate = {x = 1}`` then ``plate.x = 2``): tomllib says "(at end of document)",
  which l41's search of the inline table read as a column (``int()`` raised) and the line was
  tomllib's words again ("Cannot mutate immutable namespace ('plate',)"), named before it:
  ``plate is given twice (at line 3, the end of the file)``;
* ``sim report --results DIR`` of a directory without results that holds an entry named
  ``.partial`` (or ``..partial``), which c41's search for a run that did not finish took for
  the staging directory of a results directory named "" (``.``): "sim: error: ValueError:
  Invalid name ''": no results named, as of any such directory.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import sim
from sim.cli import main
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "results" / "brown_table1"  # read, never written


def test_a_name_whose_staging_name_is_too_long_does_not_exist(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    name = "r" * 250  # a name the system takes; ".<name>.partial" (259 bytes) it does not
    assert main(["show", name]) == 2
    err = capsys.readouterr().err.strip()
    # before: "sim: error: File name too long: .rrr...rrr.partial"
    assert len(err.splitlines()) == 1 and "does not exist" in err and ".partial" not in err, err
    # before: OSError [Errno 36] File name too long
    with pytest.raises(sim.ConfigError, match="does not exist"):
        sim.Results(name, "brown_table1").names()


def test_a_damaged_table_under_a_directory_named_threads_is_not_short_of_memory(tmp_path):
    d = tmp_path / "threads" / "brown_table1"
    shutil.copytree(RESULTS, d, ignore=shutil.ignore_patterns("*.png", "trials"))
    f = d / "claims.parquet"
    f.write_bytes(f.read_bytes()[: f.stat().st_size // 2])  # its footer cut off
    # before: "cannot be read (not enough memory: Could not open Parquet input source ..."
    with pytest.raises(sim.ConfigError, match=r"claims.parquet cannot be read \(ArrowInvalid\)"):
        sim.Results(d, "brown_table1").table("claims")


def test_a_trials_table_removed_by_hand_is_named_not_the_chunks(tmp_path):
    d = tmp_path / "wolf_polynomial"
    src = ROOT / "results" / "wolf_polynomial"
    shutil.copytree(src, d, ignore=shutil.ignore_patterns("*.png", "trials", "trials.parquet"))
    # before: ".../trials is missing: its run wrote it (the committed results/ hold no chunks"
    with pytest.raises(
        sim.ConfigError, match=r"trials\.parquet is missing: its run wrote it \(removed"
    ):
        sim.Results(d, "wolf_polynomial").table("trials")


def test_a_key_given_twice_on_the_last_line_after_its_inline_table_is_named(tmp_path, capsys):
    f = tmp_path / "twice.toml"
    f.write_text('study = "brown_table1"\nplate = {x = 1}\nplate.x = 2', encoding="utf-8")
    # before: "malformed TOML: Cannot mutate immutable namespace ('plate',) (at end of document)"
    line = one_line(capsys, main(["check", str(f)]), "plate is given twice (at line 3, the end")
    assert "immutable" not in line, line


@pytest.mark.parametrize("entry", [".partial", "..partial"])
def test_a_bare_partial_entry_is_no_unfinished_run(tmp_path, capsys, entry):
    (tmp_path / entry).mkdir()
    # before: "sim: error: ValueError: Invalid name ''"
    line = one_line(capsys, main(["report", "--results", str(tmp_path)]), "no study results in")
    assert "ValueError" not in line, line
