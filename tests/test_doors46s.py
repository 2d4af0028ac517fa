"""The classes of the sweep doors46s (brief S46: output streams and resource limits, signals
not tried before), one case each; each failed on the code before its fix.

* Ctrl-C or a closed terminal (SIGINT or SIGHUP to the terminal's whole process group) during
  a ``--executor dask`` run reached the run's Dask worker processes and multiprocessing's
  resource tracker as well as the run: each worker printed a 30-line ``KeyboardInterrupt``
  traceback of its event loop, and SIGHUP killed the tracker, whose replacement printed a
  ``KeyError`` traceback for each semaphore the run released (twelve), besides the run's own
  ``sim: interrupted`` line. The executor is started by a thread with both signals blocked,
  which its workers and the tracker inherit (:mod:`sim.spared_workers`): one line, exit 130.

Held (found right): ``>&-``, ``2>&-``, ``> /dev/full``, ``| head -1`` of every command's
``--help`` and ``--version``, of ``sim check``, ``python -m benchmarks``; ``COLUMNS`` of 0, -5,
``abc`` or 1e20 and ``TERM`` unset; SIGUSR1, SIGUSR2, SIGQUIT, SIGALRM, SIGVTALRM and SIGPROF to
``sim run --workers 2`` and to ``python -m sim.batch`` (death by the signal as its default, no
process left, the same command resumes to the tables of a clean run); SIGHUP and two quick
SIGINTs to the group of ``sim run --workers 2`` and of ``python -m sim.batch``.
"""

from __future__ import annotations

import contextlib
import glob
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PLATE = ROOT / "studies" / "network_plate.toml"


def _session(sid: int) -> list[str]:
    """The live processes of session ``sid`` (each its pid and command line)."""
    psutil = pytest.importorskip("psutil")
    left = []
    for p in psutil.process_iter(["pid", "cmdline", "status"]):
        with contextlib.suppress(psutil.Error, OSError):
            if os.getsid(p.pid) == sid and p.info["status"] != psutil.STATUS_ZOMBIE:
                left.append(f"{p.pid} {' '.join(p.info['cmdline'] or [])}")
    return left


@pytest.mark.long
def test_ctrl_c_and_a_hangup_to_a_dask_runs_group_end_it_in_one_line(tmp_path):
    pytest.importorskip("distributed")
    out = tmp_path / "out"
    run = subprocess.Popen(
        [sys.executable, "-m", "sim", "run", str(PLATE), "--out", str(out), "--no-figures"]
        + ["--trials", "20000", "--chunk", "200", "--executor", "dask", "--workers", "1"],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own group, as a terminal's job: Ctrl-C reaches all of it
    )
    try:
        chunks = str(tmp_path / ".out.partial" / "trials" / "part-0" / "chunk-*.parquet")
        deadline = time.monotonic() + 180
        while not glob.glob(chunks) and run.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)  # the first chunk written: the cluster's worker is running
        assert run.poll() is None and glob.glob(chunks), "the run ended before its first chunk"
        os.killpg(run.pid, signal.SIGHUP)  # the terminal closed: the tracker too
        os.killpg(run.pid, signal.SIGINT)  # Ctrl-C: every worker
        err = run.communicate(timeout=120)[1].decode()
        deadline = time.monotonic() + 20
        while (left := _session(run.pid)) and time.monotonic() < deadline:
            time.sleep(0.1)  # the tracker ends when the run's process has ended
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(run.pid, signal.SIGKILL)
        run.stderr.close()
    # before: the run's line after a worker's KeyboardInterrupt and the tracker's KeyErrors
    assert run.returncode == 130 and err.splitlines() == [
        "sim: interrupted; run the same command again to finish the missing chunks"
    ], err
    assert left == []
