"""A reading of session 42's second merges (doors43r, brief R43), decided: each class through a
real door; each test fails on the code before its fix:

* a table pyarrow could not read for want of memory is told by "thread" in pyarrow's words
  outside the quoted path of the file (r42's ``_QUOTED`` in :mod:`sim.report.read`), whose
  quoted span ended at the first quote after it: a path holding a quote of its own (a
  directory ``it's threads`` or ``runs' threads``) was cut there, its ``threads`` searched,
  and a damaged table was "not enough memory for this command" from ``sim report`` and "cannot
  be read (not enough memory: ...)" from ``Results.table``. The span ends at a quote followed
  by punctuation or the end (pyarrow's ``'PATH': ...``), and the table is named unreadable.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import sim
from sim.cli import main

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "results" / "brown_table1"  # read, never written


@pytest.mark.parametrize("folder", ["it's threads", "runs' threads"])
def test_a_damaged_table_under_a_quoted_threads_directory_is_not_short_of_memory(
    tmp_path, folder, capsys
):
    d = tmp_path / folder / "brown_table1"
    shutil.copytree(RESULTS, d, ignore=shutil.ignore_patterns("*.png", "trials"))
    f = d / "claims.parquet"
    f.write_bytes(f.read_bytes()[: f.stat().st_size // 2])  # its footer cut off
    # before: "cannot be read (not enough memory: Could not open Parquet input source ..."
    with pytest.raises(sim.ConfigError, match=r"claims.parquet cannot be read \(ArrowInvalid\)"):
        sim.Results(d, "brown_table1").table("claims")
    # before: "sim: error: not enough memory for this command: reading claims.parquet: ..."
    assert main(["report", "--results", str(d.parent)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "memory" not in err, err
    assert "claims.parquet" in err, err
