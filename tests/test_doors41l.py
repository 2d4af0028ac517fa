"""Last session's left items (doors41l, brief L41), decided: each class through a real door;
each test fails on the code before its fix:

* ``sim run ... >&-``, ``sim report >&-`` and ``python -m sim.batch ... >&-`` (standard output
  closed) ran and ended in exit 0, their summary printed nowhere (``> /dev/full`` is exit 2
  after the run): every program refuses a closed standard output before it starts, one line
  as ``sim check`` and ``sim show`` said, exit 2 (``> /dev/null`` prints nowhere);
* the command line with the working directory deleted called a relative study file "no such
  study file" (``sim check``, ``sim run``, ``python -m sim.batch``) and ``sim show x`` "does not
  exist": each names the argument and says the working directory is gone, as the API does;
* a Wolf CSV whose data rows end in Excel's trailing commas (empty cells after the header's
  last column) was refused as "a decimal comma?": read as nothing; and a decimal comma in the
  number before the note, with the note left out (``...,32,271``), was read silently as 32 mm
  and the note "271": refused naming the cell and the note;
* a key given twice in an inline table, first as an inline table (``plate = {x = {a = 1},
  x = 2}``, or ``x.b = 2`` after it) got tomllib's own words ("Cannot mutate immutable
  namespace ('x',)"): named whole (``plate.x``, an array's item as ``p.q[0].x``); and a key
  given twice under an array of tables was named without its item
  (``network.grids.spacing_mm``): ``network.grids[1].spacing_mm``;
* under a memory limit just above a run's peak pyarrow could not allocate (``ArrowMemoryError``)
  or start a thread of its pool, and ``sim show``, ``sim report`` and ``Results.table`` called
  ``claims.parquet`` "not the claims table its run wrote: cannot be read": they say not enough
  memory (the limit when one is set);
* on a terminal of 0 rows (``stty rows 0``) the progress bar was blank (tqdm took the height
  for -1 rows, the bar's line outside them): drawn at the terminal's width;
* a sweep over ``trials`` (``trials = [400, 800]`` of brown_table1, whose chunk is 200) was
  refused, every cell naming ``chunk``, where ``--set trials=400`` picks the chunk: each cell
  picks it by the same rule (20 and 40 here);
* ``sim show`` of a sweep whose cell directory was deleted printed the cell's row as if it
  were there, exit 0 (``sim report`` rewrote the README.md linking it, ``Results.table("sweep")``
  read it): each names the missing cell, as a removed table is named;
* results whose run record and tables name a study this version lacks (a newer version's):
  ``sim show`` said "study: unknown study", ``sim report`` "claims.parquet cannot be read: study:
  unknown study", and ``Results.table`` warned they were made by code "changed since" (stale):
  each says the directory holds results of a study this version does not have, and no stale
  note is given of them.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import on_a_terminal
from oneline import SIM_ERROR, one_line, one_line_of

import sim
import sim.batch
import sim.report.read
from sim.cli import main
from sim.mc.sweep import cell_config
from sim.studies.wolf.tables import load_table1

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = ROOT / "studies" / "brown_table1.toml"
WOLF1 = ROOT / "studies" / "data" / "wolf_table1.csv"
PY = sys.executable


@pytest.mark.parametrize(
    "argv",
    [
        ["sim", "run", str(TABLE1), "--trials", "40", "--no-figures", "--out", "{tmp}/o"],
        ["sim", "report", "--results", "{tmp}"],
        ["sim.batch", str(TABLE1), "--results", "{tmp}", "--", "--trials", "40"],
    ],
)
def test_a_command_that_writes_files_refuses_a_closed_standard_output(tmp_path, argv):
    cmd = " ".join([PY, "-m", *(a.format(tmp=tmp_path) for a in argv)]) + " >&-"
    proc = subprocess.run(["sh", "-c", cmd], capture_output=True, text=True, timeout=120, cwd=ROOT)
    # before: exit 0, the summary (results in DIR, REPORT.md's path, N runs done) nowhere
    one_line_of(proc, "standard output is closed (>&-): nothing to print to")
    assert sorted(os.listdir(tmp_path)) == []  # refused before it started


@pytest.fixture
def gone_cwd(tmp_path, monkeypatch):
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    return tmp_path


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["check", "studies/brown_table1.toml"], "STUDY: studies/brown_table1.toml"),
        (["run", "studies/brown_table1.toml"], "STUDY: studies/brown_table1.toml"),
        (["show", "brown_table1"], "DIR: brown_table1"),
    ],
)
def test_the_command_line_with_the_working_directory_gone_says_so(capsys, gone_cwd, argv, name):
    # before: "no such study file", "does not exist (nor is there a directory results/x ...)"
    one_line(
        capsys,
        main(argv),
        "is relative, but the working directory is gone",
        prefix=SIM_ERROR + name,
    )


def test_the_batch_with_the_working_directory_gone_says_so(capsys, gone_cwd):
    rc = sim.batch.main(["studies/brown_table1.toml", "--results", str(gone_cwd)])
    one_line(
        capsys, rc, "FILE: studies/brown_table1.toml is relative, but the working directory is gone"
    )


def _wolf(tmp_path, edit) -> Path:
    lines = WOLF1.read_text(encoding="utf-8").splitlines()
    p = tmp_path / "t1.csv"
    p.write_text("\r\n".join(edit(ln) for ln in lines) + "\r\n", encoding="utf-8-sig")
    return p


def test_excels_trailing_commas_in_a_wolf_table_are_read_as_nothing(tmp_path):
    p = _wolf(tmp_path, lambda ln: ln + ",,," if ln[:1].isdigit() else ln)
    got, want = load_table1(p), load_table1(WOLF1)  # before: "a decimal comma?"
    assert all(np.array_equal(got[k], want[k]) for k in want)
    st = sim.load(ROOT / "studies" / "wolf_polynomial.toml", **{"table1.file": str(p)})
    assert st.config["table1.file"] == str(p)


def test_a_decimal_comma_before_a_note_left_out_is_named(tmp_path, capsys):
    def split(ln):  # 005,10,...,-53.136,32.271,"" -> ...,-53.136,32,271
        return (
            ",".join(ln.split(",")[:8]).replace(",32.271", ",32,271")
            if ln.startswith("005,10,")
            else ln
        )

    p = _wolf(tmp_path, split)
    assert ",32,271\n" in p.read_text(encoding="utf-8-sig")
    rc = main(
        ["check", str(ROOT / "studies" / "wolf_polynomial.toml"), "--set", f'table1.file="{p}"']
    )
    # before: read as y_foster_mm 32 and the note '271', exit 0
    one_line(
        capsys,
        rc,
        "table1.file: ",
        "(line ",
        "y_foster_mm '32' and the note '271': a decimal comma?",
    )


@pytest.mark.parametrize(
    ("value", "name"),
    [
        ("plate = {x = {a = 1}, x = 2}", "plate.x"),
        ("plate = {x = {a = 1}, x.b = 2}", "plate.x"),
        ("p = {q = [{x = {a = 1}, x = 2}]}", "p.q[0].x"),
    ],
)
def test_a_key_given_twice_after_its_inline_table_is_named(tmp_path, capsys, value, name):
    f = tmp_path / "s.toml"
    f.write_text(f'study = "brown_table1"\n{value}\n', encoding="utf-8")
    # before: "malformed TOML: Cannot mutate immutable namespace ('x',) (at line 2, ...)"
    one_line(
        capsys,
        main(["check", str(f)]),
        f"malformed TOML: {name} is given twice in an inline table (at line 2",
    )


def test_a_key_given_twice_in_an_array_of_tables_names_its_item(tmp_path, capsys):
    text = (ROOT / "studies" / "network_brown.toml").read_text(encoding="utf-8")
    grid = '\n[[network.grids]]\nprefix = "{}"\nnx = 2\nny = 2\nspacing_mm = 45.0\n'
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith("grids = "))
    f = tmp_path / "net.toml"
    f.write_text(text + grid.format("P") + grid.format("Q") + "spacing_mm = 4\n", encoding="utf-8")
    # before: "network.grids.spacing_mm is given twice"
    one_line(capsys, main(["check", str(f)]), "network.grids[1].spacing_mm is given twice (at line")


RESULTS = ROOT / "results" / "brown_table1"  # read, never written


@pytest.mark.parametrize(
    "error",
    [
        pa.ArrowMemoryError("malloc of size 18752 failed"),
        pa.ArrowException("Couldn't start thread: Resource temporarily unavailable"),
    ],
)
def test_a_table_read_short_of_memory_is_not_called_damaged(tmp_path, monkeypatch, capsys, error):
    def short(*a, **k):
        raise error

    monkeypatch.setattr(sim.report.read, "read_table", short)
    monkeypatch.setattr(pq, "read_table", short)
    # before: "claims.parquet is not the claims table its run wrote: cannot be read (...)"
    line = one_line(capsys, main(["show", str(RESULTS)]), "not enough memory for this command")
    assert "reading claims.parquet" in line and "not the claims table" not in line, line
    res = tmp_path / "res"
    shutil.copytree(RESULTS, res / "brown_table1", ignore=shutil.ignore_patterns("*.png", "trials"))
    rc = main(["report", "--results", str(res)])
    one_line(capsys, rc, "not enough memory for this command: reading claims.parquet")
    with pytest.raises(sim.ConfigError, match="cannot be read \\(not enough memory: "):
        sim.Results(RESULTS, "brown_table1").table("claims")


@pytest.mark.long
def test_a_terminal_of_no_rows_shows_the_bar(tmp_path):
    run = [
        "run",
        str(TABLE1),
        "--trials",
        "40",
        "--chunk",
        "2",
        "--no-figures",
        "--out",
        str(tmp_path / "o"),
    ]
    rc, seen, _ = on_a_terminal(run, 120, rows_cols=(0, 100))  # stty rows 0
    assert rc == 0, seen
    assert b"/40 trials" in seen, seen  # before: nothing drawn


def test_a_sweep_over_trials_picks_each_cells_chunk_as_trials_does(tmp_path, capsys):
    f = tmp_path / "sw.toml"
    f.write_text('study = "brown_table1"\n[sweep]\ntrials = [400, 800]\n', encoding="utf-8")
    # before: "sweep.trials: every cell failed (2 of 2) on load ... chunk: 400 trials in chunks
    # of 200 give 2 chunks ..."
    assert main(["check", str(f)]) == 0, capsys.readouterr().err
    assert "in 2 sweep cells" in capsys.readouterr().out
    st = sim.load(TABLE1)
    cells = [cell_config(st.study, st.config, {"trials": n}, 1) for n in (400, 800, 8000)]
    assert [c["chunk"] for c in cells] == [20, 40, 200]  # as --set trials=N picks it
    assert [sim.load(TABLE1, trials=n).config["chunk"] for n in (400, 800, 8000)] == [20, 40, 200]


@pytest.mark.long
def test_a_sweep_whose_cell_was_deleted_names_the_cell(tmp_path, capsys):
    f = tmp_path / "sw.toml"
    f.write_text('study = "brown_table1"\n[sweep]\ntrials = [40, 60]\n', encoding="utf-8")
    out = tmp_path / "res" / "sw"
    assert main(["run", str(f), "--quiet", "--no-figures", "--out", str(out)]) == 0
    assert main(["show", str(out)]) == 0
    capsys.readouterr()
    shutil.rmtree(out / "cells" / "cell0001_r0")
    words = "cell0001_r0 is missing: its sweep's run wrote it (removed by hand?)"
    one_line(capsys, main(["show", str(out)]), words, prefix=SIM_ERROR + "DIR: ")  # before: 0
    one_line(capsys, main(["report", "--results", str(out.parent)]), words)
    assert not (out.parent / "REPORT.md").exists()
    with pytest.raises(sim.ConfigError, match=re.escape(words)):
        sim.Results(out, "brown_table1").table("sweep")


def _of_another_study(d: Path, name: str) -> None:
    """``d``'s run record and tables made to name the study ``name`` (their sha256 kept)."""
    rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    rec["config"]["study"] = name
    rec["written_as"] = name  # as that version's run of studies/<name>.toml recorded it
    rec["study_file"] = {"path": f"studies/{name}.toml", "sha256": "0" * 64}
    for f in d.glob("*.parquet"):
        t = pq.read_table(f)
        meta = {
            k: v.replace(b'"study": "brown_table1"', f'"study": "{name}"'.encode())
            for k, v in t.schema.metadata.items()
        }
        pq.write_table(t.replace_schema_metadata(meta), f)
        rec["table_sha256"][f.name] = hashlib.sha256(f.read_bytes()).hexdigest()
    (d / "run.json").write_text(json.dumps(rec), encoding="utf-8")


def test_results_of_a_study_this_version_lacks_say_so(tmp_path, capsys):
    d = tmp_path / "res" / "brown_future"
    shutil.copytree(RESULTS, d, ignore=shutil.ignore_patterns("*.png", "README.md"))
    _of_another_study(d, "brown_future")
    words = (
        "holds results of the study 'brown_future', which this version of the suite does not have"
    )
    one_line(capsys, main(["show", str(d)]), words, prefix=SIM_ERROR + "DIR: ")  # "unknown study"
    one_line(
        capsys,
        main(["report", "--results", str(d.parent)]),
        words,
        prefix=SIM_ERROR + "--results: ",
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # before: StaleResultsWarning ("its study's code changed")
        assert sim.Results(d, "brown_future").table("claims").num_rows > 0
