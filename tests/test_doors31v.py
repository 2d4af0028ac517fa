"""The classes of the sweep doors31v (brief V31: ``make verify``, ``python -m sim.batch``,
``make bench`` and ``sim report`` under filesystem faults, each step failing in turn by EIO,
ENOSPC or a kill, and run two at a time), one case each; each failed on the code before its
fix.

* The brown section's million-trial run (a child process writing its chunk store
  ``million_trials.tmp`` under ``--out``) that failed (a full disk, EIO) or was killed (the OOM
  killer, ``kill -9``) ended ``make bench`` in a ``CalledProcessError`` traceback, exit 1. It
  is now one line naming how the child ended and, when it said why, the file.
* That child killed while writing a chunk left the chunk's temporary
  (``.chunk-000002.parquet.<pid>.tmp``) in the store, which every later ``make bench`` into
  that ``--out`` refused as "not written by the benchmark" until it was removed by hand. The
  store's own temporaries are now the benchmark's.
* Two benchmarks into one ``--out`` at once both ran: each could remove the other's chunk
  store while it ran, or take its chunks as its own (the store resumes: timing less work),
  and they wrote their tables and figures over each other's, a page of one run beside the
  tables of the other. ``--out`` is now locked
  for the life of a benchmark (a ``flock`` on the directory, no file left in it): the second
  stops at once in one line naming the first's pid.
* SIGTERM (or SIGHUP) to ``make bench`` ended it at once, exit 143 without a word, and left
  its million-trial child running, writing into ``--out`` after the benchmark had ended (and
  its lock with it). It now ends as Ctrl-C does: its children stopped, one line, exit 130.
* The benchmark's page (``README.md``) was written in place: a write cut short (a full disk,
  ``ulimit -f``) left a torn page where the finished one had been (and one cut within its
  first line made every later ``make bench`` into that ``--out`` refuse it as not the
  benchmark's). It is now written beside and renamed into place.
* ``make verify`` whose temporary scratch directory could not be removed at the end (an I/O
  error on one of the re-runs' files) ended in exit 2 with "Input/output error:
  claims.parquet" (a bare file name), its finished comparisons neither printed nor recorded
  in ``reproducibility.parquet``. The check now stands: the comparisons are printed and
  recorded and one note names the directory left behind.
* A re-run of ``make verify`` ended by a signal of its own (the OOM killer, ``kill -9`` of
  the re-run alone) was recorded as a failed reproduction: exit 1, and
  ``reproducibility.parquet`` replaced by a record whose study read "no: the re-run was killed
  by SIGKILL" (the report then showed results that had reproduced as not reproducing). It is
  now one line naming the signal, exit 2, and the earlier record is kept.
* A re-run into ``--scratch`` that could not remove its lock file at its very end (an I/O
  error: the run published, exit 0, the lock file left, as doors29e decided) left
  ``DIR/<study>/.lock``, which every later ``make verify`` with that ``--scratch`` refused as
  "holds '.lock', which the suite did not write" until it was removed by hand. The suite's
  lock file is now the suite's.
* A re-run whose ``--out`` under ``--scratch`` could not be made (a full disk: "sim: error:
  --out: cannot write to DIR: No space left on device") was called "the re-run refused its
  options"; it is now "the re-run could not run here", as the other errors of the system.
"""

from __future__ import annotations

import errno
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from benchmarks import brown, cli
from benchmarks.page import write_page
from sim.cli import main as sim_main
from sim.report.verify import child as verify_child
from sim.report.verify import main as verify_main
from sim.report.verify import rerun as verify_rerun
from tests.oneline import one_line

TINY = ["--set", "trials=40", "--set", "chunk=2", "--set", "region.points=256"]
TINY += ["--set", "region.rounds=0"]


def test_a_failing_million_trial_child_is_one_line(tmp_path):
    (tmp_path / "million_trials.tmp").write_text("")  # its store cannot be made: ENOTDIR
    with pytest.raises(RuntimeError) as e:  # before: CalledProcessError, a traceback
        brown.peak_memory(tmp_path, 2000, 1000)
    msg = str(e.value)
    assert "\n" not in msg and "child process) exited with 2: Not a directory" in msg, msg
    assert "million_trials.tmp" in msg


