"""The classes of the sweep doors35v (brief V35: who owns ``results/``: committed results,
overrides, left-behind directories), one case each; each failed on the code before its fix.

* ``sim run studies/X.toml`` with an override (``--set``, ``--trials``, ``--seed``,
  ``--chunk``) and no ``--out`` wrote the committed ``results/X`` when it did not exist yet
  (the user's experiment became the study's results, for ``sim report``, REPORT.md and ``make
  verify``), and rewrote it, its ``run.json`` now naming the override, when the override gave
  the committed config (``--seed`` of the file's value). A run with overrides goes to
  ``scratch/X-<config hash>/`` and says so (:func:`sim.places.default_out`); the file as written still
  writes ``results/X``.
* ``sim run studies/X.toml --no-figures`` without ``--out`` replaced the committed
  ``results/X`` by results without figures: its PNG files deleted, exit 0. It goes to
  ``scratch/`` too.
* ``python -m sim.batch studies/X.toml -- --seed 6`` (no ``--results``: the default
  ``results/``) replaced the committed ``results/X`` with a run off the study file, where
  ``sim run`` of the same goes to ``scratch/``: refused before any run, naming ``--results``
  (``make reproduce`` and ``make rerun`` give ``--results results``: their ``RUN_FLAGS`` are
  asked for).
* ``python -m sim.batch mine/my_net.toml`` in the project's root wrote a new
  ``results/my_net`` into the committed results, where ``sim run mine/my_net.toml`` goes to
  ``scratch/`` (doors22d): refused naming ``--results`` (with ``--results results`` it is
  written, as asked).
* ``sim run studies/net_c.toml`` (a new study file of the project's, of the study kind
  ``network`` whose ``results/network`` exists) went to ``scratch/network-<hash>/``, said to
  be "of another config" than ``results/network``, where ``make reproduce`` writes
  ``results/net_c``: it writes ``results/net_c`` too (a copy outside ``studies/`` is still
  compared with the study kind's results).
* ``make verify``'s record (``reproducibility.parquet``) did not say with which overrides
  each study was re-run: it has the column ``overrides`` (the run's, as its ``run.json``
  records them), and the report's *Reproducibility* section names them.
* ``make verify`` killed outright (``kill -9``) left its ``$TMPDIR/sim-verify-*`` (the re-runs'
  results) for good: its directory is ``sim-verify-<pid>-XXXXXXXX`` with a marker holding
  that pid, and a later verify removes those of a dead verify (not one of a live process,
  without the marker, or of another name: :mod:`sim.report.verify.scratch`).
* ``make bench BENCH_FLAGS=--quick`` (the docs' smoke run) replaced the committed full
  measurements of ``results/bench`` (``BENCH_OUT``'s default) with its tiny sizes' numbers:
  a smoke run goes to ``scratch/bench-quick`` by default (make and ``python -m benchmarks``),
  and a directory holding a full benchmark's tables is refused to it, naming ``--out``.
* ``python -m sim.batch`` interrupted while it checked its files said "interrupted; the same
  command again resumes the unfinished runs" of a batch that had started none: it says that
  nothing was run.

Held (found right): ``sim.load(...).run()`` without ``out`` writes a new temporary directory,
never ``results/``; ``sim run`` of the study file as written still writes ``results/X`` when it
holds the committed config and code (the same numbers); ``make verify --scratch results`` is
refused (the committed results); ``sim show`` and ``sim check`` write nothing.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import one_line
from test_doors18c import make

import sim.batch
from benchmarks.cli import main as bench_main
from sim import cli
from sim.report.verify import main as verify_main
from sim.report.verify.record import markdown
from sim.report.verify.scratch import MARK

ROOT = Path(__file__).resolve().parents[1]
NET = """study = "network"
trials = 40
chunk = 2
seed = 5
[network]
name = "mine"
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = "P", sigma_mm = 0.002 } ]
"""


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A project root: ``studies/net_a.toml`` with its committed results (figures drawn),
    ``studies/net_b.toml`` with none; copy it before writing (:func:`project`)."""
    root = tmp_path_factory.mktemp("made")
    (root / "studies").mkdir()
    for name in ("net_a", "net_b"):
        (root / "studies" / f"{name}.toml").write_text(NET)
    here = os.getcwd()
    os.chdir(root)
    try:
        assert cli.main(["run", "studies/net_a.toml", "--quiet"]) == 0
    finally:
        os.chdir(here)
    assert sorted(p.name for p in (root / "results" / "net_a").glob("*.png"))
    return root


@pytest.fixture
def project(made, tmp_path, monkeypatch):
    """A copy of :func:`made` as the working directory."""
    root = tmp_path / "p"
    shutil.copytree(made, root, symlinks=True)
    monkeypatch.chdir(root)
    return root


