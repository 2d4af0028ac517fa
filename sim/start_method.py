"""The caller's ``multiprocessing`` start method left as the run found it: unset.

Starting a process by ``forkserver`` or ``spawn`` (the local pool's workers when the caller's
process has threads of its own, :func:`sim.mc.executors._start_method`; a Dask cluster's
workers) reads ``multiprocessing.get_start_method()`` for the child's preparation data, which
fixes the process's default for good: after such a run of the Python API (or of
``sim.cli.main([...])`` in process), the caller's own ``multiprocessing.set_start_method(...)``
failed with "context has already been set". A run fixed by nobody but itself is put back
unset when the last run of the process ends (``set_start_method(None, force=True)``, the
documented way to unset it); a method the caller set before, or another than the default
set meanwhile, is kept.
"""

from __future__ import annotations

import functools
import multiprocessing
import threading

__all__ = ["keeps_start_method_unset"]

#: the method reading the default fixes (the platform's first, as documented)
_DEFAULT = multiprocessing.get_all_start_methods()[0]
_lock = threading.Lock()
#: the runs of this process under way, and whether the method was unset when the first began
_state = {"runs": 0, "unset": False}


def keeps_start_method_unset(fn):
    """``fn`` (a run) leaving the start method unset if it was unset when it began (or when
    the first of the runs then under way in other threads began)."""

    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        with _lock:
            if _state["runs"] == 0:
                _state["unset"] = multiprocessing.get_start_method(allow_none=True) is None
            _state["runs"] += 1
        try:
            return fn(*args, **kwargs)
        finally:
            with _lock:
                _state["runs"] -= 1
                fixed = multiprocessing.get_start_method(allow_none=True)
                # the platform's default, as reading it fixes it (not one a thread set since)
                if _state["runs"] == 0 and _state["unset"] and fixed == _DEFAULT:
                    multiprocessing.set_start_method(None, force=True)

    return wrapped
