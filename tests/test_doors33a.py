"""The classes of the sweep doors33a (brief A33: interrupts placed per phase of ``sim report``,
``python -m sim.batch`` and ``make verify``), one case each; each failed on the code before its
fix. Each phase is reached by a patched function that sends the process the signal itself.

* SIGINT or SIGTERM just before a file's rename (:class:`sim.mc.storage.atomic_path`: only an
  OSError there removed the temporary) left ``.REPORT.md.<pid>.tmp`` in the results directory
  after ``sim report`` (and ``.README.md.<pid>.tmp`` in a study's, a chunk's in a run's) until
  a later write into it: the temporary now goes on any exception, which is raised as it was.
* ``python -m sim.batch`` interrupted after every run ended, while it wrote ``--timings`` or its
  summary, said "interrupted; the same command again resumes the unfinished runs" (there were
  none) and left the timings file of an earlier batch as this one's: the timings are written
  first (the signal handled once they are, as a run's publishing) and the line says so.
* ``python -m sim.batch`` sent SIGTERM while one of its runs published its results: the run
  published them and said so ("interrupted after the results were written to X/"), but the
  driver dropped the run's words and said only "interrupted; the same command again resumes
  the unfinished runs", as if that run were unfinished: its line now names the study files
  whose runs wrote their results.
* ``make verify`` interrupted after every re-run ended and was compared said "interrupted; the
  re-run was stopped": while it printed the comparisons (the record is then not written: the
  line says so), while it wrote ``reproducibility.parquet`` (now written first, then handled:
  the line says it was recorded), and while it removed its temporary scratch directory, which
  was left in the temporary directory for good (now removed first).
* SIGTERM to ``make`` of ``make verify`` (``timeout 1h make verify``, a CI job's limit) ended
  make and its shell only: verify, orphaned, ran on with its re-run, printed its comparisons
  after make had said "Terminated" and wrote the record into the results. The Makefile names
  the shell to verify (``SIM_STOP_WITH_PARENT=$$``, as ``sim.batch`` names itself to its runs),
  which ends as after SIGTERM when the shell does: its re-run stopped, its temporary scratch
  removed, nothing recorded.

Held (found right; each phase by a process sending itself SIGINT and SIGTERM, then the same
command again): ``sim report`` while reading the tables, before and after each study's README.md
and before a study's section (exit 130, one line; every file as before or as the report writes
it, no temporary; the next report exit 0); ``python -m sim.batch`` between two studies of
``--jobs 1`` and while a run of ``--jobs 2`` writes its README while the other computes (the
ended run's results complete, the other's ``.X.partial`` resumed by the same command, which
``--stale-only`` then reports up to date; no child left, the ``--timings`` lock removed);
``make verify`` during a re-run (as it starts, while it publishes and writes its README: the
re-run stopped, its staging directory under ``--scratch`` resumed by the next verify, which ends
ok) and while comparing (exit 130, nothing recorded, the temporary scratch removed).
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import sim.batch
import sim.report.verify.cli as verify_cli
from sim.cli import main
from sim.mc import storage
from sim.report.verify.rules import Comparison

ROOT = Path(__file__).resolve().parent.parent
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
RUN = ["run", TABLE1, "--trials", "40", "--chunk", "2", "--quiet", "--no-figures"]
RUN += ["--set", "region.points=256", "--set", "region.rounds=0"]
SIGNALS = [pytest.param(s, id=s.name) for s in (signal.SIGINT, signal.SIGTERM)]


def _kill_me(sig) -> None:
    os.kill(os.getpid(), sig)  # handled before the next line of Python runs


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A results directory with one small run of brown_table1 (copy it before writing)."""
    res = tmp_path_factory.mktemp("res")
    assert main([*RUN, "--out", str(res / "brown_table1")]) == 0
    return res


