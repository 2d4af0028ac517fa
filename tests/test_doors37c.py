"""The classes of the sweep doors37c (brief C37: concurrency and interruption with the last
session's features: two runs into one default ``scratch/`` directory, readers of a directory
a run publishes, two verifies, a kill at each phase and the same command again), one case
each; each failed on the code before its fix.

* ``sim show DIR`` while a run published ``DIR`` (``sim run --overwrite`` with another seed in
  another terminal) read the claims table's provenance of the old run and then the claims of
  the new one: it printed the new run's claims and counts under the old run's configuration
  note (``seed`` = 7 of a run of seed 8), exit 0. It now reads again when another directory
  took the place of ``DIR`` while it read (:mod:`sim.mc.settle`), and prints one run.
* ``sim.Results(path, study).table(name)`` read ``run.json`` of the old run and the table of
  the new one, and called a directory that holds one whole run one that "mixes results of
  two runs; run its study again" (a table read before a run published another shape was
  "not the table its run wrote": edited by hand). It reads again the same way, and returns
  the new run's table.

Held (found right): two ``sim run`` of one study with the same override and no ``--out`` (one
``scratch/<name>-<hash>/``): the second stops at once naming the first's pid, the first's
results are whole; a run killed (SIGINT, SIGTERM, SIGKILL) during its trials, after them
(before sealing), while drawing its figures and at each step of publishing, then the same
command again (also ``--overwrite`` over earlier results of another seed, a file of the
user's in them): tables byte for byte those of an uninterrupted run, the user's file kept,
no staging or swap directory left; ``make verify --scratch DIR`` interrupted (SIGINT,
SIGTERM, SIGKILL) during its re-run, then again: the re-run resumes its chunks and compares
ok, no ``sim run`` left running.
"""

from __future__ import annotations

import os
import shutil

import pyarrow.parquet as pq
import pytest

import sim
from sim.cli import main
from sim.report import read as read_mod
from sim.report import run_summary

RUN = ["run", "studies/brown_table1.toml", "--trials", "40", "--chunk", "2", "--quiet"]
RUN += ["--set", "region.points=256", "--set", "region.rounds=0", "--no-figures"]


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    """Results of two seeds of one config (7 and 8), made once for the module."""
    root = tmp_path_factory.mktemp("runs")
    for seed in (7, 8):
        assert main([*RUN, "--seed", str(seed), "--out", str(root / f"s{seed}")]) == 0
    return root


def _published_while_read(two_runs, tmp_path):
    """``X`` holding the run of seed 7, and a publish that puts the run of seed 8 in its place
    (as :func:`sim.mc.publish.publish` does: a new directory at the path, the old moved
    aside), to be called by a reader at the moment of the race."""
    x, y = tmp_path / "X", tmp_path / "Y"
    shutil.copytree(two_runs / "s7", x)
    shutil.copytree(two_runs / "s8", y)
    done = []

    def publish() -> None:
        if not done:
            done.append(1)
            os.rename(x, tmp_path / ".X.old.1")
            os.rename(y, x)

    return x, publish


def test_show_of_a_directory_a_run_publishes_prints_one_run(
    two_runs, tmp_path, monkeypatch, capsys
):
    x, publish = _published_while_read(two_runs, tmp_path)
    real = run_summary.records

    def records(path):  # the claims read after the provenance that names the config
        publish()
        return real(path)

    monkeypatch.setattr(run_summary, "records", records)
    assert main(["show", str(x)]) == 0
    raced = capsys.readouterr().out
    monkeypatch.undo()
    assert main(["show", str(x)]) == 0
    whole = capsys.readouterr().out
    assert "`seed` = 8" in whole
    assert raced == whole  # before: seed 8's claims under "`seed` = 7 (the file: 1967)"


def test_results_of_a_directory_a_run_publishes_read_one_run(two_runs, tmp_path, monkeypatch):
    x, publish = _published_while_read(two_runs, tmp_path)
    real = read_mod.read_record

    def read_record(d):  # run.json read, then the table's provenance of the new run
        rec = real(d)
        publish()
        return rec

    monkeypatch.setattr(read_mod, "read_record", read_record)
    got = sim.Results(x, "brown_table1").claims()  # before: "mixes results of two runs"
    assert got.equals(pq.read_table(two_runs / "s8" / "claims.parquet"))
