"""Doors of session 51 found by the lead: ``make verify`` over a ``reproducibility.parquet``
that make verify did not write (a user's own file of that name, another table, a truncated
copy) re-ran every study and then replaced it with its record without a word; refused now
before any re-run, naming the file and --no-record, the file kept. The suite's own record is
replaced as before."""

from __future__ import annotations

import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from oneline import one_line

import sim.report.verify.cli as verify_cli

RECORD = Path(__file__).resolve().parents[1] / "results" / "reproducibility.parquet"


class _Started(Exception):
    """The re-runs were reached."""


def _no_rerun(*args, **kwargs):
    raise _Started()


@pytest.mark.parametrize("kind", ["text", "table", "truncated"])
def test_a_file_make_verify_did_not_write_is_not_replaced(capsys, monkeypatch, tmp_path, kind):
    """Class: deleting or changing what the suite did not write. Before: the file was replaced
    by verify's record after every re-run (hours), exit 0; now one line before any re-run."""
    results = tmp_path / "res"
    results.mkdir()
    rec = results / "reproducibility.parquet"
    if kind == "text":
        rec.write_text("my notes on reproducibility\n", encoding="utf-8")
    elif kind == "table":
        pq.write_table(pa.table({"study": ["mine"], "ok": [True]}), rec)
    else:
        rec.write_bytes(RECORD.read_bytes()[:300])
    before = rec.read_bytes()
    monkeypatch.setattr(verify_cli, "verify", _no_rerun)
    rc = verify_cli.main(["--results", str(results), "--studies", str(tmp_path)])
    one_line(capsys, rc, "is not a record of make verify", "--no-record", str(rec))
    assert rec.read_bytes() == before


def test_the_suites_own_record_is_replaced_as_before(monkeypatch, tmp_path):
    """The property's other side: a record make verify wrote does not stop a verify (the
    re-runs are reached)."""
    results = tmp_path / "res"
    results.mkdir()
    shutil.copy(RECORD, results / RECORD.name)
    monkeypatch.setattr(verify_cli, "verify", _no_rerun)
    with pytest.raises(_Started):
        verify_cli.main(["--results", str(results), "--studies", str(tmp_path)])
