"""The helpers ``sim`` exports beside :func:`sim.load` (``sim.load_study``,
``sim.read_provenance``, ``sim.write_table``, ``sim.run_chunks``: what every study uses),
taking their arguments as the API's own functions do. Called from a notebook, a missing or
unknown argument was Python's ``TypeError``, a handle or a ``Results`` given for a path
``TypeError: expected str, bytes or os.PathLike``, and ``sim.read_provenance`` of a
directory, a missing file or a study file pyarrow's ``OSError`` or ``ArrowInvalid`` with a
traceback (and ``help()`` of it said nothing): each is one :class:`sim.ConfigError` naming
the argument. The suite's own code calls the functions themselves, unchanged.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from sim.api_args import arguments
from sim.api_paths import check_path, why_unread
from sim.mc import runner, storage
from sim.mc.config import ConfigError
from sim.studies import load_study as _load_study

__all__ = ["load_study", "read_provenance", "write_table", "run_chunks"]


def _of_a_path(fn):
    """``fn``, whose first argument ``path`` is a path, checked as the API checks one."""

    @functools.wraps(fn)
    def checked(path, *args, **kwargs):
        check_path("path", path)
        return fn(path, *args, **kwargs)

    return arguments(checked)


def _of_counts(run):
    """``run`` (:func:`sim.mc.runner.run_chunks`) refusing, naming it, a chunk function that is
    not callable and a count that is not a whole number (``sim.run_chunks(None, 2, 1, 1)`` was
    "'NoneType' object is not callable" from inside the runner; ``trials=2.5``, NumPy's words)."""

    @functools.wraps(run)
    def checked(fn, trials, seed, chunk, part=0, *args, **kwargs):
        if not callable(fn):
            raise ConfigError("fn", f"must be a function fn(rng, n), got {type(fn).__name__}")
        for name, v, least in (("trials", trials, 1), ("seed", seed, 0), ("chunk", chunk, 1)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ConfigError(name, f"must be a whole number >= {least}, got {v!r}")
        if isinstance(part, bool) or not isinstance(part, (int, np.integer)) or part < 0:
            raise ConfigError("part", f"must be a whole number >= 0, got {part!r}")
        return run(fn, int(trials), int(seed), int(chunk), int(part), *args, **kwargs)

    return arguments(checked)


load_study = _of_a_path(_load_study)
write_table = _of_a_path(storage.write_table)
run_chunks = _of_counts(runner.run_chunks)


@arguments
def read_provenance(path: str | Path) -> dict[str, Any]:
    """The provenance a table the suite wrote carries in its Parquet schema (its study's
    ``config``, ``code_hash``, ...), as a dict; ``{}`` for a Parquet file without one."""
    check_path("path", path)
    try:
        return storage.read_provenance(path)
    except (OSError, ValueError, pa.ArrowException) as e:
        p = os.fspath(path)
        if os.path.isdir(p):
            why = "a directory, not a table (sim.Results(path, study) reads its tables)"
        elif not os.path.lexists(p):
            why = "no such file"
        elif isinstance(e, pa.ArrowInvalid):
            why = "not a Parquet file"
        else:
            why = why_unread(e) if isinstance(e, OSError) else str(e).splitlines()[0]
        raise ConfigError("path", f"{p}: {why}") from None
