"""The classes of the sweep doors48s (brief S48: Ctrl-C while a Dask cluster starts, and the
leaked-semaphore warning), one case each; each failed on the code before its fix.

* Ctrl-C while ``sim run --executor dask`` started its LocalCluster waited for the start to
  finish (2 to 17 s on a loaded machine, up to 30 s) before the run ended: the start, in a
  thread of its own (:mod:`sim.spared_workers`), could not be ended from the run's thread
  (closed from there, Dask's start hung). Now the run kills the worker processes the start
  has begun (its own new children, not the resource tracker nor a caller's), which ends the
  start at once: one line, exit 130, in about a second (8.7 s before, measured with two
  workers).
"""

from __future__ import annotations

import _thread
import subprocess
import sys
import threading

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
