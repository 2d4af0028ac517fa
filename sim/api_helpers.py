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
import json
import os
import stat
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from sim.api_args import arguments
from sim.api_paths import check_path, why_unread
from sim.mc import runner, storage, tolerance
from sim.mc.config import MAX_CHUNKS, ConfigError
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
        if (n := -(-int(trials) // int(chunk))) > MAX_CHUNKS:  # 10**12 of 1: a list of them
            raise ConfigError(  # built for good, as the runs' own limit (sim.mc.config) refuses
                "chunk",
                f"{trials:,} trials in chunks of {chunk:,} make {n:,} chunks (at most "
                f"{MAX_CHUNKS:,}): make chunk at least {-(-int(trials) // MAX_CHUNKS):,}",
            )
        units = kwargs.get("units")
        if units is not None and (
            isinstance(units, bool)
            or not isinstance(units, (int, float, np.integer, np.floating))
            or not 0 <= units < float("inf")
        ):
            raise ConfigError("units", f"must be a number >= 0 or None, got {units!r}")
        return run(_Returns(fn), int(trials), int(seed), int(chunk), int(part), *args, **kwargs)

    return arguments(checked)


class _Returns:
    """A chunk function ``fn(rng, n)`` of the caller's whose result is checked to be a mapping
    of names to arrays, as the runner takes it: an ``int`` or a list was "'int' object has no
    attribute 'items'" from inside the runner. Picklable when ``fn`` is (a pool's tasks)."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, rng, n):
        out = self.fn(rng, n)
        if not isinstance(out, Mapping):
            raise ConfigError(
                "fn", f"must return a mapping of names to arrays, returned {type(out).__name__}"
            )
        return out


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
    for k in values or {}:  # {1: 2}: "normalize() argument 2 must be str, not int"
        if not isinstance(k, str):
            raise ConfigError("values", f"a key must be a string (got {k!r:.60})")


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


def _as_table(columns: Mapping) -> pa.Table:
    """``columns`` as the table :func:`sim.mc.storage.write_table` writes (each column made as
    it makes it), refusing a name that is not a string, a column pyarrow cannot hold (values of
    mixed kinds, a set) and columns of unequal lengths, naming the column: pyarrow's
    ``ArrowInvalid`` or ``TypeError`` ended in a traceback ("expected bytes, int found")."""
    arrays = {}
    for name, v in columns.items():
        if not isinstance(name, str):
            raise ConfigError("columns", f"a column's name must be a string, got {name!r:.60}")
        try:
            arrays[name] = pa.array(v if isinstance(v, list) else np.asarray(v))
        except (pa.ArrowException, TypeError, ValueError, OverflowError) as e:
            why = str(e).splitlines()[0][:120] if str(e) else type(e).__name__
            raise ConfigError("columns", f"{name!r} cannot be a Parquet column: {why}") from None
    first = next(iter(arrays), None)
    for name, a in arrays.items():
        if len(a) != len(arrays[first]):
            raise ConfigError(
                "columns",
                f"{name!r} has {len(a):,} values and {first!r} {len(arrays[first]):,}: every "
                "column of a table has as many",
            )
    return pa.table(arrays)


@functools.wraps(storage.write_table)
def _write_table(path, columns, prov, tolerances=None):
    """:func:`sim.mc.storage.write_table` with its arguments checked first: each refusal one
    :class:`ConfigError` naming the argument (a directory for ``path``, ``prov`` that is not
    JSON, a tolerance that is no rule, an infinite value were Python's or pyarrow's words)."""
    _table_args(path, columns, prov, tolerances)
    if os.path.isdir(path):
        raise ConfigError("path", f"{os.fspath(path)} is a directory: name the table's file")
    table = columns if isinstance(columns, pa.Table) else _as_table(columns)
    try:
        json.dumps(prov, sort_keys=True, default=storage._jsonable)
    except (TypeError, ValueError, RecursionError) as e:
        raise ConfigError("prov", f"cannot be written as JSON: {str(e)[:120]}") from None
    for col, rule in (tolerances or {}).items():  # {"a": "x"}: "dictionary update sequence"
        if not isinstance(rule, Mapping):
            raise ConfigError("tolerances", f"{col!r} must map to a rule (a mapping with its kind)")
    if tolerances:
        try:
            tolerance.validate(tolerances, table)
        except (TypeError, ValueError, AttributeError, KeyError) as e:
            raise ConfigError("tolerances", str(e).splitlines()[0][:160]) from None
    try:
        return storage.write_table(path, table, prov, tolerances)
    except storage.NonFiniteError as e:
        raise ConfigError("columns", str(e)) from None
    except OSError as e:  # a file where its directory goes: FileExistsError from mkdir
        where = f" ({e.filename})" if e.filename and str(e.filename) != os.fspath(path) else ""
        why = e.strerror or type(e).__name__
        raise ConfigError("path", f"{os.fspath(path)} cannot be written: {why}{where}") from None


def _checked_by(check, fn):
    """``fn`` with its arguments checked first by ``check`` (which takes the same ones)."""

    @functools.wraps(fn)
    def checked(*args, **kwargs):
        check(*args, **kwargs)
        return fn(*args, **kwargs)

    return checked


load_study = _of_a_path(_checked_by(_study_args, _load_study))
write_table = _of_a_path(_write_table)
run_chunks = _of_counts(runner.run_chunks)


@arguments
def read_provenance(path: str | Path) -> dict[str, Any]:
    """The provenance a table the suite wrote carries in its Parquet schema (its study's
    ``config``, ``code_hash``, ...), as a dict; ``{}`` for a Parquet file without one."""
    check_path("path", path)
    p = os.fspath(path)
    try:  # a FIFO nobody writes to: pyarrow's open waited for good
        special = not stat.S_ISREG(os.stat(p).st_mode) and not os.path.isdir(p)
    except (OSError, ValueError):
        special = False  # not there: said below, as pyarrow fails
    if special:
        raise ConfigError("path", f"{p}: not a regular file (a pipe or a device), not a table")
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
