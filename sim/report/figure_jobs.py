"""Draw a study's figures side by side on the run's workers.

A study's figures are independent of each other and are drawn after its chunks are done, when
the workers of a local process pool (``--workers N``) or of a local Dask cluster sit idle.
:func:`draw_figures` sends each figure job there; without a pool (``--workers 1``, a remote
Dask scheduler that may not see the output directory, or ``SIM_FIGURES_HERE`` set: the
benchmark's comparison, :mod:`benchmarks.studies`) it draws them in this process, in the given
order. :func:`start_figures` sends them and returns at once, so the figures are drawn
while this process goes on with the run (the sweeps, the claims); its ``wait`` collects them.
A job is ``(fn, args)`` with ``fn`` a module-level function (picklable) that
draws one figure and saves it (:func:`sim.report.plotting.save`); the files are the same either way.
matplotlib is not thread-safe: figures drawn in this process (parts of a run side by side in
threads, e.g. ``brown_design`` with a remote Dask scheduler) are drawn one at a time under
:data:`DRAWING`.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import Executor
from typing import Callable, Sequence

__all__ = ["draw_figures", "start_figures", "DRAWING"]

#: held while this process draws a figure (matplotlib's state is shared by its threads)
DRAWING = threading.Lock()


def _submitter(executor) -> Callable | None:
    if os.environ.get("SIM_FIGURES_HERE"):
        return None
    pool = getattr(executor, "pool", None)
    if isinstance(pool, Executor):
        return pool.submit
    client = getattr(executor, "client", None)
    if client is not None and getattr(executor, "cluster", None) is not None:  # local cluster
        return lambda fn, *args: client.submit(fn, *args, pure=False)
    return None


def start_figures(jobs: Sequence[tuple[Callable, tuple]], executor=None) -> Callable[[], None]:
    """Send every ``fn(*args)`` of ``jobs`` to the executor's local workers when it has some
    (in order: put the dearest first), else draw them here at once. Returns ``wait()``, which
    returns when every figure is drawn and raises a job's exception here."""
    submit = _submitter(executor)
    if submit is None:
        for fn, args in jobs:
            with DRAWING:
                fn(*args)
        return lambda: None
    futures = [submit(fn, *args) for fn, args in jobs]

    def wait() -> None:
        for f in futures:
            f.result()

    return wait


def draw_figures(jobs: Sequence[tuple[Callable, tuple]], executor=None) -> None:
    """Run every ``fn(*args)`` of ``jobs``: on the executor's local workers when it has some,
    else here. Put the dearest figures first (the pool takes them in order). An exception in
    a job is raised here."""
    if len(jobs) < 2:
        executor = None
    start_figures(jobs, executor)()
