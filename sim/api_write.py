"""``sim.write_table`` as the API exports it: its arguments checked before anything is written,
each misuse one :class:`sim.ConfigError` naming the argument (``path``, ``columns``, ``prov``,
``tolerances``) and the column or key. Called from a notebook (doors44a) it ended in
tracebacks of pyarrow, ``json`` and the OS, and did worse silently:

* a ``path`` that is a directory was ``IsADirectoryError``, one whose parent is a file
  ``FileExistsError``; a file there that the suite did not write (a user's ``notes.txt``,
  another tool's Parquet file, a symbolic link) was replaced without a word. Only a table that
  carries the suite's provenance (``sim.provenance``) is replaced now: a run of one's own study
  again.
* a provenance value JSON does not hold (a ``datetime``, ``bytes``, a set, a complex number,
  a ``Decimal``) was ``TypeError: not JSON serialisable``, a list holding itself "Circular
  reference detected", a key that is not a str ``TypeError`` (``'<' not supported``) or, alone,
  written as its str (``{1: 2}`` read back as ``{"1": 2}``); NaN and infinities were written
  as ``NaN`` and ``Infinity``, which are not JSON (another reader of the file refuses them).
* a column of mixed types (``[1, "x"]``), of complex numbers or a record dtype, columns of
  different lengths, a column name that is not a str (or one with a lone surrogate, as
  ``os.fsdecode`` makes of bytes that are not UTF-8): pyarrow's ``ArrowInvalid``,
  ``ArrowNotImplementedError`` or ``TypeError``; a masked array (``np.ma``) was written as its
  data, the masked values as numbers: they are nulls now, as pyarrow reads a mask.
* an infinite value was the storage's ``NonFiniteError`` and a tolerance naming no column or
  not a mapping ``ValueError``/``TypeError``.
* two threads writing one path: "cannot be written (No such file or directory)" (one
  temporary file for both); they write it one after the other now.
"""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.api_paths import why_unread
from sim.mc import storage, tolerance
from sim.mc.config import ConfigError

__all__ = ["checked_write"]

#: how deep a provenance may nest (json.dumps recursed until Python's limit, a RecursionError)
DEPTH = 100


def _target(path: Any) -> Path:
    """``path`` as the file to write, refused when it is a directory, under a file, or a file
    the suite did not write (its provenance key absent: it is the user's, never replaced)."""
    p = Path(os.fspath(path))
    if p.is_symlink():
        raise ConfigError("path", f"{p} is a symbolic link; sim never replaces it: name a file")
    if p.is_dir():
        raise ConfigError("path", f"{p} is a directory: name a file in it ({p / 'table.parquet'})")
    parent = next((q for q in p.parents if os.path.lexists(q)), None)
    if parent is not None and not parent.is_dir():
        raise ConfigError("path", f"{p}: {parent} is not a directory")
    if os.path.exists(p) and not p.is_file():
        raise ConfigError(
            "path", f"{p} is not a regular file (a pipe or a device); sim never replaces it"
        )
    if os.path.lexists(p) and not _ours(p):
        raise ConfigError(
            "path",
            f"{p} exists and is not a table sim wrote (no sim.provenance in it); sim never "
            "replaces it: remove it or name another file",
        )
    return p


def _ours(p: Path) -> bool:
    """Whether ``p`` is a Parquet table with the suite's provenance in its schema."""
    if not p.is_file():  # a FIFO: reading its schema blocked for good
        return False
    try:
        return storage._KEY in (pq.read_schema(p).metadata or {})
    except (OSError, ValueError, pa.ArrowException):
        return False


def _column(name: Any, v: Any) -> pa.Array:
    """One column as Arrow holds it (a masked array's masked values null), or refused."""
    if not isinstance(name, str):
        raise ConfigError("columns", f"a column's name must be a str, got {name!r:.60}")
    if not name.isascii():  # a lone surrogate (a name decoded from bytes that are not
        try:  # UTF-8, os.fsdecode): Arrow's UnicodeEncodeError, a traceback
            name.encode("utf-8")
        except UnicodeEncodeError:
            raise ConfigError(
                "columns", f"column {name!r:.60}: its name is not text UTF-8 can hold"
            ) from None
    if isinstance(v, (set, frozenset, Mapping)):  # np.asarray: one object, "only 1-D arrays"
        kind = "mapping" if isinstance(v, Mapping) else "set"
        raise ConfigError("columns", f"column {name!r} is a {kind}, of no order: give a list")
    try:
        if isinstance(v, np.ma.MaskedArray):
            return pa.array(np.asarray(v.data), mask=np.ma.getmaskarray(v))
        return pa.array(v if isinstance(v, list) else np.asarray(v))
    except (pa.ArrowException, TypeError, ValueError, OverflowError) as e:
        words = str(e).splitlines()[0][:160] if str(e) else type(e).__name__
        raise ConfigError(
            "columns", f"column {name!r} cannot be stored in a table ({words})"
        ) from None


