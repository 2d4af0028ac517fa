"""Adaptive Monte-Carlo trial counts through the runner (in the spirit of JCGM 101 §7.9).

:func:`run_adaptive` runs whole chunks of one stream with :func:`sim.mc.runner.run_chunks`, so
the chunks go to the run's executor (process pool, Dask) and its chunk store, and a killed run
resumes. After each stage it asks ``stat(results)`` for ``{name: (value, standard error)}``;
while a standard error exceeds the target, it predicts the trials needed from ``se ~ 1/sqrt(N)``
(rounded up to whole chunks, at least one chunk more) and runs the stage to that total. Each
stage re-requests chunks ``0 .. K-1`` of the same stream: finished chunks come from the store
(a temporary one when the run has none), so the first ``N`` trials equal a fixed run of ``N``.
The run's estimate counts every stage at ``max_trials``; after each stage the run's bar counts
the trials predicted instead (more when a stage predicts more), so its time left is the work
the stages will do, not their maximum (counted at it until it stopped, brown_design's time
left was about twice the real one for its first half), and it ends at 100 %.
"""

from __future__ import annotations

import math
import tempfile
from typing import Callable, Mapping

import numpy as np

from sim.mc.runner import ChunkStore, run_chunks
from sim.studies import RunContext

__all__ = ["run_adaptive"]


def run_adaptive(
    fn,
    stat: Callable[[dict], Mapping[str, tuple[float, float]]],
    target: float,
    seed: int,
    chunk: int,
    part: int,
    min_trials: int,
    max_trials: int,
    label: str = "",
    ctx: RunContext | None = None,
    units: float | None = None,
):
    """``units``: a trial's unit adjustments on the run's bar. Returns ``(results, stats)``; ``len`` of a per-trial result is the trials it took."""
    top = max(chunk, (max_trials // chunk) * chunk)  # whole chunks only
    N = min(top, max(chunk, math.ceil(min_trials / chunk) * chunk))
    tmp, shared = None, ctx
    if ctx is None or ctx.store is None:
        tmp = tempfile.TemporaryDirectory(prefix="sim-adaptive-")
        ctx = RunContext(
            quiet=getattr(ctx, "quiet", True),
            executor=getattr(ctx, "executor", None),
            store=ChunkStore(tmp.name),
        )
    counted = max_trials  # the trials the run's bar counts for this stage (its estimate's)

    def recount(n: int) -> None:  # the bar counts ``n`` from now on (the stage's prediction)
        nonlocal counted
        if tmp is None and hasattr(shared, "unneeded") and n != counted:
            shared.unneeded(counted - n, units)
            counted = n

    try:
        while True:
            res = run_chunks(fn, N, seed, chunk, part=part, label=label, ctx=ctx, units=units)
            st = dict(stat(res))
            worst = max((se / target for _, se in st.values()), default=0.0)
            if worst < 1.0 or N >= top:
                recount(N)
                return res, st
            need = N * worst**2 * 1.05 if np.isfinite(worst) else 2 * N
            N = min(top, max(N + chunk, math.ceil(need / chunk) * chunk))
            recount(N)
    finally:
        if tmp is not None:
            tmp.cleanup()
