"""How a run's worker processes start, as the caller's process sees it: its ``multiprocessing``
start method left as the run found it, and a script read from standard input not imported
again by the workers.

Starting a process by ``forkserver`` or ``spawn`` (the local pool's workers when the caller's
process has threads of its own, :func:`sim.mc.executors._start_method`; a Dask cluster's
workers) reads ``multiprocessing.get_start_method()`` for the child's preparation data, which
fixes the process's default for good: after such a run of the Python API (or of
``sim.cli.main([...])`` in process), the caller's own ``multiprocessing.set_start_method(...)``
failed with "context has already been set". A method fixed by nobody but the runs is put back
unset when the last run of the process ends (``set_start_method(None, force=True)``, the
documented way to unset it); a method the caller set before, or another than the default set
meanwhile, is kept.

The same preparation data names the caller's main module by its ``__file__``, which each
worker runs again. A script read from standard input (``python - < script.py``, a pipe to
``python``) has ``__file__ = "<stdin>"``, no file: every worker printed a ``FileNotFoundError``
traceback and the run was refused as if the script lacked its main guard. While runs are under
way such a ``__file__`` (one naming no file, a script deleted since it started too) is hidden,
as a notebook's ``__main__`` has none, so the workers import only the suite, and put back after.

A Dask cluster's nannies set variables in the caller's ``os.environ`` before they spawn each
worker (``distributed.nanny.pre-spawn-environ``: ``OMP_NUM_THREADS=1`` and its kind,
``MALLOC_TRIM_THRESHOLD_``; ``PYTHONHASHSEED``; ``__DASK_PARENT_PID``) and left them there:
every process the caller started after a Dask run ran BLAS on one thread with a fixed hash
seed. Those variables are put back as the first run found them when the last ends (a nanny
sets them again before each start).
"""

from __future__ import annotations

import functools
import multiprocessing
import os
import sys
import threading
from multiprocessing import process

__all__ = ["for_the_callers_process"]

#: the method reading the default fixes (the platform's first, as documented)
_DEFAULT = multiprocessing.get_all_start_methods()[0]
_lock = threading.Lock()
#: the variables a Dask nanny sets in its own process besides its ``pre-spawn-environ``
_DASK_SETS = ("PYTHONHASHSEED", "__DASK_PARENT_PID")
#: the runs of this process under way, whether the method was unset when the first began, and
#: the ``__main__`` whose ``__file__`` naming no file is hidden meanwhile, with that name
_state: dict = {"runs": 0, "unset": False, "hidden": None, "environ": {}}


def _no_file(main) -> str | None:
    """``main.__file__`` if the workers could not run it again (no such file), else None;
    read as multiprocessing reads it (relative to the process's first working directory)."""
    path = getattr(main, "__file__", None)
    if not isinstance(path, str) or getattr(main, "__spec__", None) is not None:
        return None  # no file (a notebook, python -c) or a module (python -m): imported by name
    if not os.path.isabs(path) and process.ORIGINAL_DIR is not None:
        path = os.path.join(process.ORIGINAL_DIR, path)
    return None if os.path.isfile(path) else main.__file__


def _dask_variables_back(before: dict) -> None:
    """The variables a Dask nanny set in this process (see the module) as in ``before``."""
    if "distributed" not in sys.modules:
        return  # no Dask cluster ran in this process
    import dask

    spawn_env = dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {}
    for name in (*spawn_env, *_DASK_SETS):
        if name not in before:
            os.environ.pop(name, None)
        elif os.environ.get(name) != before[name]:
            os.environ[name] = before[name]


def for_the_callers_process(fn):
    """``fn`` (a run) leaving the start method unset if it was unset when it began (or when
    the first of the runs then under way in other threads began), its workers not importing a
    ``__main__`` that names no file, and the variables a Dask nanny sets as they were."""

    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        with _lock:
            if _state["runs"] == 0:
                _state["unset"] = multiprocessing.get_start_method(allow_none=True) is None
                _state["environ"] = dict(os.environ)
                main = sys.modules.get("__main__")
                if (name := _no_file(main)) is not None:
                    try:
                        del main.__file__
                        _state["hidden"] = (main, name)
                    except (AttributeError, TypeError):  # not a module's: left as it is
                        pass
            _state["runs"] += 1
        try:
            return fn(*args, **kwargs)
        finally:
            with _lock:
                _state["runs"] -= 1
                if _state["runs"] == 0:
                    fixed = multiprocessing.get_start_method(allow_none=True)
                    # the platform's default, as reading it fixes it (not one set since)
                    if _state["unset"] and fixed == _DEFAULT:
                        multiprocessing.set_start_method(None, force=True)
                    _dask_variables_back(_state["environ"])
                    if _state["hidden"] is not None:
                        main, name = _state["hidden"]
                        _state["hidden"] = None
                        if not hasattr(main, "__file__"):
                            main.__file__ = name

    return wrapped
