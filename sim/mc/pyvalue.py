"""A Python value given for a config key (``sim.load(..., **overrides)``) as the value a study
file would hold, so that it is validated, recorded and hashed like one.

A Python caller holds numbers of many types; a study file holds TOML's four: bool, a 64-bit
integer, a double and a string, in lists and tables. Each value is read as the number it is:

* any integer (``np.int64(7)``, an ``IntEnum`` member, an ``int`` subclass) is the ``int``;
* a ``Fraction`` with denominator 1 and a ``Decimal`` written without a point or an exponent
  (``Decimal("400")``) are that ``int``; others are the double nearest them, as TOML reads
  the same digits (``Decimal("0.1")`` is ``0.1``); one beyond a double's range, or so small it
  would be read as 0, is refused naming the key;
* a NumPy float is the decimal number it prints: ``np.float32(0.1)`` is ``0.1`` (not its
  binary value ``0.10000000149011612``), as the same digits typed into a study file would be
  (the shortest digits, whatever the caller's ``np.set_printoptions(legacy="1.13")`` prints);
  ``np.longdouble`` is the double nearest it (refused as a ``Decimal`` is when
  no double holds it: ``1e-4000``); a ``float`` subclass is the ``float``;
* a NumPy array, a tuple and a list are lists (at any depth: ``plate.points`` as a tuple of
  tuples or an ``(n, 2)`` array), a 0-d array its element, a mapping a table; so are a
  pyarrow array or column (the suite's own tables: ``res.table("points").column("x_mm")``)
  and any other array-like (``__array__``: a pandas Series, a DataFrame as rows), whose
  many-line repr a refusal quoted over many lines; a pyarrow scalar is its Python value;
* another sequence (a ``range``, a ``deque``, ``d.keys()``) is a list; an iterator (a generator, ``zip``,
  ``map``: read once) and a set (no order) are refused, saying to give a list;
* ``np.bool_`` is ``bool``; ``np.str_`` and a ``str`` subclass are ``str``;
* an ``os.PathLike`` of a ``str`` (``pathlib.Path``) is that ``str``: a file key
  (``network.gama_xml``) takes the path it is (it was refused as "must be a string").

A caller's object that raises while it is read (a ``PathLike`` whose ``__fspath__``, a
``Sequence`` whose ``__len__``, an ``Integral`` whose ``__int__`` raises) is refused naming
the key and the exception (it passed through the API as a traceback of the caller's code).

Anything else (a complex number, a date, ``None``) is passed on as given and refused by the
key's validation with one line naming the type expected (a date or time quoted as TOML writes
it: ``2020-01-01``, not ``datetime.date(2020, 1, 1)``). A bool stays a bool (refused where
a number is meant: ``True`` is not the trial count 1).
"""

from __future__ import annotations

import datetime
import decimal
import numbers
import os
from collections.abc import Iterator, Mapping, MappingView, Sequence, Set
from typing import Any

import numpy as np
import pyarrow as pa

from sim.mc.config import ConfigError, refuse_big_ints
from sim.mc.numtext import unheld
from sim.mc.toml_dates import as_written

__all__ = ["as_config_value"]

#: most digits of an integral Decimal converted to an int (any over 19 is refused anyway)
_MAX_DIGITS = 4000
#: most entries of a sequence other than a list or tuple (a ``range``) made a list
_MAX_ITEMS = 10**6


def _decimal(key: str, v: decimal.Decimal) -> Any:
    if v.is_nan():  # sNaN: float() raises; NaN is refused by the key ("must be finite")
        return float("nan")
    if v.is_infinite():
        return float(v)
    text = str(v)
    if "E" not in text and "." not in text:  # written as an integer: the int
        if len(text.lstrip("-")) > _MAX_DIGITS:
            raise ConfigError(key, f"an integer of over {_MAX_DIGITS} digits is not a config value")
        return int(v)
    return _nearest(key, v, float(v))


def _nearest(key: str, v: Any, x: float) -> float:
    """``x``, the double nearest the finite non-double ``v``; refused when ``v`` is beyond a
    double's range (``x`` infinite) or so small that ``x`` is 0."""
    if x in (float("inf"), float("-inf")) or (x == 0 and v != 0):
        raise ConfigError(key, unheld(repr(v), x))  # the words of a study file's digits
    return x


