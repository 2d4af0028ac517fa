"""``sim.run_chunks`` as the API exports it: its arguments and what its chunk function returns
checked, each misuse one :class:`sim.ConfigError` naming the argument (doors44a). A study of
the user's own called it as every study does, and:

* a chunk function that returned too many rows (``n + 1`` for a chunk of ``n`` trials) ran,
  its rows concatenated into more values than trials, without a word; one that returned a
  list or None was ``AttributeError: ... has no attribute 'items'``, a scalar NumPy's
  "zero-dimensional arrays cannot be concatenated", other keys or shapes from one chunk to the
  next ``KeyError`` or NumPy's words, a function of one argument Python's ``TypeError``;
* ``quiet="no"`` ran quiet (a true string), ``ctx=3`` or a dict ran in this process with no
  store, ``label=3`` and ``keep_rows="no"`` were taken as they came, ``units="x"`` was
  Python's "could not convert string to float";
* ``trials=10**12`` in chunks of 1 built a list of 10**12 chunk sizes (the process swapped,
  then died): at most :data:`sim.mc.config.MAX_CHUNKS` chunks, as a study's run has.

The chunk function's own exception (a ``ValueError`` of the user's code) is the user's and
passes through as it is, with a note naming the chunk; what it returns is the user's too: NaN
or infinite values are returned as they are (NaN may stand for "missing", as in the studies).
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from sim.mc.config import MAX_CHUNKS, ConfigError
from sim.mc.runner import ROWS, RunContext

__all__ = ["Checked", "check_options", "check_fn", "check_counts", "ran"]

#: set on an exception of the chunk function itself (kept through a worker's pickle)
_OWN = "_sim_chunk_function"


class Checked:
    """The chunk function ``fn``, its output checked (picklable when ``fn`` is: it runs in
    a worker as ``fn`` would). A kept array's first axis is the chunk's trials ``n`` or 1 (a
    per-chunk statistic); a ``rows.`` array is 1-D of ``n`` values."""

    def __init__(self, fn):
        self.fn = fn

    def __call__(self, rng: np.random.Generator, n: int) -> Mapping:
        try:
            out = self.fn(rng, n)
        except Exception as e:  # the user's own: passed on, marked and with the chunk named
            try:
                setattr(e, _OWN, True)
                e.add_note(
                    f"(in the chunk function of sim.run_chunks, a chunk of {n} trial{'s' * (n != 1)})"
                )
            except (AttributeError, TypeError):
                pass
            raise
        if not isinstance(out, Mapping):
            raise ConfigError("fn", f"must return a dict of arrays, returned {_kind(out)}")
        for key, v in out.items():
            if not isinstance(key, str):
                raise ConfigError("fn", f"returned the key {key!r:.40}: a key must be a str")
            try:
                a = np.asarray(v)
            except (ValueError, TypeError) as e:  # ragged lists: NumPy's "inhomogeneous shape"
                raise ConfigError("fn", f"returned {key!r}, not an array ({_first(e)})") from None
            if a.dtype.hasobject:  # neither stored (a run's chunk files) nor sent by a worker
                raise ConfigError(
                    "fn", f"returned {key!r} of Python objects: a chunk's arrays hold numbers"
                )
            shape = a.shape
            if key.startswith(ROWS) and shape != (n,):
                raise ConfigError(
                    "fn",
                    f"returned {key!r} of shape {shape} for {n} trials: per-trial rows are 1-D, of {n}",
                )
            if not shape or shape[0] not in (n, 1):
                raise ConfigError(
                    "fn",
                    f"returned {key!r} of shape {shape} for a chunk of {n} trials: a kept "
                    f"array's first axis is the chunk's trials ({n}) or 1 (a per-chunk statistic)",
                )
        return out


def _first(e: Exception) -> str:
    return str(e).splitlines()[0][:120] if str(e) else type(e).__name__


def _kind(v: Any) -> str:
    name = type(v).__name__
    return "None" if v is None else f"{'an' if name[0] in 'aeiou' else 'a'} {name}"


def check_fn(fn: Any) -> None:
    """``fn`` callable as ``fn(rng, n)``: two positional arguments."""
    if not callable(fn):
        raise ConfigError("fn", f"must be a function fn(rng, n), got {type(fn).__name__}")
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # a builtin without a signature: called as it is
        return
    try:
        sig.bind(None, None)
    except TypeError:
        name = getattr(fn, "__qualname__", type(fn).__name__)
        raise ConfigError(
            "fn", f"{name}{sig} cannot be called as fn(rng, n) (a generator and a trial count)"
        ) from None


def check_options(trials: int, chunk: int, label, quiet, ctx, keep_rows, units) -> None:
    """The options of :func:`sim.mc.runner.run_chunks` of the types it reads them as."""
    if -(-trials // chunk) > MAX_CHUNKS:
        raise ConfigError(
            "chunk",
            f"{trials:,} trials in chunks of {chunk:,} make {-(-trials // chunk):,} chunks "
            f"(at most {MAX_CHUNKS:,}): make chunk at least {-(-trials // MAX_CHUNKS):,}",
        )
    if not isinstance(label, str):
        raise ConfigError("label", f"must be a str (the progress bar's), got {label!r:.60}")
    for name, v in (("quiet", quiet), ("keep_rows", keep_rows)):
        if not isinstance(v, (bool, np.bool_)):
            raise ConfigError(name, f"must be True or False (got {v!r:.60})")
    if ctx is not None and not isinstance(ctx, RunContext):
        raise ConfigError(
            "ctx", f"must be the RunContext a study's run is given, or None, got {_kind(ctx)}"
        )
    if units is not None:
        ok = isinstance(units, (int, float, np.integer, np.floating)) and not isinstance(
            units, (bool, np.bool_)
        )
        if not ok or not math.isfinite(units) or units <= 0:
            raise ConfigError("units", f"must be a positive number or None, got {units!r:.60}")


def check_counts(out: Mapping, trials: int, chunks: int) -> None:
    """Refuse a key whose chunks gave their trials as its first axis in some and 1 (a
    per-chunk statistic) in others, each chunk alone passing :class:`Checked`: concatenated
    they are neither ``trials`` values nor ``chunks`` (6 trials in chunks of 3, ``(3,)`` then
    ``(1,)``: 4 values returned, without a word). Where every chunk gave the same kind the
    count is exactly one of the two, so the totals tell (run across workers, no chunk knows
    another's)."""
    for key, v in out.items():
        m = np.shape(v)[0]
        if m not in (trials, chunks):
            raise ConfigError(
                "fn",
                f"returned {key!r} with the chunk's trials as its first axis in some chunks and 1 "
                f"(a per-chunk statistic) in others: {m} values for {trials} trials in {chunks} "
                "chunks; return one kind in every chunk",
            )


def ran(e: Exception) -> ConfigError | None:
    """The refusal of chunks that do not fit together (``e`` raised where the runner
    concatenates them: other keys or shapes from one chunk to the next), or None for an
    exception of the chunk function itself."""
    own = getattr(e, _OWN, False) or isinstance(e, ConfigError)
    if own or not isinstance(e, (KeyError, ValueError)):
        return None
    what = f"the key {e.args[0]!r}" if isinstance(e, KeyError) and e.args else "arrays"
    return ConfigError(
        "fn",
        f"returned {what} in one chunk unlike another: every chunk must return the same keys, "
        "of arrays whose shapes differ only in the first axis",
    )
