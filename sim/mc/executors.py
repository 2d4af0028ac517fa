"""Where the chunks of a run are computed (:func:`make_executor`): in this process, a local
process pool whose workers die with the parent, or a ``dask.distributed`` client. Each runs
:func:`sim.mc.streams.call_chunk`, so the output is bit-for-bit the same on all of them."""

from __future__ import annotations

import logging
import multiprocessing
import os
import resource
import signal
import sys
import threading
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import suppress

from sim.mc.streams import call_chunk as _call_chunk

__all__ = ["make_executor", "InProcess", "end_dask_clusters", "script_words", "StartRefused"]


class InProcess:
    """Runs chunks one after another in this process."""

    def run(self, fn, seed, part, jobs):
        for k, n in jobs:
            yield k, n, _call_chunk(fn, seed, part, k, n)

    def close(self, kill: bool = False):
        pass


def _watch_parent(ppid: int) -> None:
    import time

    while True:
        if os.getppid() != ppid:
            os._exit(1)
        time.sleep(0.5)


def _worker_init(ppid: int | None) -> None:
    """In each pool worker: ignore SIGINT (the parent handles Ctrl-C and stops the pool) and
    die with the parent, even after ``kill -9`` (PR_SET_PDEATHSIG on Linux; a thread that
    watches the parent everywhere). ``ppid`` None: the worker's parent is a fork server,
    which ends when the run's process does once the worker lets go of the server's "alive"
    pipe, which every process it starts is given: held, the server and the workers each
    waited for the other for ever after the run was killed (SIGKILL, SIGUSR1)."""
    if ppid is None:
        ppid = os.getppid()
        _release_fork_server()
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOPS)  # held by the forking parent (_Pool)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass
    if os.getppid() != ppid:  # the parent died before we got here
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(ppid,), daemon=True).start()


def _release_fork_server() -> None:
    """In a worker started by multiprocessing's fork server: close its copy of the server's
    "alive" pipe (private to multiprocessing; left as it is where it differs), so the server
    ends when the run's process does (a worker starts no process of its own)."""
    from multiprocessing import forkserver

    server = getattr(forkserver, "_forkserver", None)
    fd = getattr(server, "_forkserver_alive_fd", None)
    if isinstance(fd, int):
        with suppress(OSError):
            os.close(fd)
        server._forkserver_alive_fd = None


def process_start_method() -> str:
    """The process's start method: the caller's (``set_start_method``) or the platform's
    default, read without fixing it. ``multiprocessing.get_start_method()`` (and a pool or lock
    made on the default context) fixes the default for the life of the process: after any run
    of the Python API, the caller's own ``multiprocessing.set_start_method("spawn")`` failed
    with "context has already been set"."""
    return (
        multiprocessing.get_start_method(allow_none=True)
        or (
            multiprocessing.get_all_start_methods()[0]  # the first is the default (documented)
        )
    )


def _start_method() -> str | None:
    """How to start the pool's workers: the platform's default, except that a process with
    other threads running is never forked. A fork copies only the calling thread, so a lock
    another thread holds at that instant (a module's import lock while a figure thread imports
    matplotlib, an I/O lock) stays held for ever in the child, and the worker hangs on its
    first import (seen with ``brown_design``, ``--workers 2`` and its figures drawn in threads). Then
    ``forkserver`` starts the workers from a clean single-threaded server instead."""
    methods = multiprocessing.get_all_start_methods()
    if process_start_method() != "fork":
        return None  # spawn (macOS, Windows) or a method the user chose: no fork hazard
    if threading.active_count() == 1:
        return "fork"
    return "forkserver" if "forkserver" in methods else "spawn"