def _files(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def test_a_run_with_overrides_without_out_leaves_the_committed_results(project, capsys):
    committed = _files(project / "results" / "net_a")
    # the file's own seed: the committed config, rewritten with "overrides": ["seed=5"]
    assert cli.main(["run", "studies/net_a.toml", "--seed", "5", "--quiet"]) == 0
    assert _files(project / "results" / "net_a") == committed
    err = capsys.readouterr().err
    assert "a run with the overrides seed=5 is not studies/net_a.toml as written" in err, err
    assert "writing to scratch/net_a-" in err, err
    # no results yet: the experiment became results/net_b
    assert cli.main(["run", "studies/net_b.toml", "--set", "trials=60", "--quiet"]) == 0
    assert not (project / "results" / "net_b").exists()
    (out,) = (project / "scratch").glob("net_b-*")
    assert json.loads((out / "run.json").read_text())["overrides"] == ["trials=60"]
    capsys.readouterr()


def test_a_run_without_figures_leaves_the_committed_figures(project, capsys):
    committed = _files(project / "results" / "net_a")
    assert cli.main(["run", "studies/net_a.toml", "--no-figures", "--quiet"]) == 0
    assert _files(project / "results" / "net_a") == committed  # before: the PNGs deleted
    err = capsys.readouterr().err
    assert "a run with --no-figures is not studies/net_a.toml as written" in err, err
    # the file as written still writes the committed results (the same numbers)
    assert cli.main(["run", "studies/net_a.toml", "--quiet"]) == 0
    assert capsys.readouterr().err == ""
    assert _files(project / "results" / "net_a").keys() == committed.keys()


def test_a_batch_with_overrides_needs_results_named(project, capsys):
    committed = _files(project / "results" / "net_a")
    rc = sim.batch.main(["studies/net_a.toml", "--", "--seed", "6", "--quiet"])
    one_line(capsys, rc, "the overrides seed=6", "give --results DIR", prefix="sim.batch: ")
    rc = sim.batch.main(["studies/net_a.toml", "--", "--no-figures"])
    one_line(capsys, rc, "--no-figures", "--results results", prefix="sim.batch: ")
    assert _files(project / "results" / "net_a") == committed


def test_a_batch_of_an_authors_file_needs_results_named(project, capsys):
    (project / "mine").mkdir()
    (project / "mine" / "my_net.toml").write_text(NET)
    rc = sim.batch.main(["mine/my_net.toml"])
    words = "mine/my_net.toml is not a study file of the project's studies"
    one_line(capsys, rc, words, "give your own --results DIR", prefix="sim.batch: ")
    assert not (project / "results" / "my_net").exists()  # before: made, exit 0


def test_a_new_study_file_of_the_project_runs_into_its_own_results(project, capsys):
    shutil.copytree(project / "results" / "net_a", project / "results" / "network")
    (project / "studies" / "network.toml").write_text(NET)
    (project / "studies" / "net_c.toml").write_text(NET.replace("seed = 5", "seed = 9"))
    assert cli.main(["run", "studies/net_c.toml", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert out == "network: results in results/net_c/\n", out  # before: scratch/network-...
    assert (
        json.loads((project / "results" / "net_c" / "run.json").read_text())["config"]["seed"] == 9
    )


def test_the_verify_record_names_the_overrides_of_each_run(project, capsys):
    res = project / "res"
    argv = ["run", "studies/net_b.toml", "--seed", "6", "--out", str(res / "net_b"), "--quiet"]
    assert cli.main([*argv, "--no-figures"]) == 0
    assert verify_main(["--results", str(res), "--workers", "1"]) == 0
    capsys.readouterr()
    t = pq.read_table(res / "reproducibility.parquet").to_pylist()
    assert [(r["study"], r["ok"], r["overrides"]) for r in t] == [("net_b", True, ["seed=6"])]
    assert "yes (re-run with the run's overrides: seed=6)" in markdown(res)


def _dead_pid() -> int:
    p = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], text=True,
                       capture_output=True, check=True)  # fmt: skip
    return int(p.stdout)


def test_a_later_verify_removes_the_scratch_of_a_killed_verify(
    project, tmp_path, monkeypatch, capsys
):
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(tmp))
    dead, live = _dead_pid(), os.getppid()
    left = tmp / f"sim-verify-{dead}-abcd_123"  # as a verify killed -9 left it
    (left / "net_a" / "trials").mkdir(parents=True)
    (left / MARK).write_text(str(dead))
    kept = [tmp / f"sim-verify-{live}-abcd_123", tmp / f"sim-verify-{dead}-unmarked"]
    kept += [tmp / f"sim-verify-{dead}-othermrk", tmp / "sim-verify-olderone"]
    for d, text in zip(kept, [str(live), None, str(live), str(dead)]):
        d.mkdir()
        if text is not None:
            (d / MARK).write_text(text)
    empty = project / "empty"
    empty.mkdir()
    one_line(capsys, verify_main(["--results", str(empty)]), "no study results")
    assert sorted(tmp.iterdir()) == sorted(kept)  # before: left for good


def test_a_batch_interrupted_while_checking_its_files_says_nothing_ran(
    project, monkeypatch, capsys
):
    real = sim.batch._configs_problems

    def checking(*a, **k):
        os.kill(os.getpid(), signal.SIGINT)  # handled before the next line of Python runs
        return real(*a, **k)

    monkeypatch.setattr(sim.batch, "_configs_problems", checking)
    rc = sim.batch.main(["studies/net_a.toml", "--results", str(project / "r")])
    line = one_line(capsys, rc, code=130)
    assert line == "sim.batch: interrupted before any run started: nothing was run"
    assert not (project / "r").exists()


def test_a_smoke_benchmark_leaves_the_committed_measurements(tmp_path, capsys):
    full = tmp_path / "bench"
    shutil.copytree(ROOT / "results" / "bench", full)
    before = _files(full)
    rc = bench_main(["--quick", "--only", "engines", "--out", str(full)])
    one_line(capsys, rc, "holds the measurements of a full benchmark", "give another --out")
    assert _files(full) == before  # before: engines.parquet, engines.png, README.md replaced
    p = make("-n", "bench", "BENCH_FLAGS=--quick")
    assert p.stdout.strip().endswith("--out 'scratch/bench-quick' --quick"), (p.stdout, p.stderr)
