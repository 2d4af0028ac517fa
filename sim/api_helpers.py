"""The helpers ``sim`` exports beside :func:`sim.load` (``sim.load_study``,
``sim.read_provenance``, ``sim.write_table``, ``sim.run_chunks``: what every study uses),
taking their arguments as the API's own functions do. Called from a notebook, a missing or
unknown argument was Python's ``TypeError``, a handle or a ``Results`` given for a path
``TypeError: expected str, bytes or os.PathLike``, and ``sim.read_provenance`` of a
directory, a missing file or a study file pyarrow's ``OSError`` or ``ArrowInvalid`` with a
traceback (and ``help()`` of it said nothing): each is one :class:`sim.ConfigError` naming
the argument. The suite's own code calls the functions themselves, unchanged. What
``sim.write_table`` and ``sim.run_chunks`` check beyond their arguments' kinds (the file
written over, the provenance, the columns; what a chunk function returns) is in
:mod:`sim.api_write` and :mod:`sim.api_chunks`.
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
from sim.api_chunks import Checked, check_counts, check_fn, check_options, ran
from sim.api_paths import check_path, why_unread
from sim.api_write import checked_write
from sim.mc import runner, storage
from sim.mc.config import ConfigError, parse_override
from sim.mc.paths import link_problem
from sim.mc.pyvalue import as_config_value
from sim.report.read import memory_failure
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
    def checked(
        fn,
        trials,
        seed,
        chunk,
        part=0,
        label="",
        quiet=False,
        ctx=None,
        keep_rows=False,
        units=None,
    ):
        check_fn(fn)
        for name, v, least in (("trials", trials, 1), ("seed", seed, 0), ("chunk", chunk, 1)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ConfigError(name, f"must be a whole number >= {least}, got {v!r}")
        if isinstance(part, bool) or not isinstance(part, (int, np.integer)) or part < 0:
            raise ConfigError("part", f"must be a whole number >= 0, got {part!r}")
        check_options(int(trials), int(chunk), label, quiet, ctx, keep_rows, units)
        try:
            out = run(
                Checked(fn), int(trials), int(seed), int(chunk), int(part), label, bool(quiet),
                ctx, bool(keep_rows), units,
            )  # fmt: skip
        except Exception as e:
            if (refusal := ran(e)) is not None:  # chunks that do not fit together
                raise refusal from None
            raise
        check_counts(out, int(trials), -(-int(trials) // int(chunk)))
        return out

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


def _study_values(path, overrides=(), trials=None, seed=None, values=None):
    """:func:`sim.studies.load_study` of its arguments read as :func:`sim.load` reads them:
    ``values``, ``trials`` and ``seed`` of any number type (``np.int64(40)``, a tuple) as the
    plain value (they were "must be an integer (got np.int64(40))"), ``None`` and a key that
    is not a str refused (it was "is required", and a ``TypeError``), a key given twice (by
    ``overrides`` and ``values``, or ``values`` and ``trials``) refused, where one value was
    dropped without a word; a malformed override and an unreadable file named as the argument
    (it named ``--set``, or nothing)."""
    _study_args(path, overrides, trials, seed, values)
    given: dict[str, str] = {}
    for text in overrides:
        try:
            key, _ = parse_override(text)
        except ConfigError as e:
            raise ConfigError("overrides", e.detail.replace("--set ", "an override ")) from None
        given[key] = "overrides"
    vals = {}
    for k, v in (values or {}).items():
        if not isinstance(k, str):
            raise ConfigError(
                "values", f"a key must be a dotted str such as 'trials', got {k!r:.60}"
            )
        if v is None:
            raise ConfigError(
                k, "is None, which no study file holds: leave it out for the file's value"
            )
        vals[k] = as_config_value(k, v)
    counts = {
        n: as_config_value(n, v) for n, v in (("trials", trials), ("seed", seed)) if v is not None
    }
    for k, where in [*((k, "values") for k in vals), *((n, n) for n in counts)]:
        if k in given:
            raise ConfigError(
                k, f"given twice (by {given[k]} and {where}): one value would be dropped"
            )
        given[k] = where
    try:
        return _load_study(path, overrides, counts.get("trials"), counts.get("seed"), vals)
    except ConfigError as e:
        if e.key is None and str(e).startswith(os.fspath(path)):  # the study file's own
            raise ConfigError("path", str(e)) from None
        raise


load_study = _of_a_path(functools.wraps(_load_study)(_study_values))
write_table = _of_a_path(
    _checked_by(_table_args, functools.wraps(storage.write_table)(checked_write))
)
run_chunks = _of_counts(runner.run_chunks)


@arguments
def read_provenance(path: str | Path) -> dict[str, Any]:
    """The provenance a table the suite wrote carries in its Parquet schema (its study's
    ``config``, ``code_hash``, ...), as a dict; ``{}`` for a Parquet file without one."""
    check_path("path", path)
    p = os.fspath(path)
    if os.path.exists(p) and not os.path.isdir(p) and not os.path.isfile(p):
        # a FIFO nobody writes to: pyarrow's open blocked for good
        raise ConfigError("path", f"{p}: not a regular file (a pipe or a device)")
    try:
        prov = storage.read_provenance(path)
    except (OSError, ValueError, pa.ArrowException) as e:
        if os.path.isdir(p):
            why = "a directory, not a table (sim.Results(path, study) reads its tables)"
        elif not os.path.lexists(p):
            why = "no such file"
        elif (link := link_problem(p)) is not None:  # it was pyarrow's "Failed to open local
            why = link  # file 'loop'. Detail: [errno 40] Too many levels of symbolic links"
        elif isinstance(e, pa.ArrowInvalid):
            why = "not a Parquet file"
        elif isinstance(e, OSError) and e.errno and not memory_failure(e):
            why = os.strerror(e.errno)  # not pyarrow's "Failed to open local file ... Detail"
        else:
            why = why_unread(e) if isinstance(e, OSError) else str(e).splitlines()[0]
        raise ConfigError("path", f"{p}: {why}") from None
    if not isinstance(prov, dict):  # another tool's key of that name: [1, 2] was returned
        raise ConfigError("path", f"{p}: its metadata sim.provenance is not a JSON object")
    return prov