def _files(d: Path) -> dict[str, bytes]:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("sig", SIGNALS)
def test_an_interrupt_before_the_rename_of_report_md_leaves_no_temporary(
    results, tmp_path, monkeypatch, capsys, sig
):
    res = tmp_path / "res"
    shutil.copytree(results, res)
    assert main(["report", "--results", str(res)]) == 0
    before = _files(res)
    real = os.replace

    def replace(src, dst, *a, **k):
        if Path(dst).name == "REPORT.md":
            _kill_me(sig)
        return real(src, dst, *a, **k)

    monkeypatch.setattr(storage.os, "replace", replace)
    capsys.readouterr()
    rc = main(["report", "--results", str(res)])
    assert (rc, capsys.readouterr().err) == (130, "sim: interrupted\n")
    # before: .REPORT.md.<pid>.tmp stayed beside the REPORT.md it did not replace
    assert _files(res) == before
    monkeypatch.undo()
    assert main(["report", "--results", str(res)]) == 0 and _files(res) == before


def _batch_timings(tmp_path, monkeypatch, capsys, sig):
    """python -m sim.batch whose runs ended (``run_all`` returns their timings) interrupted by
    ``sig`` as it begins to write ``--timings``."""
    timings = tmp_path / "t.json"
    timings.write_text('{"an earlier batch": [0, 1.0, 0.0]}')
    done = {"brown_table1": [0, 2.5, 0.0]}
    monkeypatch.setattr(sim.batch, "run_all", lambda *a, **k: dict(done))
    real = sim.batch.atomic_path

    class interrupted(real):
        def __enter__(self):
            _kill_me(sig)
            return super().__enter__()

    monkeypatch.setattr(sim.batch, "atomic_path", interrupted)
    rc = sim.batch.main([TABLE1, "--results", str(tmp_path / "r"), "--timings", str(timings)])
    return rc, capsys.readouterr(), timings, done


@pytest.mark.parametrize("sig", SIGNALS)
def test_a_batch_interrupted_while_writing_its_timings_says_its_runs_ended(
    tmp_path, monkeypatch, capsys, sig
):
    rc, out, timings, done = _batch_timings(tmp_path, monkeypatch, capsys, sig)
    # before: "sim.batch: interrupted; the same command again resumes the unfinished runs",
    # and t.json still the earlier batch's
    words = f"sim.batch: interrupted after every run ended; their timings were written to {timings}"
    assert (rc, out.err.strip()) == (130, words)
    assert json.loads(timings.read_text()) == done
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.json"]  # no lock, no temporary


def _verify(tmp_path, monkeypatch, sig, at: str, *options: str):
    """``make verify`` whose re-runs ended and were compared (one study, ok), interrupted by
    ``sig`` at ``at``: printing the comparisons, writing the record, removing its temporary
    scratch directory."""
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()

    def verify(results, scratch, **k):
        (scratch / "brown_table1").mkdir()  # a re-run's results in the scratch directory
        (scratch / "brown_table1" / "claims.parquet").write_bytes(b"")
        return [Comparison("brown_table1", files=6)]

    monkeypatch.setattr(verify_cli, "verify", verify)
    for name in ("_print", "write_record"):
        if name == at:
            real = getattr(verify_cli, name)
            monkeypatch.setattr(verify_cli, name, lambda *a, r=real: (_kill_me(sig), r(*a))[1])
    if at == "rmtree":
        real = shutil.rmtree
        monkeypatch.setattr(
            verify_cli.shutil, "rmtree", lambda *a, **k: (_kill_me(sig), real(*a, **k))
        )
    return verify_cli.main(["--results", str(tmp_path), *options])


@pytest.mark.parametrize("sig", SIGNALS)
@pytest.mark.parametrize(
    "at,recorded", [("_print", False), ("write_record", True), ("rmtree", False)]
)
def test_verify_interrupted_after_its_comparisons_says_so(
    tmp_path, monkeypatch, capsys, sig, at, recorded
):
    rc = _verify(tmp_path, monkeypatch, sig, at)
    record = tmp_path / "reproducibility.parquet"
    how = "were recorded" if recorded else "were not recorded"
    # before: "sim verify: interrupted; the re-run was stopped", the record not written
    words = f"sim verify: interrupted after the comparisons; they {how} in {record}"
    assert (rc, capsys.readouterr().err.strip()) == (130, words)
    assert record.exists() == recorded
    if recorded:
        assert pq.read_table(record).column("study").to_pylist() == ["brown_table1"]
    assert list((tmp_path / "tmp").iterdir()) == []  # before: sim-verify-* left (at rmtree)


