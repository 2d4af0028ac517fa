"""Timing helpers of the benchmark: CPU time of this process, and a call with the compiled
kernels off (``SIM_NO_JIT=1``, :mod:`sim.lsq.compile`)."""

from __future__ import annotations

import os
import time

import numpy as np

__all__ = ["cpu_time", "numpy_path"]


def cpu_time(f, repeat: int = 3) -> float:
    """Best CPU time of this process over ``repeat`` calls of ``f()`` (s). Single-threaded
    work: CPU time is steadier than wall time on a shared machine; executors and study runs
    are timed by wall clock."""
    best = np.inf
    for _ in range(repeat):
        t = time.process_time()
        f()
        best = min(best, time.process_time() - t)
    return best


def numpy_path(f):
    """``f()`` with the compiled kernels off (``SIM_NO_JIT=1``, :mod:`sim.lsq.compile`)."""
    old = os.environ.get("SIM_NO_JIT")
    os.environ["SIM_NO_JIT"] = "1"
    try:
        return f()
    finally:
        if old is None:
            del os.environ["SIM_NO_JIT"]
        else:
            os.environ["SIM_NO_JIT"] = old
