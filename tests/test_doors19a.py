"""The classes of the sweep doors19a (issue 26: ``sim run`` and its neighbours killed with
SIGKILL at many points, then the same command again), one case each; each failed on the
code before its fix. The harness that found them (a sleep ladder and a hook that kills the
process at the k-th call of a chosen function, about 80 cases) lives outside the project.

* a run killed while it removed the results it had just replaced (``--overwrite``, or a
  re-run) left ``.<name>.old.<pid>`` beside the results for good: half of the old results,
  never named and never removed by any later run. The old results are now removed with
  their run record last, and the next publish of that output removes such a directory of
  a process no longer alive (or of its own pid: a container's) when it still holds a run
  record or is empty; a directory of that name that holds neither is the user's and kept
  (:func:`sim.mc.publish.publish`);
* a run killed after the old results went aside and before the new ones came in, then a run
  of another config with ``--overwrite``: the staging directory (with the copy of the user's
  file) was cleared, and the user's only file stayed in the hidden ``.<name>.old.<pid>``,
  never named; it is now brought into the new results (or, when the new run writes a file
  of its name, the directory is kept and named);
* ``python -m sim.batch`` (and ``make verify``) killed with SIGKILL: its study runs ran on,
  orphaned, holding their outputs' locks, and the same command run again was refused for
  each ("being written by a running sim"); a child run now asks to be sent SIGTERM when its
  driver dies (:func:`sim.mc.children.die_with_parent`) and ends as after Ctrl-C, its
  staging directory resumable;
* a worker of ``--workers 2`` killed (``kill -9``, the OOM killer): "sim: error: network: the
  run failed in sim.studies.network.run._mc: BrokenProcessPool: ...", exit 3 (the study
  blamed, as for a bug); now one line saying a worker ended abruptly and that the same
  command resumes, exit 2 (:func:`sim.execute.execute`);
* ``sim report`` killed while writing a README.md or REPORT.md left ``.README.md.<pid>.tmp``
  for good (the same command again did not remove it, and a re-run of the study carried it
  into the new results as the user's file); a write now removes the temporaries of its file
  that a dead process (or its own pid: a container's) left (:class:`sim.mc.storage.atomic_path`);
* one study run of ``python -m sim.batch`` killed (``kill -9``, the OOM killer): the batch
  ended with exit 1 and not a word; it now says which run was killed, by what, and that the
  same command resumes it (:func:`sim.batch.run_all`).
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import one_line

from sim.cli import main
from sim.mc import outputs
from sim.mc import publish as publishing
from sim.mc.storage import read_record

ROOT = Path(__file__).resolve().parents[1]
PLATE = str(ROOT / "studies" / "network_plate.toml")
SMALL = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]


class _Killed(BaseException):
    """Stands in for SIGKILL: nothing after it runs in the process (no handler catches it)."""


def _dead_pid() -> int:
    p = subprocess.Popen(["true"])
    p.wait()  # reaped: its pid names no process
    return p.pid


def test_a_run_killed_while_removing_the_replaced_results_leaves_nothing_after_the_next(
    tmp_path, monkeypatch
):
    out = tmp_path / "out"
    assert main(["run", PLATE, *SMALL, "--seed", "7", "--out", str(out)]) == 0
    (out / "user.txt").write_text("mine")
    real = publishing.shutil.rmtree

    def killed(p, *a, **k):  # the first removal of the old results' files: killed there
        raise _Killed

    monkeypatch.setattr(publishing.shutil, "rmtree", killed)
    cmd = ["run", PLATE, *SMALL, "--overwrite", "--out", str(out)]
    with pytest.raises(_Killed):
        main(cmd)
    monkeypatch.setattr(publishing.shutil, "rmtree", real)
    left = outputs.swap_dir(out)
    assert read_record(left) is not None  # the record is removed last: still the suite's
    # another run's leftover, of a process no longer alive; and a user's look-alike
    dead = tmp_path / f".out.old.{_dead_pid()}"
    real(left / "trials")
    left.rename(dead)
    users = tmp_path / ".out.old.5"
    users.mkdir()
    (users / "notes.txt").write_text("keep")
    empty = tmp_path / f".out.old.{_dead_pid()}"
    empty.mkdir()
    assert read_record(out)["config"]["seed"] != 7  # the new results were in place
    assert main(cmd) == 0  # the same command again
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [".out.old.5", "out"], names
    assert (users / "notes.txt").read_text() == "keep"
    assert (out / "user.txt").read_text() == "mine"


def test_a_run_killed_between_moving_the_old_results_aside_and_publishing_keeps_user_files(
    tmp_path, monkeypatch, capsys
):
    """Killed after the old results went aside and before the new ones came in: ``out`` is
    gone, the user's file is in the hidden old results (and a copy in the staging directory).
    A run of another config with ``--overwrite`` then cleared the staging directory, copy
    included, and left the only one in ``.out.old.<pid>`` for good, unnamed: now it is
    brought into the new results and the leftover removed."""
    out = tmp_path / "out"
    assert main(["run", PLATE, *SMALL, "--seed", "7", "--out", str(out)]) == 0
    (out / "user.txt").write_text("mine")
    # (the two renames: where the system cannot swap them in one step; doors27b)
    monkeypatch.setattr(publishing, "_exchange", lambda a, b: False)
    real = publishing.os.replace

    def killed(src, dst, *a, **k):
        real(src, dst, *a, **k)
        if Path(src) == out:
            raise _Killed

    monkeypatch.setattr(publishing.os, "replace", killed)
    with pytest.raises(_Killed):
        main(["run", PLATE, *SMALL, "--overwrite", "--out", str(out)])
    monkeypatch.setattr(publishing.os, "replace", real)
    assert not out.exists() and (outputs.swap_dir(out) / "user.txt").is_file()
    capsys.readouterr()
    assert main(["run", PLATE, *SMALL, "--seed", "3", "--overwrite", "--out", str(out)]) == 0
    assert "note" not in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (out / "user.txt").read_text() == "mine"
    assert read_record(out)["config"]["seed"] == 3


_CHILD = """
import signal, sys, time
from sim.mc.children import die_with_parent
signal.signal(signal.SIGTERM, lambda *a: (print("stopped", flush=True), sys.exit(130)))
print("ready" if die_with_parent() is None else "orphan", flush=True)
time.sleep(60)
"""

_DRIVER = """
import os, signal, subprocess, sys
from sim.mc.children import child_env
subprocess.Popen([sys.executable, "-c", sys.argv[1]], env=child_env())
sys.stdin.readline()
os.kill(os.getpid(), signal.SIGKILL)
"""


def test_a_child_run_ends_when_its_driver_is_killed():
    """The driver is killed with SIGKILL once its child is ready; the child is sent SIGTERM
    (reading the shared pipe to its end waits for both: without the fix, 60 s and no
    "stopped")."""
    drv = subprocess.Popen(
        [sys.executable, "-c", _DRIVER, _CHILD],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert drv.stdout.readline().strip() == "ready"
    drv.stdin.write("\n")
    drv.stdin.close()
    assert drv.stdout.read().split() == ["stopped"]
    assert drv.wait() == -9


def test_a_killed_worker_is_named_as_such_and_the_same_command_resumes(
    tmp_path, monkeypatch, capsys
):
    from concurrent.futures.process import BrokenProcessPool

    network_run = importlib.import_module("sim.studies.network.run")
    real = network_run._mc

    def broken(*a, **k):  # what the pool raises once a worker was killed
        raise BrokenProcessPool("A process in the process pool was terminated abruptly")

    out = tmp_path / "out"
    cmd = ["run", PLATE, *SMALL, "--out", str(out)]
    monkeypatch.setattr(network_run, "_mc", broken)
    capsys.readouterr()
    line = one_line(capsys, main(cmd), prefix="sim: error: network: a worker process of the run")
    assert line.endswith(
        "ended abruptly (killed, or out of memory?); the finished chunks are "
        "kept: run the same command again to resume"
    ), line
    monkeypatch.setattr(network_run, "_mc", real)
    assert main(cmd) == 0 and read_record(out) is not None


def test_a_temporary_left_by_a_killed_report_is_removed_by_the_next(tmp_path, capsys):
    res = tmp_path / "res"
    assert main(["run", PLATE, *SMALL, "--out", str(res / "network_plate")]) == 0
    assert main(["report", "--results", str(res)]) == 0
    dead = _dead_pid()
    left = [res / f".REPORT.md.{dead}.tmp", res / "network_plate" / f".README.md.{dead}.tmp"]
    live = res / f".REPORT.md.{os.getppid()}.tmp"  # a live writer's: kept
    for p in (*left, live):
        p.write_text("half a report")
    before = (res / "REPORT.md").read_bytes()
    assert main(["report", "--results", str(res)]) == 0
    assert not any(p.exists() for p in left) and live.read_text() == "half a report"
    assert (res / "REPORT.md").read_bytes() == before


def test_a_batch_says_which_run_was_killed(tmp_path, monkeypatch, capsys):
    from sim import batch

    real = batch.subprocess.Popen
    suicide = "import os, signal; os.kill(os.getpid(), signal.SIGKILL)"

    def killed(cmd, *a, **k):  # the study's run, killed at its start
        return real([sys.executable, "-c", suicide], *a, **k)

    monkeypatch.setattr(batch.subprocess, "Popen", killed)
    capsys.readouterr()
    rc = batch.main(["--results", str(tmp_path / "res"), PLATE])
    err = capsys.readouterr().err
    assert rc != 0 and "Traceback" not in err
    assert err.splitlines() == [
        "network_plate.toml: its run was killed by SIGKILL; the same command again resumes it"
    ], err
