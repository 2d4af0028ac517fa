"""Doors sweep 47k: the items the helpers of session 46 left, each failing on the code before
its fix.

* A results directory whose ``run.json`` was deleted, and a value of its tables edited by
  hand: every reader (``sim show``, ``sim report``, ``sim.Results``, ``make verify``) took it
  as results of a version that recorded no table shapes and printed the edited value as the
  run's, exit 0. Every version whose claims table the readers take (one with a ``verdict``
  column) wrote ``run.json`` beside it (the first commit's results, without one, had no
  ``verdict`` column and are refused as an older version's table), so a study directory
  without its record is refused in one line naming the ``run.json``
  (:func:`sim.mc.table_shape.record_problem`). A sweep's cells, whose record is the sweep's,
  are read as before (tests/test_doors_sweep.py).
* ``claims.parquet`` replaced by a FIFO: ``sim show`` said "no claims.parquet or
  sweep.parquet", ``sim report`` left the study out of REPORT.md without a word (or said "no
  study results"), ``make verify --study`` "no results of ..."; a figure replaced by a FIFO
  was "missing: its run drew it; removed since?" in the README. Each names it as a FIFO, not
  the suite's file (:mod:`sim.mc.file_kind`), never opening it.
* ``sim.write_table`` wrote ``inf`` inside a list (or struct) column where the same value at
  a column's top level is refused: refused now, naming the column and its row
  (:mod:`sim.mc.finite`; no committed table holds a list or struct of floats).
* A run over the work limit whose region holds the work: the advice began "reduce trials or
  the lists in the study file" and named the region's keys last; it leads with them.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import sim
from sim.cli import main
from sim.report.verify.rerun import verify
from sim.report.verify.rules import VerifyError
from tests.hand_edits import copy_of_tiny as _copy
from tests.hand_edits import edit_first_value
from tests.oneline import SIM_ERROR, one_line
from tests.within import within

STUDIES = Path(__file__).resolve().parents[1] / "studies"


def test_a_results_directory_whose_run_record_was_deleted_is_refused(tiny_run, tmp_path, capsys):
    """``run.json`` deleted and a claim's value edited: ``sim show``, ``sim report``,
    ``Results.claims()`` and verify read the edited value as the run's (the directory taken
    as an older version's results); each refuses naming the missing ``run.json``."""
    d = _copy(tiny_run, tmp_path)
    edited = edit_first_value(d)
    (d / "run.json").unlink()
    rec = str(d / "run.json")
    one_line(capsys, main(["show", str(d)]), rec, "is missing", "run the study again")
    one_line(capsys, main(["report", "--results", str(d.parent)]), rec, "is missing")
    assert not (d.parent / "REPORT.md").exists()
    with pytest.raises(sim.ConfigError, match=f"{rec} is missing") as e:
        sim.Results(d, "network").claims()
    assert str(edited) not in str(e.value)
    scratch = tmp_path / "scratch"
    shutil.copytree(tiny_run("network_plate"), scratch / "network_plate")
    [comp] = verify(d.parent, scratch, rerun=False)
    assert not comp.ok and any(f"{rec} is missing" in f for f in comp.failures), comp.failures
    assert sorted(p.name for p in d.iterdir()) == sorted(
        p.name for p in tiny_run("network_plate").iterdir() if p.name != "run.json"
    )  # nothing the user left was deleted or rewritten by a refusal


