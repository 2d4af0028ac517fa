"""The one lock under which this process draws a figure: matplotlib is not thread-safe (its
font cache and text parser are shared), and figures are drawn from threads: brown_design runs
its parts in threads when its chunks go to a pool (``sim.studies.design.parts``), and two API
runs (``sim.load(...).run(...)``) in threads of one program draw their figures at once.

Every figure of the suite is drawn under it: the jobs of :func:`sim.report.plotting.draw` and
the figures the studies draw directly (the consistent regions, the sweep's), each wrapped in
:func:`one_at_a_time`. A thread that holds it already (a figure drawn inside a ``draw`` job)
goes on without taking it again: a second ``acquire`` of the plain lock waited for itself.
"""

from __future__ import annotations

import functools
import threading
from contextlib import contextmanager
from typing import Callable, Iterator, TypeVar

__all__ = ["DRAWING", "drawing", "one_at_a_time"]

#: held while this process draws a figure
DRAWING = threading.Lock()

_held = threading.local()  # .on: this thread holds DRAWING

F = TypeVar("F", bound=Callable)


@contextmanager
def drawing() -> Iterator[None]:
    """Hold :data:`DRAWING` for the block (already held by this thread: go on)."""
    if getattr(_held, "on", False):
        yield
        return
    with DRAWING:
        _held.on = True
        try:
            yield
        finally:
            _held.on = False


def one_at_a_time(fn: F) -> F:
    """``fn`` (it draws a figure and saves it) called under :func:`drawing`."""

    @functools.wraps(fn)
    def locked(*args, **kwargs):
        with drawing():
            return fn(*args, **kwargs)

    return locked  # type: ignore[return-value]