#: the signals that stop a run, held while a pool forks its workers (see :class:`_Pool`)
_STOPS = {signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", signal.SIGTERM)}


def _ready() -> int:
    return os.getpid()


def _may_start_processes(what: str) -> None:
    """Refuse (one line) to start worker processes from a daemonic process (a worker of the
    caller's ``multiprocessing.Pool``), which multiprocessing forbids: ``run(workers=2)`` there
    ended in its bare "AssertionError: daemonic processes are not allowed to have children"."""
    if multiprocessing.current_process().daemon:
        raise RuntimeError(
            f"{what} from a daemonic process (a worker of a multiprocessing Pool), which may "
            "start no processes: use 1 worker here (the results are the same)"
        )


class _Pool:
    """A local process pool (``concurrent.futures``); its workers die with the parent. They
    are all started here, while the caller is the only thread that needs to exist (see
    :func:`_start_method`), not later at the first chunk, when a run may have threads of its
    own (the parts of ``brown_design``, figures drawn in this process)."""

    def __init__(self, workers: int):
        _may_start_processes(f"{workers} worker processes")
        method = _start_method()
        # the method the workers start by: ours, or the caller's (``set_start_method``; the
        # default of Python 3.14 on Linux) -- a forkserver's workers are its children, not
        # ours: given our pid they took their parent for dead and quit ("terminated abruptly")
        self.start_method = method or process_start_method()
        self.pool = ProcessPoolExecutor(  # a named context: the caller's default stays unset
            max_workers=workers,
            mp_context=multiprocessing.get_context(self.start_method),
            initializer=_worker_init,
            initargs=(None if self.start_method == "forkserver" else os.getpid(),),
        )
        # Ctrl-C or SIGTERM in the at-fork hooks of a fork (logging's lock release) is
        # "Exception ignored" by Python: the run went on to exit 0 (doors15a). Held over the
        # forks, a stop signal is delivered here after them; the workers unblock it first thing
        held = self.start_method == "fork"
        old = signal.pthread_sigmask(signal.SIG_BLOCK, _STOPS) if held else None
        try:
            try:
                ready = [self.pool.submit(_ready) for _ in range(workers)]
            finally:
                if held:
                    signal.pthread_sigmask(signal.SIG_SETMASK, old)
            for f in ready:
                f.result()  # every worker forked now (a fork pool starts them all at once)
        except BaseException:  # a worker that could not start (ulimit -n: no pipe): the one
            self.close(kill=True)  # started waited for work forever, and Python's exit on it
            raise

    def run(self, fn, seed, part, jobs):
        futs = {self.pool.submit(_call_chunk, fn, seed, part, k, n): (k, n) for k, n in jobs}
        for f in as_completed(futs):
            k, n = futs[f]
            yield k, n, f.result()

    def close(self, kill: bool = False):
        """Stop the pool; ``kill``: terminate running workers at once (interrupt, failure)."""
        if kill:
            procs = list((getattr(self.pool, "_processes", None) or {}).values())
            for p in procs:
                try:
                    p.kill()
                except (OSError, AttributeError):
                    pass
            for p in procs:
                p.join(5)
        self.pool.shutdown(wait=True, cancel_futures=True)


class _Dask:
    """A ``dask.distributed`` client: a given scheduler, or a LocalCluster for the run."""

    def __init__(self, workers: int, scheduler: str | None):
        try:
            from dask.distributed import Client, LocalCluster
            from dask.distributed import as_completed as dask_completed
        except ImportError:
            raise RuntimeError(
                "the dask executor needs dask[distributed]: pip install -e '.[dask]'"
            ) from None
        self._completed = dask_completed
        self.cluster = None
        _rss_limit_not_taken(1 if scheduler else workers)  # the client's messages too
        if scheduler:
            self.client = Client(scheduler, timeout="10s")
        else:
            _may_start_processes("a LocalCluster")
            _enough_files(workers)
            try:
                self.cluster = LocalCluster(
                    n_workers=max(workers, 1),
                    threads_per_worker=1,
                    processes=True,
                    # ":0": a free port, never the "Port 8787 is already in use" warning (None
                    # still means the default 8787); the nanny's closing chatter is not for users
                    dashboard_address=":0",
                    silence_logs=logging.ERROR,
                )
                self.client = Client(self.cluster)
            except BaseException:  # a signal while the cluster starts: end what has started
                end_dask_clusters()
                raise

    def run(self, fn, seed, part, jobs):
        """The chunks ``jobs`` of ``fn``, sent to the workers once (scattered), not with each
        task: a network's chunk function holds the network and its factor (37 MiB pickled at
        10,000 points), and sent with each of 20 tasks it grew the run's process by 0.75 GiB
        over the estimate (client and scheduler each held every copy) and printed Dask's
        six-line "Sending large graph" warning."""
        jobs = list(jobs)
        if not jobs:
            return
        fn_f = self.client.scatter(fn, broadcast=True, hash=False)
        futs = {}
        for k, n in jobs:
            futs[self.client.submit(_call_chunk, fn_f, seed, part, k, n, pure=False)] = (k, n)
        for f in self._completed(list(futs)):
            k, n = futs[f]
            yield k, n, f.result()

    def close(self, kill: bool = False):
        if not kill:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()
            return
        with suppress(Exception):  # interrupted: whatever state the workers are in
            self.client.close(timeout=5)
        if self.cluster is not None:
            end_dask_clusters()


#: open files a LocalCluster needs per worker (pipes, sockets, its nanny): measured with
#: ``ulimit -n``, 2 workers hang past 100 s at 40 files, fail with tracebacks at 32 and run at 64
DASK_FILES_PER_WORKER = 32


class StartRefused(RuntimeError):
    """The executor was refused before any worker process started (a limit it cannot start
    under): no script was imported again, so :func:`script_words` does not apply."""


def _enough_files(workers: int) -> None:
    """Refuse (one line) to start a LocalCluster under a limit of open files it cannot start
    in: it would not fail but retry for minutes, printing tracebacks of its monitors."""
    need = DASK_FILES_PER_WORKER * max(workers, 2)
    soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    if soft != resource.RLIM_INFINITY and soft < need:
        n = max(workers, 1)
        raise StartRefused(
            f"a LocalCluster of {n} worker{'s' if n > 1 else ''} needs at least {need} open "
            f"files, and ulimit -n is {soft} (raise it, or use --executor local)"
        )


#: the least share of a hard ``ulimit -m`` a Dask worker runs under (bytes): a worker process
#: holds about 150 MB before its first task, and is paused at 80 % of its share (two workers
#: under 400 MB hung; under 1,000,000 kB each of two ran as without the limit)
DASK_WORKER_RSS = 400 * 2**20


def _rss_limit_not_taken(workers: int = 1) -> None:
    """Refuse (one line) to start Dask under a hard ``ulimit -m`` that Dask would take for the
    machine's memory (:func:`distributed.system.memory_limit`) and that leaves each of its
    ``workers`` less than :data:`DASK_WORKER_RSS`: Linux does not enforce it, but Dask sizes
    its workers (paused at 80 %) and its messages (half of it) from it, so a run under it hung
    (400 MB), ended in "CommClosedError ... Stream is closed" (100 MB) or in a 63-line tornado
    traceback (under 256 kB: "cannot convert 'float' object to bytearray"). A larger limit
    runs (R44: ``ulimit -m 20000000``, 19 GiB on a machine of 24, was refused)."""
    hard = resource.getrlimit(resource.RLIMIT_RSS)[1]
    if hard == resource.RLIM_INFINITY or hard <= 0 or hard >= DASK_WORKER_RSS * max(workers, 1):
        return
    from distributed.system import memory_limit  # heavy optional dependency (dask extra)

    if memory_limit() >= hard:  # the limit is what Dask takes for the memory (or less)
        each = f" ({hard / max(workers, 1) / 2**20:.0f} MiB each of {workers} workers)"
        raise StartRefused(
            f"Dask takes ulimit -m ({hard // 1024} kB) for this machine's memory, which Linux "
            f"does not enforce, and its workers stall or fail under it{each * (workers > 1)}, "
            f"under the {DASK_WORKER_RSS // 2**20} MiB a worker needs (start the run from a "
            "shell without ulimit -m or with a larger one, or use --executor local)"
        )


def end_dask_clusters() -> None:
    """End this process's dask clusters after an interrupt, quietly and for good: each is
    closed once (a worker still starting makes dask's close raise), kept from dask's second
    close at exit (which would print its traceback), and its worker processes are killed."""
    import psutil  # installed with the dask extra (a dependency of distributed)
    from distributed.deploy.spec import SpecCluster  # heavy optional dependency (dask extra)

    for name in ("asyncio", "distributed", "tornado"):  # their chatter about the interrupted
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)  # start-up is not for users
    for c in list(SpecCluster._instances):
        c.shutdown_on_close = False
        with suppress(Exception):
            c.close(timeout=5)
    with suppress(Exception):  # nannies and their workers (grandchildren) alike
        for proc in psutil.Process().children(recursive=True):
            with suppress(Exception):
                if "resource_tracker" not in " ".join(proc.cmdline()):  # ends with us
                    proc.kill()
    for proc in multiprocessing.active_children():  # reaped, no zombies
        with suppress(Exception):
            proc.join(1)