#: a batch's run that sends the driver SIGTERM as it publishes its results: the SIGTERM the
#: driver passes on comes while it publishes (held until its results are published), or after
#: (they are published, or the run has ended): in each case its results are written
_CHILD = """import os, runpy, sys
import sim.execute as ex
real = ex.publish
def publish(a, b):
    os.kill(os.getppid(), 15)
    return real(a, b)
ex.publish = publish
sys.argv = ["sim", *sys.argv[1:]]
runpy.run_module("sim", run_name="__main__", alter_sys=True)
"""


@pytest.mark.long
def test_a_batch_interrupted_while_a_run_publishes_names_its_results(tmp_path, monkeypatch, capsys):
    child, res = tmp_path / "child.py", tmp_path / "res"
    child.write_text(_CHILD)
    shutil.copy(TABLE1, tmp_path / "a.toml")
    pids = []

    class Popen(sim.batch.subprocess.Popen):  # the runs of the batch as _CHILD
        def __init__(self, cmd, *a, **k):
            super().__init__([cmd[0], str(child), *cmd[3:]], *a, **k)
            pids.append(self.pid)

    monkeypatch.setattr(sim.batch.subprocess, "Popen", Popen)
    monkeypatch.chdir(ROOT)
    rc = sim.batch.main([str(tmp_path / "a.toml"), "--results", str(res), "--", *RUN[2:]])
    err = capsys.readouterr().err.strip()
    # before: the line without the parenthesis, as if its run were unfinished
    assert (rc, err) == (130, f"{sim.batch.INTERRUPTED} (the results of a.toml were written)")
    assert sorted(p.name for p in res.iterdir()) == ["a"]  # complete, nothing beside
    assert (res / "a" / "claims.parquet").is_file() and (res / "a" / "run.json").is_file()
    assert len(pids) == 1 and not Path(f"/proc/{pids[0]}").exists()  # no child left


def _read_until(fd: int, seconds: float, needle: bytes | None = None) -> tuple[bytes, bool]:
    """What the pipe ``fd`` gives within ``seconds``: until ``needle`` is read, or until its end
    (every process that holds it has ended); and whether that came in time."""
    got, end = b"", time.monotonic() + seconds
    while (left := end - time.monotonic()) > 0 and select.select([fd], [], [], left)[0]:
        chunk = os.read(fd, 4096)
        got += chunk
        if not chunk or (needle is not None and needle in got):
            return got, True
    return got, False


@pytest.mark.skipif(shutil.which("make") is None, reason="no make on this machine")
def test_sigterm_to_make_verify_ends_verify_and_its_re_run(results, tmp_path):
    studies, res, tmp = tmp_path / "studies", tmp_path / "res", tmp_path / "tmp"
    studies.mkdir(), tmp.mkdir()
    shutil.copy(TABLE1, studies / "brown_table1.toml")  # 4000 trials: a re-run of seconds
    shutil.copytree(results, res)
    make = subprocess.Popen(
        ["make", "-s", "-o", ".venv/.installed", "verify"]
        + [f"VERIFY_FLAGS=--results {res} --studies {studies}"],
        cwd=ROOT,
        env={**os.environ, "TMPDIR": str(tmp)},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # (the test ends every process it started: its group)
    )
    try:
        fd = make.stderr.fileno()
        got, ok = _read_until(fd, 120, b"sim verify: re-running brown_table1\n")
        assert ok, got
        make.terminate()  # SIGTERM to make alone (`timeout 1h make verify`), which kills its shell
        assert make.wait(timeout=60) != 0
        rest, ended = _read_until(fd, 60)  # verify holds the pipe while it runs
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(make.pid, signal.SIGKILL)
        make.stderr.close()
    # before: verify ran on, orphaned, re-ran the study and wrote the record after make ended
    assert ended, rest
    assert verify_cli.INTERRUPTED in rest.decode().splitlines()
    assert not (res / "reproducibility.parquet").exists() and list(tmp.iterdir()) == []