def _scalar(key: str, v: Any) -> Any:
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (np.datetime64, np.timedelta64)):  # a date or a duration, no number:
        # refused by the key. np.timedelta64 is a NumPy integer: int() of one in seconds was a
        # TypeError traceback, and one in nanoseconds (as a datetime64's .item()) its count:
        # trials=np.timedelta64(40, "ns") ran 40 trials
        x = v.item()
        return as_written(x) if isinstance(x, (datetime.date, datetime.time)) else v
    if isinstance(v, numbers.Integral):  # int subclasses, IntEnum, NumPy integers
        return int(v)
    if isinstance(v, np.floating):  # the decimal number it prints (float32(0.1) is 0.1);
        with np.printoptions(legacy=False):  # the caller's legacy="1.13": 12 digits printed
            x = float(str(v))  # a longdouble no double holds (1e-4000 was 0.0) refused
        return _nearest(key, v, x) if np.isfinite(v) else x
    if isinstance(v, float):
        return float(v)
    if isinstance(v, numbers.Rational):  # Fraction
        if v.denominator == 1:
            return int(v.numerator)
        try:
            x = float(v)
        except OverflowError:
            x = float("inf") if v > 0 else float("-inf")
        return _nearest(key, v, x)
    if isinstance(v, decimal.Decimal):
        return _decimal(key, v)
    if isinstance(v, numbers.Real):  # another library's real number
        return _nearest(key, v, float(v))
    if isinstance(v, str):  # np.str_, a str subclass (a StrEnum member)
        return str.__str__(v)
    if isinstance(v, np.generic):  # datetime64 and the like: refused by the key, as Python's
        return as_written(v.item())
    if isinstance(v, (datetime.date, datetime.time)):  # refused by the key, quoted as TOML
        return as_written(v)  # writes it (2020-01-01), as a study file's date is
    if isinstance(v, os.PathLike):  # Path("net.xml"); one of bytes is refused by the key
        try:
            text = os.fspath(v)
        except TypeError:
            return v
        return str.__str__(text) if isinstance(text, str) else v
    return v


def as_config_value(key: str, v: Any) -> Any:
    """``v`` as a study file would hold it (module docstring); ConfigError naming ``key`` for
    a number no double can hold or a value nested too deeply."""
    try:
        return _convert(key, v)
    except RecursionError:
        raise ConfigError(key, "is nested too deeply") from None
    except ConfigError:
        raise
    except Exception as e:  # the caller's object raised while read: a PathLike whose
        # __fspath__, a Sequence whose __len__, a Mapping whose __iter__, an Integral whose
        # __int__, an array-like whose __array__ raised passed through the API as a traceback
        raise ConfigError(key, _unreadable(v, e)) from None


def _unreadable(v: Any, e: Exception) -> str:
    """The words for ``v``, a caller's object that raised ``e`` while read as a value."""
    try:  # an exception of the caller's whose own __str__ raises: named by its type
        said = " ".join(str(e).split())[:120]
    except Exception:  # noqa: BLE001 - (it was that second exception's traceback)
        said = ""
    said = f"{type(e).__name__}: {said}" if said else type(e).__name__
    return (
        f"is not a config value: reading its {type(v).__name__} raised {said} "
        "(give a plain value: a number, a str or a list)"
    )


def _convert(key: str, v: Any) -> Any:
    if isinstance(v, (pa.Array, pa.ChunkedArray, pa.Scalar)):
        try:
            py = v.as_py() if isinstance(v, pa.Scalar) else v.to_pylist()
        except (ValueError, pa.ArrowException):  # a timestamp or duration in ns (not whole
            # microseconds) was a ValueError traceback; no key takes a date or a duration
            raise ConfigError(
                key, f"is a pyarrow {v.type} value with no Python form: not a config value"
            ) from None
        return _convert(key, py)
    if not isinstance(v, (np.ndarray, np.generic, str, bytes, Mapping)) and hasattr(
        type(v), "__array__"
    ):
        try:
            v = np.asarray(v)
        except (TypeError, ValueError):  # refused by the key, naming its type
            return v
    if isinstance(v, np.ndarray):
        if v.ndim == 0 and np.ma.is_masked(v):  # np.ma.masked: v[()] is itself ("nested too
            raise ConfigError(  # deeply", the recursion's words)
                key, "is masked (np.ma.masked, no value): give one, or leave the key out"
            )
        if v.ndim == 0:
            return _convert(key, v[()])
        if v.dtype.kind in "iub" or v.dtype == np.float64:
            return v.tolist()
        return [_convert(key, x) for x in v]
    if isinstance(v, (list, tuple)):
        return [_convert(key, x) for x in v]
    if isinstance(v, MappingView) or (
        isinstance(v, Sequence) and not isinstance(v, (str, bytes, bytearray, memoryview))
    ):
        if len(v) > _MAX_ITEMS:  # range(10**12) is no list to make
            raise ConfigError(key, f"has {len(v)} entries, over {_MAX_ITEMS}")
        return [_convert(key, x) for x in v]
    if isinstance(v, (Iterator, Set)):  # refused by the key as "<zip object at 0x7f...>"
        what = "a set, which has no order" if isinstance(v, Set) else "an iterator, read once"
        raise ConfigError(
            key, f"is {what} ({type(v).__name__}): give a list (list(...) or sorted(...))"
        )
    if isinstance(v, Mapping):
        out = {}
        for k, x in v.items():
            if not isinstance(k, str):  # a study file's tables have names: {1: 2.0} in a
                # network record was a TypeError traceback (its field guessed, or sorted)
                raise ConfigError(key, f"a table's key must be a string (got {repr(k)[:60]})")
            name = _scalar(key, k)
            out[name] = _convert(f"{key}.{name}", x)
        return out
    refuse_big_ints(key, v)  # before int() of a 10**400 IntEnum or Fraction
    return _scalar(key, v)