def _table(columns: Mapping | pa.Table) -> pa.Table:
    """The table to write: ``columns`` as the storage makes it, every column checked."""
    if isinstance(columns, pa.Table):
        return columns
    arrays = {name: _column(name, v) for name, v in columns.items()}
    rows = {name: len(a) for name, a in arrays.items()}
    if len(set(rows.values())) > 1:
        (a, m), (b, n) = sorted(rows.items(), key=lambda kv: kv[1])[:: len(rows) - 1]
        raise ConfigError(
            "columns", f"columns differ in length: {a!r} has {m} row{'s' * (m != 1)}, {b!r} {n}"
        )
    return pa.table(arrays)


def _a(v: Any) -> str:
    name = type(v).__name__
    return f"{'an' if name[0] in 'aeiou' else 'a'} {name}"


def _where(at: str, key: Any) -> str:
    return f"{at}[{key!r}]" if at else repr(key)


def check_prov(v: Any, at: str = "", seen: tuple = ()) -> None:
    """Refuse, naming where it is in ``prov``, a value the provenance's JSON does not hold
    as it is: what ``json`` writes is None, bools, finite numbers, str, lists and mappings of
    str keys (NumPy scalars and arrays and paths as the storage converts them)."""
    if len(seen) > DEPTH:
        raise ConfigError("prov", f"{at} is nested more than {DEPTH} deep")
    if isinstance(v, (np.generic, np.ndarray)):  # as the storage writes them: their items
        v = v.tolist()
    elif isinstance(v, Path):
        return
    if v is None or isinstance(v, (bool, int, str)):
        return
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ConfigError(
                "prov", f"{at} is {v}, which JSON does not hold (None stands for no number)"
            )
        return
    if isinstance(v, (list, tuple, Mapping)):
        if id(v) in seen:
            raise ConfigError("prov", f"{at or 'it'} holds itself")
        inner = seen + (id(v),)
        if isinstance(v, Mapping):
            for k, x in v.items():
                if not isinstance(k, str):
                    raise ConfigError(
                        "prov",
                        f"{_where(at, k)}: a key must be a str, not {_a(k)}",
                    )
                check_prov(x, _where(at, k), inner)
        else:
            for i, x in enumerate(v):
                check_prov(x, f"{at}[{i}]", inner)
        return
    raise ConfigError(
        "prov",
        f"{at} is {type(v).__name__}, which the provenance's JSON does not hold: give a str, "
        "a number, a bool, None, a list or a mapping",
    )


#: a lock for each file written by threads of this process (:func:`_one_writer`)
_LOCKS: dict[str, threading.Lock] = {}
_LOCKS_LOCK = threading.Lock()


def _one_writer(path: Any) -> threading.Lock:
    """The lock of ``path``'s file: its temporary file is named by the process
    (``.<name>.<pid>.tmp``), so two threads writing one path wrote one temporary, and one of
    them, its temporary renamed by the other, said "cannot be written (No such file or
    directory)" (34 of 60 writes of two threads)."""
    key = os.path.abspath(os.fspath(path))
    with _LOCKS_LOCK:
        return _LOCKS.setdefault(key, threading.Lock())


def checked_write(path: Any, columns: Any, prov: Any, tolerances: Any = None) -> Path:
    """:func:`sim.mc.storage.write_table` of checked arguments (see the module's words), one
    thread of the process at a time for one file."""
    with _one_writer(path):
        return _write(path, columns, prov, tolerances)


def _write(path: Any, columns: Any, prov: Any, tolerances: Any) -> Path:
    p = _target(path)
    table = _table(columns)
    check_prov(prov)
    if tolerances:
        for col, spec in tolerances.items():
            if not isinstance(spec, Mapping):
                raise ConfigError(
                    "tolerances",
                    f"{col!r} must map to a rule such as {{'kind': 'exact'}}, got {spec!r:.60}",
                )
        try:
            tolerance.validate(tolerances, table)
        except (ValueError, TypeError, AttributeError, KeyError) as e:
            raise ConfigError("tolerances", str(e).splitlines()[0][:200]) from None
    try:
        return storage.write_table(p, table, prov, tolerances)
    except storage.NonFiniteError as e:
        raise ConfigError("columns", str(e)) from None
    except OSError as e:
        raise ConfigError("path", f"{p} cannot be written ({why_unread(e)})") from None
