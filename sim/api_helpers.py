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

import sim.api_env  # noqa: F401 - the environment, before NumPy and Arrow load

# isort: split
import functools
import os
from collections.abc import Mapping
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


def _study_args(path, overrides=(), trials=None, seed=None, values=None):
    """Refuse overrides given as other than ``"key=value"`` strings (a dict was iterated by its
    keys and refused as "--set needs key=value (got 'trials')") and values not a mapping."""
    if isinstance(overrides, (str, bytes, Mapping)) or not isinstance(overrides, (list, tuple)):
        raise ConfigError(
            "overrides",
            f'must be a list of "key=value" strings, got {type(overrides).__name__}'
            + (" (a mapping of values: values=)" if isinstance(overrides, Mapping) else ""),
        )
    for bad in (o for o in overrides if not isinstance(o, str)):
        raise ConfigError("overrides", f'must be "key=value" strings, got {bad!r}')
    if values is not None and not isinstance(values, Mapping):
        raise ConfigError("values", f"must be a mapping of keys to values, got {values!r}")


def _table_args(path, columns, prov, tolerances=None):
    """Refuse columns that are not a mapping of names to 1-D arrays (pyarrow's "only handle
    1-dimensional arrays", or an AttributeError of ``.items``), a provenance not a mapping."""
    if not isinstance(columns, (Mapping, pa.Table)):
        raise ConfigError("columns", f"must map names to 1-D arrays, got {type(columns).__name__}")
    for name, v in columns.items() if isinstance(columns, Mapping) else ():
        flat = not isinstance(v, np.ndarray) or v.ndim == 1
        if isinstance(v, (str, bytes)) or not hasattr(v, "__len__") or not flat:
            raise ConfigError("columns", f"{name!r} must be a 1-D array or list, got {v!r:.60}")
    for key, v in (("prov", prov), ("tolerances", tolerances)):
        if v is not None and not isinstance(v, Mapping):
            raise ConfigError(key, f"must be a mapping, got {type(v).__name__}")


def _checked_by(check, fn):
    """``fn`` with its arguments checked first by ``check`` (which takes the same ones)."""

    @functools.wraps(fn)
    def checked(*args, **kwargs):
        check(*args, **kwargs)
        return fn(*args, **kwargs)

    return checked


load_study = _of_a_path(_checked_by(_study_args, _load_study))
write_table = _of_a_path(_checked_by(_table_args, storage.write_table))
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
