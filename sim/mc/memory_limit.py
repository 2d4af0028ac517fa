"""The memory limit a command was given (``--max-memory-gb``), for the checks made while it
loads a study: the size check of a network at load (:mod:`sim.studies.network.validate`)
read ``SIM_MAX_MEMORY_GB`` alone, so ``sim run --max-memory-gb 64`` of a large network was
refused at the default 8 GiB, naming the environment variable, while the run's own estimate
(:func:`sim.mc.estimate.check_limits`) took the option."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from sim.mc.estimate import DEFAULT_MAX_MEMORY_GB, _limit

__all__ = ["memory_given", "memory_limit_gb"]

#: the command's ``--max-memory-gb`` while it runs (None: not given)
_GIVEN: ContextVar[float | None] = ContextVar("max_memory_gb", default=None)


def memory_limit_gb() -> float:
    """The memory limit in GiB: the command's, else ``SIM_MAX_MEMORY_GB``, else the default."""
    return _limit(_GIVEN.get(), "SIM_MAX_MEMORY_GB", DEFAULT_MAX_MEMORY_GB, "--max-memory-gb")


@contextmanager
def memory_given(gb: float | None) -> Iterator[None]:
    """The checks inside take ``gb`` (a command's ``--max-memory-gb``; None: the environment's)."""
    token = _GIVEN.set(gb)
    try:
        yield
    finally:
        _GIVEN.reset(token)
