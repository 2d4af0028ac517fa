"""The local process pool never forks a process whose other threads may hold a lock.

A fork copies only the calling thread: a module import lock held by another thread at that
instant stays held in the child, and the child's first import of that module waits for ever
(the ``brown_design`` + ``--workers 2`` hang, figures drawn in threads). The pool starts its
workers when it is made, and with ``forkserver`` when other threads are running.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

from sim.mc import executors


def test_fork_only_when_single_threaded(monkeypatch):
    monkeypatch.setattr(
        executors.multiprocessing, "get_start_method", lambda allow_none=True: "fork"
    )
    monkeypatch.setattr(executors.threading, "active_count", lambda: 1)
    assert executors._start_method() == "fork"  # the only thread: a fork is safe
    monkeypatch.setattr(executors.threading, "active_count", lambda: 3)
    assert executors._start_method() in ("forkserver", "spawn")
    monkeypatch.setattr(
        executors.multiprocessing, "get_start_method", lambda allow_none=True: "spawn"
    )
    assert executors._start_method() is None  # the platform's own non-fork method is kept


def test_pool_made_while_a_thread_imports_does_not_hang(tmp_path):
    """A thread is inside a slow import when the pool is made; a worker then imports the same
    module. With a plain fork the worker would wait on the inherited lock for ever."""
    (tmp_path / "slowmod.py").write_text("import time\ntime.sleep(1.5)\nVALUE = 7\n")
    (tmp_path / "probe.py").write_text(
        "def load():\n    import slowmod\n    return slowmod.VALUE\n"
    )
    script = textwrap.dedent(
        f"""
        import sys, threading, time
        sys.path.insert(0, {str(tmp_path)!r})
        from sim.mc.executors import _Pool
        import probe
        t = threading.Thread(target=lambda: __import__("slowmod"))
        t.start()
        time.sleep(0.3)  # the thread now holds slowmod's import lock
        pool = _Pool(2)
        print(pool.start_method, pool.pool.submit(probe.load).result(timeout=60))
        t.join()
        pool.close()
        """
    )
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    method, value = r.stdout.split()
    assert value == "7"
    assert method in ("forkserver", "spawn")
