"""The classes of the sweep doors48s (brief S48: Ctrl-C while a Dask cluster starts, and the
leaked-semaphore warning), one case each; each failed on the code before its fix.

* Ctrl-C while ``sim run --executor dask`` started its LocalCluster waited for the start to
  finish (2 to 17 s on a loaded machine, up to 30 s) before the run ended: the start, in a
  thread of its own (:mod:`sim.spared_workers`), could not be ended from the run's thread
  (closed from there, Dask's start hung). Now the run kills the worker processes the start
  has begun (its own new children, not the resource tracker nor a caller's), which ends the
  start at once: one line, exit 130, in about a second (8.7 s before, measured with two
  workers).
* A run whose local pool starts by ``forkserver`` (``run(workers=2)`` from a script with a
  thread of its own; ``brown_design``'s figures) killed by a signal it does not handle
  (SIGUSR1, SIGALRM, SIGKILL, the OOM killer) left its two workers and the fork server
  running for ever (and the resource tracker waiting on them): each worker held the server's
  "alive" pipe, so the server never saw the run end, and the workers watched the server.
  Each worker now closes its copy (:func:`sim.mc.executors._worker_init`): all end with it.
"""

from __future__ import annotations

import _thread
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from sim import spared_workers


def test_ctrl_c_while_a_dask_cluster_starts_kills_its_workers_not_waits(monkeypatch):
    """Ctrl-C while the executor starts (a start that ends only when its worker process
    ends, as Dask's does when a worker dies): before, the run's thread waited for the start
    (here all of ``_WAIT_INTERRUPTED``) and the worker was left running; now the start's new
    child is killed, the start ends, and the interrupt is raised after ``end``."""
    pytest.importorskip("psutil")
    monkeypatch.setattr(spared_workers, "_WAIT_INTERRUPTED", 5.0)
    mine = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])  # a caller's
    started = threading.Event()
    seen: dict[str, object] = {}

    def make():
        worker = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
        seen["worker"] = worker
        started.set()
        seen["code"] = worker.wait(timeout=30)  # a worker that died: the start fails
        raise RuntimeError("Nanny failed to start")

    def interrupt():
        started.wait(30)
        _thread.interrupt_main()  # Ctrl-C, delivered to the run's (main) thread

    ended = []
    threading.Thread(target=interrupt, daemon=True).start()
    try:
        with pytest.raises(KeyboardInterrupt):
            spared_workers.start_sparing_workers("dask", make, ended.append)
        assert ended == [None]
        assert seen.get("code") == -9, "the starting worker was not killed"  # before: None
        assert mine.poll() is None, "a child the caller had before the start was killed"
    finally:
        for p in (mine, seen.get("worker")):
            if p is not None and p.poll() is None:
                p.kill()
                p.wait()


#: a run's process with a thread of its own (so its pool starts by forkserver): prints its
#: workers' and the fork server's pids, then dies by SIGUSR1 (no handler: the default)
_KILLED_RUN = """
import os, signal, sys, threading
from multiprocessing import forkserver
from sim.mc.executors import make_executor
if __name__ == "__main__":
    threading.Thread(target=threading.Event().wait, daemon=True).start()
    pool = make_executor("local", 2)
    assert pool.start_method == "forkserver", pool.start_method
    print(*pool.pool._processes, forkserver._forkserver._forkserver_pid, flush=True)
    os.kill(os.getpid(), signal.SIGUSR1)
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_forkserver_workers_end_with_a_run_killed_by_a_signal(tmp_path):
    """A signal without a handler (SIGUSR1) to a run whose pool started by forkserver: before,
    its workers and the fork server each waited for the other, for ever; now all end."""
    script = tmp_path / "killed_run.py"
    script.write_text(_KILLED_RUN)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parent.parent)}
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    with out.open("w") as o, err.open("w") as e:  # files: the workers left held a pipe open
        code = subprocess.run([sys.executable, str(script)], env=env, stdout=o, stderr=e).returncode
    assert code == -signal.SIGUSR1, err.read_text()
    pids = [int(w) for w in out.read_text().split()]
    assert len(pids) == 3, out.read_text()
    try:
        deadline = time.monotonic() + 30  # they end within a second (a worker's watch)
        while (left := [p for p in pids if _alive(p)]) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert left == [], "the workers and the fork server were left running"  # before: all
    finally:
        for p in pids:
            if _alive(p):
                os.kill(p, signal.SIGKILL)
