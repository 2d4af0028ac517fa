"""One engine case of the benchmark (:mod:`benchmarks.engines`, :mod:`benchmarks.engines_linear`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Case"]


@dataclass(frozen=True)
class Case:
    """One engine case on ``T`` trials: ``engine()`` solves all trials at once (an array with
    a leading trial axis), ``one(t)`` solves trial ``t`` with SciPy (the same quantity);
    ``tol`` is the largest absolute difference allowed, in ``unit``; ``scipy`` names the
    SciPy call; ``why`` says in words why the loop is hard to beat, for a row below the
    target; ``floor(t)``, when given, is the bare compiled call of trial ``t`` under the SciPy
    loop (e.g. the LAPACK routine alone, its inputs prepared beforehand), timed for the note
    of a row below the target as ``floor_label``."""

    n_points: int
    engine: Callable[[], np.ndarray]
    one: Callable[[int], np.ndarray]
    tol: float
    unit: str
    scipy: str
    why: str = ""
    floor: Callable[[int], object] | None = None
    floor_label: str = ""
    #: the compiled module(s) the row times against their NumPy path ("" none)
    module: str = ""
    #: the NumPy side when it is not ``engine`` under ``SIM_NO_JIT=1`` (e.g. another kernel)
    numpy: Callable[[], np.ndarray] | None = None
    numpy_label: str = "the NumPy path (SIM_NO_JIT=1)"