def _suite_entry(main) -> bool:
    """Whether the process's ``__main__`` is the suite's own command (``python -m sim``, the
    ``sim`` script), whose code is guarded: no script of the caller's is imported again."""
    spec = getattr(main, "__spec__", None)
    if spec is not None and (spec.name == "sim" or spec.name.startswith("sim.")):
        return True
    return getattr(getattr(main, "main", None), "__module__", None) == "sim.__main__"


def script_words(kind: str, workers: int, scheduler: str | None) -> str:
    """Why starting the executor may have failed when the caller is a script (the Python API):
    workers started by ``spawn`` or ``forkserver`` (Dask's LocalCluster; a local pool in a
    process with threads, or under the caller's start method) import the caller's script
    again, and a script without ``if __name__ == "__main__":`` starts its run again there,
    which multiprocessing refuses ("terminated abruptly", Dask's "Nanny failed to start"
    with no cause). "" when that cannot be the cause."""
    main = sys.modules.get("__main__")
    script = getattr(main, "__file__", None)
    if not script or scheduler or (kind == "local" and workers <= 1) or _suite_entry(main):
        return ""
    if kind == "local" and (_start_method() or process_start_method()) == "fork":
        return ""
    return (
        f" (its worker processes import {os.path.basename(script)} again: is the script's "
        'code under if __name__ == "__main__":?)'
    )


def make_executor(kind: str = "local", workers: int = 1, scheduler: str | None = None):
    """``local`` (in-process when ``workers == 1``, else a process pool) or ``dask``."""
    if kind == "local":
        return InProcess() if workers <= 1 else _Pool(workers)
    if kind == "dask":
        return _Dask(workers, scheduler)
    raise ValueError(f"unknown executor {kind!r} (local or dask)")