def test_a_claims_table_made_a_fifo_is_named_as_one(tiny_run, tmp_path, capsys):
    """``claims.parquet`` replaced by a FIFO: ``sim show`` said "no claims.parquet or
    sweep.parquet", ``sim report`` "no study results" (or left the study out of REPORT.md
    when another study was there), verify "no results of ..."; each names the FIFO now."""
    d = _copy(tiny_run, tmp_path)
    other = _copy(tiny_run, tmp_path, "brown_table1")
    (d / "claims.parquet").unlink()
    os.mkfifo(d / "claims.parquet")
    words = (str(d / "claims.parquet"), "is a FIFO (named pipe), not a table the suite wrote")
    one_line(capsys, within(60, main, ["show", str(d)]), *words, prefix=SIM_ERROR + "DIR: ")
    rc = within(60, main, ["report", "--results", str(d.parent)])
    one_line(capsys, rc, *words, prefix=SIM_ERROR + "--results: ")
    assert not (d.parent / "REPORT.md").exists() and (other / "claims.parquet").is_file()
    for only in (None, ["network_plate"]):
        with pytest.raises(VerifyError, match=r"network_plate/claims.parquet is a FIFO"):
            within(60, verify, d.parent, tmp_path / "scratch", 1, only, False)
    assert (d / "claims.parquet").is_fifo()
    shutil.rmtree(d)  # the other study alone: read as before
    assert main(["report", "--results", str(d.parent)]) == 0
    capsys.readouterr()


def test_a_figure_made_a_fifo_is_named_as_one_in_the_readme(tiny_run, tmp_path, capsys):
    """A figure replaced by a FIFO: the README said "missing: its run drew it; removed
    since?"; what stands there is said, and the FIFO is never opened (since doors48k the
    report refuses, one line naming it, as it refuses a table so replaced)."""
    d = _copy(tiny_run, tmp_path)
    drew = json.loads((d / "run.json").read_text("utf-8"))["figure_sha256"]
    name = sorted(drew)[0]
    (d / name).unlink()
    os.mkfifo(d / name)
    rc = within(60, main, ["report", "--results", str(d.parent)])
    one_line(capsys, rc, f"{name} is a FIFO (named pipe), not the figure its run drew")
    assert (d / name).is_fifo()


INF = float("inf")


@pytest.mark.parametrize(
    ("columns", "where"),
    [
        ({"a": [[1.0, INF]]}, "column a holds inf inside its row 0"),
        ({"x": [1, 2, 3], "a": [[1.0], None, [2.0, -INF]]}, "column a holds -inf inside its row 2"),
        (
            {"a": [{"s": 1.0, "t": "u"}, {"s": INF, "t": "v"}]},
            "column a holds inf inside its row 1",
        ),
        ({"a": [[[2.0]], [[3.0], [INF]]]}, "column a holds inf inside its row 1"),
        (pa.table({"a": pa.array([[1.0, 2.0], [3.0, INF]], pa.list_(pa.float32(), 2))}), "row 1"),
        (
            pa.table(
                {"m": pa.array([[("k", 1.0)], [("j", INF)]], pa.map_(pa.string(), pa.float64()))}
            ),
            "column m holds inf inside its row 1",
        ),
    ],
    ids=["list", "list-after-a-null", "struct", "list-of-lists", "fixed-size-list", "map"],
)
def test_an_infinity_inside_a_list_column_is_refused(tmp_path, columns, where):
    """An infinite value inside a list, struct or map column: written (a top-level one was
    refused); refused now naming the column and row, nothing written."""
    p = tmp_path / "t.parquet"
    with pytest.raises(sim.ConfigError, match="not finite") as e:
        sim.write_table(p, columns, {"study": "mine"})
    assert where in str(e.value) and not p.exists()


def test_a_nan_or_a_finite_list_column_is_written_as_before(tmp_path):
    """NaN stays "missing" inside a list as at the top level; finite lists are written."""
    p = sim.write_table(tmp_path / "t.parquet", {"a": [[1.0, float("nan")], [], None]}, {})
    assert pq.read_table(p)["a"].to_pylist()[0][0] == 1.0


def test_a_region_over_the_work_limit_leads_with_its_keys(capsys):
    """A region that holds the run's work over the limit: the advice began "reduce trials or
    the lists in the study file", the region's keys last; they lead now."""
    argv = ["check", str(STUDIES / "gridplate_two_plates.toml")]
    for s in ("region.points=65536", "region.rounds=6", "region.draws=1e6"):
        argv += ["--set", s]
    line = one_line(capsys, main([*argv, "--max-adjustments", "4e8"]), prefix=SIM_ERROR)
    keys = "change region.points, region.rounds or region.draws, which hold most of it"
    assert f"SIM_MAX_ADJUSTMENTS); {keys}, or reduce trials" in line, line
