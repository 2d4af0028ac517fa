"""A Dask cluster's worker processes spared the terminal's stop signals (not in
:mod:`sim.mc.executors`, which every study's code hash holds: this is the command's, not a
study's).

Ctrl-C and a closed terminal (SIGHUP) reach every process of the terminal's process group: the
run's own, and the worker processes of its Dask ``LocalCluster`` and multiprocessing's resource
tracker, which it starts. The run handles them (one line, exit 130, its cluster ended); the
others did not: each Dask worker printed a 30-line ``KeyboardInterrupt`` traceback from its
event loop after Ctrl-C, and SIGHUP killed the resource tracker, whose replacement printed a
``KeyError`` traceback for each semaphore the run released (a dozen). The local process pool's
workers ignore them already (:mod:`sim.mc.executors`).

So the executor is started by a thread of its own in which SIGINT and SIGHUP are blocked: the
threads the cluster starts (its event loop's, and through it each worker's launcher) inherit
that mask, and a process inherits it across ``exec``, so every worker (a restarted one too) and
the resource tracker, started there first, never receive them. The run's own thread keeps its
mask and waits: an interrupt while the cluster starts kills the worker processes the start
has begun, which ends the start at once (a nanny whose worker died fails), and then ends what
started (blocked in the run's thread instead, it waited for Dask's next ten-second check; ended
while it starts, from another thread, Dask's start hung; waited for, it took 2 to 17 s).
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import suppress
from typing import Any, Callable

__all__ = ["SPARED", "start_sparing_workers"]

#: the signals a terminal sends its whole process group (Ctrl-C, a hangup), which the run's
#: process handles and its Dask workers are spared
SPARED = frozenset({signal.SIGINT, getattr(signal, "SIGHUP", signal.SIGINT)})

#: how long an interrupted start is waited for before whatever started is ended (s): a
#: LocalCluster of two workers starts in 2 to 10 s on the loaded reference machine
_WAIT_INTERRUPTED = 30.0


def _tracker_started() -> None:
    """Start multiprocessing's resource tracker now, under the block: started later by a
    cluster's thread, it would unblock SIGINT in that thread (as ``ensure_running`` does after
    starting it), and the workers started from there would receive Ctrl-C again. One already
    running (an earlier run of the Python API in this process) is left as it is."""
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    signal.pthread_sigmask(signal.SIG_BLOCK, SPARED)


def _children() -> set[int]:
    """The pids of this process's child processes (psutil: a dependency of Dask's)."""
    import psutil

    with suppress(psutil.Error):
        return {p.pid for p in psutil.Process().children()}
    return set()


def _kill_new_children(before: set[int]) -> None:
    """Kill this process's children that were not there ``before`` (the worker processes of
    the cluster that starts), but for multiprocessing's resource tracker (it ends with us, and
    killed, the semaphores the run releases get its replacement's tracebacks). Children of
    the caller's own (the Python API) are left as they are."""
    import psutil

    with suppress(psutil.Error):
        for p in psutil.Process().children():
            if p.pid not in before:
                with suppress(psutil.Error):
                    if "resource_tracker" not in " ".join(p.cmdline()):
                        p.kill()


def start_sparing_workers(kind: str, make: Callable[[], Any], end: Callable[[Any], None]):
    """``make()`` (an executor of ``kind``); for ``dask`` called by a thread in which
    :data:`SPARED` are blocked (see the module). An interrupt of this thread while it waits is
    raised after ``end(executor)`` once the start has ended (``end(None)`` when it failed, or
    did not end within :data:`_WAIT_INTERRUPTED`: whatever started is ended)."""
    if kind != "dask" or not hasattr(signal, "pthread_sigmask"):
        return make()
    got: dict[str, Any] = {}
    done = threading.Event()  # not Thread.join: interrupted, it took the thread for ended

    def starting() -> None:
        try:
            signal.pthread_sigmask(signal.SIG_BLOCK, SPARED)  # this thread's, and its threads'
            _tracker_started()
            got["executor"] = make()
        except BaseException as e:  # raised in the caller's thread
            got["error"] = e
        finally:
            done.set()

    before = _children()
    threading.Thread(target=starting, name="sim: starting the dask executor", daemon=True).start()
    try:
        while not done.wait(0.05):
            pass
    except BaseException:  # an interrupt while it starts: its workers are killed, which ends
        started = False  # the start (ended by a close, from here, Dask's start hung), then it
        try:  # is ended; at once by a second interrupt
            deadline = time.monotonic() + _WAIT_INTERRUPTED
            while not (started := done.wait(0.1)) and time.monotonic() < deadline:
                _kill_new_children(before)
        finally:
            end(got.get("executor") if started else None)
        raise
    if "error" in got:
        raise got["error"]
    return got["executor"]
