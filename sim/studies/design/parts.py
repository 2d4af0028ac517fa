"""Independent parts of the ``brown_design`` run side by side (seed ``004``, Brown 1968).

Each Monte-Carlo part of the run (the check of the paper's design, every error-budget row,
every coverage case, each emcee posterior) is one or more :func:`sim.mc.runner.run_chunks`
calls, and each call waits for its last chunk: with few chunks per call (an adaptive stage of
one or three chunks, a posterior of four chains) one worker would often sit idle.
:func:`side_by_side` runs independent parts in threads of this process when the run's
executor sends chunks to other processes (a local pool or Dask), so their chunks share the
workers' queue; with the in-process executor the parts run one after another. The numbers do
not depend on it: every chunk draws from its own stream (``spawn_key = (part, chunk)``) and
each part assembles its chunks in chunk order.
"""

from __future__ import annotations

from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from contextvars import copy_context
from typing import Callable, Mapping

__all__ = ["side_by_side", "parallel"]


def parallel(ctx) -> bool:
    """True when the run's executor computes chunks in other processes."""
    ex = getattr(ctx, "executor", None)
    return getattr(ex, "pool", None) is not None or getattr(ex, "client", None) is not None


def side_by_side(tasks: Mapping[str, Callable[[], object]], ctx) -> dict:
    """``{name: task()}`` for independent callables: in threads when :func:`parallel`,
    else in the given order, each thread in a copy of the caller's context (a run without
    figures draws none there either: :func:`sim.report.plotting.without_figures`). An
    exception of a task (or an interrupt) is raised here at once."""
    if len(tasks) < 2 or not parallel(ctx):
        return {k: f() for k, f in tasks.items()}
    tp = ThreadPoolExecutor(len(tasks), thread_name_prefix="brown_design")
    try:
        futs = {k: tp.submit(copy_context().run, f) for k, f in tasks.items()}
        done, _ = wait(futs.values(), return_when=FIRST_EXCEPTION)
        for f in done:
            if f.exception() is not None:
                f.result()
        out = {k: f.result() for k, f in futs.items()}
    except BaseException:  # an interrupt or a failed part: raise now, without waiting for
        tp.shutdown(wait=False, cancel_futures=True)  # the other parts (the run's executor
        raise  # is then closed, which ends their chunk calls)
    tp.shutdown()
    return out
