"""The classes of the sweep doors41c (brief C41: concurrency and interruption with the last
session's records -- a sweep's per-cell sha256, the values digests of ``table_shape``, the
cells' provenance checks -- under kills at each step of publishing, two writers at once, and
readers while a writer replaces results), one case each; each failed on the code before its
fix.

* Two runs of the Python API in two threads of one process, one with ``figures=False``: the
  flag that turns figures off was the process's (a ``threading.Event``), so the other run,
  into its own ``out``, drew no figure either, and published its tables with a ``run.json``
  that said its figures were drawn (no ``"figures": false``: ``--stale-only`` called them
  current) and a README.md that guessed "a run with ``--no-figures``?". The flag is now a
  context variable (:func:`sim.report.plotting.without_figures`), which the threads a study
  runs its parts in take a copy of (:func:`sim.studies.design.parts.side_by_side`).
* A second ``sim run`` of the same command, started while the first was between sealing its
  staging directory and publishing it, after an earlier run of it had been killed between
  publishing's two steps (its results still naming the results they replaced,
  ``run.json`` ``replaced``): the first's sealed record is byte for byte the replaced one
  (same config, same code), so the second took the running staging directory for the replaced
  results left behind and removed it, lock file and all, before taking the lock; it then ran
  the whole study beside the first and published (exit 0), and the first, every chunk
  computed, ended "cannot be read as the run's record; run again" (exit 2). A staging
  directory whose lock is held is never taken for replaced results
  (:func:`sim.mc.left_behind.replaced_results`): the second is refused, naming the run.
* ``sim report`` while a run published a study (``make reproduce`` in another terminal):
  REPORT.md's text was built first, then every study's README.md written (seconds), then
  REPORT.md written from that text, so a run published meanwhile left REPORT.md with the
  replaced run's headline claims and consistent region beside the new run's directory and
  README.md, exit 0. REPORT.md is built again when a study was published while the READMEs
  were written (:func:`sim.report.markdown.write_report`).
* The output of a run stopped before it published (killed, interrupted after its chunks:
  only ``.DIR.partial`` is there) was "DIR does not exist" to ``sim show DIR`` and
  ``sim.Results``, and "no study results" to ``sim report``, as if no run had been made:
  nothing said that the run is unfinished and that the same command finishes it, or that a
  run is writing it now, or that it failed, and why (:func:`sim.mc.unfinished.unfinished`).
* ``make verify`` while ``make rerun`` (another terminal) replaced a study's committed results
  made with overrides by a run of others: verify re-ran the overrides it had read before, and
  the comparison with the new results said they were "of another config than the re-run with
  the run's overrides ... stale against <the study file> (edited since the run?)", a failure
  recorded in ``reproducibility.parquet`` against the new tables, of which no re-run had been
  made. It now says the results were replaced while verify re-ran them
  (:func:`sim.report.verify.rerun._replaced_since`).

Held (found right): a sweep of three cells killed (SIGKILL) at its fifth table write, before
and after sealing, after its README.md, after the swap, while removing the replaced results,
before clearing stale swaps and at a record write of ``--overwrite`` over another seed's
sweep: ``sim show`` (of the sweep and of a cell) and ``sim report`` show one whole run (or,
before a first publish, now say the run is unfinished), and
the same command again gives every table and ``run.json`` byte for byte as a clean run;
two sweeps into one ``--out`` at once and ``python -m sim.batch`` while a ``sim run`` writes
one of its results (the second refused naming the first's pid, by the command line, the API
and the batch); two API runs in two threads on one ``out`` (the second named as a thread of
this process); ``sim show`` and ``Results.table`` of a sweep's cell while the sweep is
replaced by another seed's (read again: one run); a cell's table edited and read through a
symbolic link to the cell (the sweep's sha256 names it).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import shutil
import threading
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK, tiny_overrides

import sim
from sim import execute
from sim.cli import main
from sim.mc.outputs import stage_dir
from sim.mc.storage import StageLock, write_record
from sim.report import markdown
from sim.report.verify import rerun as verify_rerun

ROOT = Path(__file__).resolve().parents[1]

NETWORK = TRIANGLE_NETWORK


def _study(tmp_path: Path, text: str = NETWORK) -> Path:
    f = tmp_path / "net.toml"
    f.write_text(text, encoding="utf-8")
    return f


def test_a_run_without_figures_in_one_thread_leaves_another_threads_figures(tmp_path):
    h = sim.load(_study(tmp_path))
    inside, other_done = threading.Event(), threading.Event()
    real = h.study.run

    def held(cfg, d, ctx):  # the run without figures is inside its trials while the other runs
        inside.set()
        assert other_done.wait(120)
        return real(cfg, d, ctx)

    no_figures = dataclasses.replace(h, study=dataclasses.replace(h.study, run=held))
    failed: list[BaseException] = []

    def first() -> None:
        try:
            no_figures.run(out=tmp_path / "a", figures=False)
        except BaseException as e:  # noqa: BLE001 - said by the test below
            failed.append(e)

    t = threading.Thread(target=first)
    t.start()
    try:
        assert inside.wait(120)
        res = h.run(out=tmp_path / "b")
    finally:
        other_done.set()
        t.join()
    assert not failed
    rec = json.loads((res.path / "run.json").read_text(encoding="utf-8"))
    assert "figures" not in rec  # drawn, it says
    drawn = sorted(p.name for p in res.path.glob("*.png"))
    assert drawn == ["network.png", "reliability.png"]  # before: none
    assert sorted(rec["figure_sha256"]) == drawn
    assert not list((tmp_path / "a").glob("*.png"))  # and the other run drew none


def test_a_second_run_never_removes_a_running_runs_staging_directory(tmp_path, monkeypatch, capsys):
    out = tmp_path / "X"
    run = ["run", str(_study(tmp_path)), "--quiet", "--no-figures", "--out", str(out)]
    assert main(run) == 0
    sealed = (out / "run.json").read_bytes()
    clean = {p.name: p.read_bytes() for p in out.glob("*.parquet")}
    # what a run of the same command killed after its swap leaves: its record names the one
    # it replaced (the same bytes: the same config and code)
    replaced = hashlib.sha256(sealed).hexdigest()
    write_record(out, {**json.loads(sealed), "replaced": replaced})
    real, second = execute.publish, []

    def publish(stage, to):  # sealed, about to publish: another `sim run` of it now
        if not second:
            second.append(None)
            second[0] = main(run)
        return real(stage, to)

    monkeypatch.setattr(execute, "publish", publish)
    capsys.readouterr()
    assert main(run) == 0  # before: 2, "... cannot be read as the run's record; run again"
    err = capsys.readouterr().err
    assert second == [2]  # before: 0, the whole study run beside the first
    assert "is being written by a running sim" in err
    assert {p.name: p.read_bytes() for p in out.glob("*.parquet")} == clean
    assert (out / "run.json").read_bytes() == sealed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X", "net.toml"]


@pytest.fixture(scope="module")
def two_salsig_runs(tmp_path_factory):
    """Tiny runs of ``salsig_encoders`` with the seeds 7 and 8 (other headline numbers)."""
    root = tmp_path_factory.mktemp("salsig")
    sets = tiny_overrides("salsig_encoders")
    for seed in (7, 8):
        run = ["run", str(ROOT / "studies" / "salsig_encoders.toml"), "--quiet", "--no-figures"]
        assert main([*run, *sets, "--seed", str(seed), "--out", str(root / f"s{seed}")]) == 0
    return root


def test_report_of_a_study_published_meanwhile_is_of_the_new_run(
    two_salsig_runs, tmp_path, monkeypatch
):
    results, name = tmp_path / "results", "salsig_encoders"
    shutil.copytree(two_salsig_runs / "s7", results / name)
    shutil.copytree(two_salsig_runs / "s8", tmp_path / "new")
    real, done = markdown.write_run_readme, []

    def write_run_readme(*args, **kwargs):  # a run of seed 8 publishes while READMEs are written
        if not done:
            done.append(1)
            os.rename(results / name, tmp_path / f".{name}.old.1")
            os.rename(tmp_path / "new", results / name)
        return real(*args, **kwargs)

    monkeypatch.setattr(markdown, "write_run_readme", write_run_readme)
    assert main(["report", "--results", str(results)]) == 0
    monkeypatch.undo()
    raced = (results / "REPORT.md").read_text(encoding="utf-8")
    assert main(["report", "--results", str(results)]) == 0
    assert raced == (results / "REPORT.md").read_text(encoding="utf-8")  # before: seed 7's


def test_the_output_of_a_run_stopped_before_it_published_is_said_unfinished(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"

    def stopped(stage, store):  # every chunk done, stopped before it sealed and published
        raise KeyboardInterrupt

    monkeypatch.setattr(execute, "seal", stopped)
    run = ["run", str(_study(tmp_path)), "--quiet", "--no-figures", "--out", str(out)]
    assert main(run) == 130
    monkeypatch.undo()
    assert stage_dir(out).is_dir() and not out.exists()
    capsys.readouterr()
    finish = "its run did not finish"
    assert main(["show", str(out)]) == 2
    assert finish in capsys.readouterr().err  # before: "X does not exist"
    assert main(["report", "--results", str(tmp_path)]) == 2
    assert finish in capsys.readouterr().err  # before: "no study results in ..." alone
    with pytest.raises(sim.ConfigError, match=finish):
        sim.Results(out, "network").claims()
    lock = StageLock(stage_dir(out)).acquire()  # a run writing it now
    try:
        assert main(["show", str(out)]) == 2
        assert "a run is writing it now" in capsys.readouterr().err
    finally:
        lock.release()
    assert main(run) == 0  # and the same command finishes it


def test_verify_of_results_replaced_while_it_re_ran_them_says_so(
    two_salsig_runs, tmp_path, monkeypatch
):
    results, name = tmp_path / "results", "salsig_encoders"
    shutil.copytree(two_salsig_runs / "s7", results / name)

    def rerun_study(d, study, target, *args):  # the re-run of seed 7's overrides, while a
        os.rename(d, tmp_path / f".{name}.old.1")  # run of seed 8 publishes in d
        shutil.copytree(two_salsig_runs / "s8", d)
        shutil.copytree(two_salsig_runs / "s7", target)
        return None

    monkeypatch.setattr(verify_rerun, "rerun_study", rerun_study)
    (comp,) = verify_rerun.verify(results, tmp_path / "scratch", studies=ROOT / "studies")
    assert not comp.ok
    assert "was replaced while verify re-ran it" in comp.failures[0]  # before: "stale against"
    assert "(keys seed)" in comp.failures[0]