@pytest.mark.long
def test_a_store_left_by_a_killed_child_does_not_block_the_next_benchmark(tmp_path, capsys):
    part = tmp_path / "million_trials.tmp" / "part-0"
    part.mkdir(parents=True)
    (part / "chunk-000000.parquet").write_bytes(b"")
    (part / ".chunk-000001.parquet.4242.tmp").write_bytes(b"")  # its chunk being written
    # before: "--out: .../million_trials.tmp was not written by the benchmark", every time
    assert cli.main(["--quick", "--only", "store", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "store.parquet").is_file()


HOLD = """
import fcntl, os, sys
fd = os.open(sys.argv[1], os.O_RDONLY | os.O_DIRECTORY)
fcntl.flock(fd, fcntl.LOCK_EX)  # as a benchmark writing into it holds it
print("held", flush=True)
sys.stdin.read()  # until the test closes the pipe
"""


def test_a_second_benchmark_into_the_same_out_is_refused_naming_the_first(tmp_path, capsys):
    out = tmp_path / "bench"
    out.mkdir()
    with subprocess.Popen(
        [sys.executable, "-c", HOLD, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    ) as first:
        try:
            assert first.stdout.readline() == "held\n"
            rc = cli.main(["--quick", "--only", "store", "--out", str(out)])  # before: exit 0
            one_line(capsys, rc, str(out), "another benchmark", f"(pid {first.pid})")
            assert not (out / "store.parquet").exists()
        finally:
            first.stdin.close()
    assert cli.main(["--quick", "--only", "store", "--out", str(out)]) == 0  # the lock is gone
    assert sorted(p.name for p in out.iterdir()) == ["store.parquet"]  # no lock file left


STOPPED = """
import sys
from benchmarks import brown, cli
from benchmarks.page import write_page
def rows(out, quick):  # the brown section's streamed run at once, long enough to be stopped
    print("started", flush=True)
    brown.peak_memory(out, 10**7, 10000)
cli.brown_rows = rows
sys.exit(cli.main(["--only", "brown", "--out", sys.argv[1]]))
"""


def _running_with(word: str) -> list[str]:
    """The pids of live processes whose command line holds ``word``."""
    pids = []
    for p in Path("/proc").iterdir():
        try:
            if p.name.isdigit() and word.encode() in (p / "cmdline").read_bytes():
                pids.append(p.name)
        except OSError:
            continue
    return pids


def test_sigterm_to_a_benchmark_stops_its_child_and_is_one_line(tmp_path):
    out = tmp_path / "bench"
    with subprocess.Popen(
        [sys.executable, "-c", STOPPED, str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    ) as bench:
        assert bench.stdout.readline() == "started\n"
        deadline = time.monotonic() + 60
        while not (out / "million_trials.tmp").exists():  # the child is writing its store
            assert time.monotonic() < deadline and bench.poll() is None
            time.sleep(0.02)
        bench.send_signal(signal.SIGTERM)
        _, err = bench.communicate(timeout=60)
    left = _running_with(f"--out={out}")
    for pid in left:  # (before the fix: the orphan)
        os.kill(int(pid), signal.SIGKILL)
    assert bench.returncode == 130 and err == "benchmarks: interrupted; nothing more was measured\n"
    assert not left  # before: exit -15 (143), no line, the child writing on


def _committed(tmp_path, capsys):
    """``results/brown_table1`` of a tiny study file ``studies/brown_table1.toml`` (its
    verify re-runs in a second or two)."""
    studies, results = tmp_path / "studies", tmp_path / "results"
    studies.mkdir()
    assert sim_main(["check", "studies/brown_table1.toml", *TINY]) == 0
    (studies / "brown_table1.toml").write_text(capsys.readouterr().out)
    argv = ["run", str(studies / "brown_table1.toml"), "--quiet", "--no-figures"]
    assert sim_main([*argv, "--out", str(results / "brown_table1")]) == 0
    return studies, results


@pytest.mark.long
def test_a_scratch_directory_that_cannot_be_removed_leaves_the_check_standing(
    tmp_path, monkeypatch, capsys
):
    studies, results = _committed(tmp_path, capsys)
    real, seen = os.unlink, []

    def eio(path, *a, dir_fd=None, **k):  # the re-run's claims table, as rmtree removes it
        if dir_fd is not None and str(path) == "claims.parquet" and not seen:
            seen.append(path)
            raise OSError(errno.EIO, "Input/output error", str(path))
        return real(path, *a, dir_fd=dir_fd, **k)

    monkeypatch.setattr(os, "unlink", eio)
    rc = verify_main(["--results", str(results), "--studies", str(studies)])
    monkeypatch.undo()
    out, err = capsys.readouterr()
    assert rc == 0 and "brown_table1: ok" in out, (rc, out, err)  # before: exit 2, nothing
    assert (results / "reproducibility.parquet").is_file()
    note = [ln for ln in err.splitlines() if "could not be removed" in ln]
    assert len(note) == 1 and "Input/output error" in note[0], err
    left = note[0].split("scratch directory ")[1].split(" could not")[0]
    assert os.path.isdir(left) and os.path.basename(left).startswith("sim-verify-")
    shutil.rmtree(left)


@pytest.mark.long
def test_a_re_run_killed_by_a_signal_is_not_recorded_as_a_failed_reproduction(
    tmp_path, monkeypatch, capsys
):
    studies, results = _committed(tmp_path, capsys)
    argv = ["--results", str(results), "--studies", str(studies)]
    assert verify_main(argv) == 0
    record = (results / "reproducibility.parquet").read_bytes()
    capsys.readouterr()
    real = verify_rerun.subprocess.Popen

    def killed(cmd, *a, **k):  # the study's re-run, ended by the OOM killer
        code = "import os, signal; os.kill(os.getpid(), signal.SIGKILL)"
        return real([sys.executable, "-c", code], *a, **k)

    monkeypatch.setattr(verify_rerun.subprocess, "Popen", killed)
    rc = verify_main(argv)  # before: exit 1, "brown_table1: FAILED", and recorded so
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if not ln.startswith("sim verify: re-running")]
    assert rc == 2 and len(lines) == 1 and "Traceback" not in err, (rc, err)
    assert lines[0].startswith("sim verify: error: brown_table1: the re-run was killed by SIGKILL")
    assert (results / "reproducibility.parquet").read_bytes() == record


@pytest.mark.long
def test_a_lock_file_left_in_an_earlier_re_run_does_not_block_the_next_verify(tmp_path, capsys):
    studies, results = _committed(tmp_path, capsys)
    argv = ["--results", str(results), "--studies", str(studies), "--no-record"]
    argv += ["--scratch", str(tmp_path / "scratch")]
    assert verify_main(argv) == 0
    (tmp_path / "scratch" / "brown_table1" / ".lock").write_text("4242\n")  # (EIO at unlink)
    capsys.readouterr()
    assert verify_main(argv) == 0  # before: "holds '.lock', which the suite did not write"
    assert "brown_table1: ok" in capsys.readouterr().out


def test_a_scratch_that_cannot_be_written_is_the_machines_not_the_options():
    line = "sim: error: --out: cannot write to /s/brown_table1: No space left on device"
    assert verify_child.system_error(line)  # before: "the re-run refused its options"
    assert not verify_child.system_error("sim: error: --out: must not be empty")


TORN = """
import resource, signal, sys
from pathlib import Path
from benchmarks.page import write_page
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write over the limit fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (256, resource.RLIM_INFINITY))
try:
    write_page(Path(sys.argv[1]), None, None, True)
except OSError as e:
    print("failed", e.errno)
"""


def test_a_page_cut_short_leaves_the_finished_one(tmp_path):
    page = tmp_path / "README.md"
    write_page(page, None, None, False)
    before = page.read_bytes()
    assert len(before) > 256
    r = subprocess.run([sys.executable, "-c", TORN, str(page)], capture_output=True, text=True)
    assert r.stdout == f"failed {errno.EFBIG}\n", (r.stdout, r.stderr)
    assert page.read_bytes() == before  # before: its first 256 bytes
    assert sorted(p.name for p in tmp_path.iterdir()) == ["README.md"]
