"""The classes of the sweep doors18a (issue 26: the file system, process limits and two
commands at once), one case each; each failed on the code before its fix. The harness that
found them (``run.sh``, about 250 cases) lives outside the project.

* a second ``sim run`` of another config into the same ``--out``, whose executor started
  (a Dask cluster, a process pool: seconds) while the first run published there, took the
  lock afterwards and replaced the first run's results at its end without ``--overwrite``:
  the output was checked before the lock, and checked again under it only as if
  ``--overwrite`` had been given (:func:`sim.execute.execute`);
* an ``--overwrite`` whose old results hold a file it may not remove keeps them in
  ``.<name>.old.<pid>``; in a container, where every command is the same pid, the next such
  run failed after every trial with "sim: error: Directory not empty: OUT", and so did every
  later run until the user found the hidden directory (:func:`sim.mc.publish.publish`);
* a umask that denies the owner (``umask 777``): ``sim run`` left a staging directory of mode
  000 that blocked every later run of that ``--out``, ``--overwrite`` included ("Permission
  denied: .../.lock"), and ``sim report`` replaced every README.md and REPORT.md by files no
  one may read, with exit 0; both are refused in one line naming the umask
  (:func:`sim.mc.storage.umask_problem`);
* a staging directory's ``.lock`` that is a symbolic or hard link to a file outside: taking
  the lock truncated that file and wrote the run's pid into it (data loss outside the
  output); a link or a FIFO there is now refused, naming it (:class:`sim.mc.storage.StageLock`);
* ``--workers 2`` under ``ulimit -n 14``: the pool's second worker could not start, the run
  printed its one line and then hung for good (the first worker waited for work, Python's
  exit for it); the pool now ends the workers it started (:class:`sim.mc.executors._Pool`);
* the staging directory removed or moved away while a run works (``rm -rf .<out>.partial``,
  or the working directory of a relative ``--out``): "internal error: AttributeError:
  'NoneType' object has no attribute 'get'", exit 3; now one line naming it
  (:func:`sim.mc.publish.seal`).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line, python_lines

from sim import execute
from sim.cli import main
from sim.mc import outputs
from sim.mc import publish as publishing
from sim.mc.config import ConfigError
from sim.mc.storage import read_record, write_record

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
SMALL = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]


def test_a_run_published_while_another_starts_its_executor_is_not_replaced(
    tmp_path, capsys, monkeypatch
):
    other = tmp_path / "other"
    assert main(["run", PLATE, *SMALL, "--seed", "9", "--out", str(other)]) == 0
    out = tmp_path / "out"
    real = execute.make_executor

    def slow_start(*args, **kwargs):  # the first run publishes while this one starts
        if not out.exists():
            shutil.copytree(other, out)
        return real(*args, **kwargs)

    monkeypatch.setattr(execute, "make_executor", slow_start)
    capsys.readouterr()
    rc = main(["run", PLATE, *SMALL, "--out", str(out)])
    one_line(
        capsys, rc, "--out", "holds results of a different config", "--overwrite", prefix=SIM_ERROR
    )
    assert json.loads((out / "run.json").read_text())["config"]["seed"] == 9
    for f in other.rglob("*"):  # the first run's results, byte for byte
        if f.is_file():
            assert (out / f.relative_to(other)).read_bytes() == f.read_bytes()
    assert not (tmp_path / ".out.partial").exists()


def test_old_results_left_by_a_run_of_the_same_pid_do_not_block_the_next(
    tmp_path, monkeypatch, capsys
):
    """``--overwrite`` of results holding a file that cannot be removed keeps the old results
    in ``.<name>.old.<pid>``; in a container every command is the same pid, and the next
    ``--overwrite`` failed after every trial with "Directory not empty" (and so did every
    run after it)."""
    out, stage = tmp_path / "res", tmp_path / ".res.partial"
    monkeypatch.setattr(publishing.shutil, "rmtree", lambda p, ignore_errors=False: None)
    for seed in (1, 2, 3):
        (stage / "trials").mkdir(parents=True)
        chunk = "trials/chunk-000000.parquet"
        write_record(stage, {"config": {"seed": seed}, "code_hash": "x", "files": [chunk]})
        (stage / "trials" / "chunk-000000.parquet").write_bytes(b"%d" % seed)
        publishing.publish(stage, out)
        assert read_record(out)["config"] == {"seed": seed} and not stage.exists()
    old = outputs.swap_dir(out)
    kept = sorted(p.relative_to(old).as_posix() for p in old.rglob("chunk-*"))
    assert kept == ["res.1/trials/chunk-000000.parquet", "trials/chunk-000000.parquet"]
    assert (old / "trials" / "chunk-000000.parquet").read_bytes() == b"1"
    assert (old / "res.1" / "trials" / "chunk-000000.parquet").read_bytes() == b"2"
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and err[1].startswith(
        f"sim: note: the replaced results are kept in {old / 'res.1'} ("
    )


def test_a_umask_that_denies_the_owner_is_refused_before_anything_is_made(tmp_path, capsys):
    """``umask 777``: a run left a staging directory of mode 000 that every later run (with
    ``--overwrite`` too) failed to lock, "Permission denied", until deleted by hand; ``sim
    report`` replaced every README.md and REPORT.md by files of mode 000 with exit 0."""
    res = tmp_path / "res"
    assert main(["run", PLATE, *SMALL, "--out", str(res / "network_plate")]) == 0
    assert main(["report", "--results", str(res)]) == 0
    before = {p: p.stat().st_mode for p in res.rglob("*.md")}
    capsys.readouterr()
    old = os.umask(0o777)
    try:
        rc_run = main(["run", PLATE, *SMALL, "--out", str(tmp_path / "o")])
        run_err = capsys.readouterr()
        rc_report = main(["report", "--results", str(res)])
    finally:
        os.umask(old)
    for rc, err in ((rc_run, run_err), (rc_report, capsys.readouterr())):
        line = err.err.removesuffix("\n")
        assert rc == 2 and "\n" not in line and "Traceback" not in err.err
        assert line.startswith("sim: error: umask 0777 denies the owner access"), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res"]  # no .o.partial
    assert {p: p.stat().st_mode for p in res.rglob("*.md")} == before


@pytest.mark.parametrize("kind", ["symlink", "hardlink", "fifo"])
def test_a_lock_path_that_is_not_a_lock_file_is_never_written_through(tmp_path, capsys, kind):
    """A staging directory whose ``.lock`` is a link to a file outside: taking the lock
    truncated that file and wrote the run's pid into it (a user's notes replaced by "18156")."""
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    stage = tmp_path / ".o.partial"
    stage.mkdir()
    lock = stage / ".lock"
    {"symlink": lambda: lock.symlink_to(notes), "hardlink": lambda: os.link(notes, lock)}.get(
        kind, lambda: os.mkfifo(lock)
    )()
    rc = main(["run", PLATE, *SMALL, "--out", str(tmp_path / "o")])
    one_line(capsys, rc, f"{lock} is not a lock file of sim", prefix=SIM_ERROR)
    assert notes.read_text() == "my notes\n" and not (tmp_path / "o").exists()


def test_a_process_pool_that_cannot_start_every_worker_ends(tmp_path):
    """``ulimit -n 14`` with ``--workers 2``: the second worker could not start (no pipe), the
    run printed its one line and then never ended: the first worker waited for work forever,
    and Python's exit waited for it. Each open-file limit just above what the process holds
    is tried in turn, so that the pool fails at each of its steps, the last one starting."""
    done = python_lines(
        "import gc, os, resource",
        "from sim.mc.executors import make_executor",
        "base = len(os.listdir('/proc/self/fd'))",
        "hard = resource.getrlimit(resource.RLIMIT_NOFILE)[1]",
        "failed = 0",
        "for extra in range(0, 80, 4):",
        "    resource.setrlimit(resource.RLIMIT_NOFILE, (base + extra, hard))",
        "    try:",
        "        ex = make_executor('local', 2, None)",
        "    except OSError:",
        "        failed += 1",
        "        gc.collect()  # the failed pool's queues",
        "        continue",
        "    ex.close()",
        "    break",
        "print(failed, extra)",
    )
    assert done.returncode == 0, done.stderr
    failed, extra = map(int, done.stdout.split())
    assert failed >= 1 and extra < 76  # refused under the smaller limits, then started


def test_a_staging_directory_removed_while_the_run_works_is_one_line(tmp_path):
    """``rm -rf .<out>.partial`` (or ``mv``, or the working directory of a relative ``--out``
    removed) while a run works: the chunks written after it made a new directory without a
    run record, and the run ended in "internal error: AttributeError: 'NoneType' object has
    no attribute 'get'" (exit 3)."""
    stage = tmp_path / ".o.partial"
    (stage / "trials" / "part-0").mkdir(parents=True)
    (stage / "trials" / "part-0" / "chunk-000003.parquet").write_bytes(b"late")
    with pytest.raises(ConfigError, match=r"^--out: .*\.o\.partial lost its run record"):
        publishing.seal(stage, None)
