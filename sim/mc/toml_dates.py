"""TOML's date and time values shown as TOML writes them, in every message that quotes one.

No key of a study takes a date or a time, but TOML reads ``trials = 1979-05-27`` (or
``07:32:00``, ``1979-05-27T07:32:00Z``) as one, and each refusal quoted it by Python's
``repr``: ``got datetime.date(1979, 5, 27)``, or, cut at 60 characters, ``got
datetime.datetime(1979, 5, 27, 7, 32, tzinfo=datetime.timezo``. :func:`as_written` gives every
such value of a study file, a ``--set`` value or an API value a ``repr`` (and ``str``) that is
its TOML text (RFC 3339: ``1979-05-27``, ``07:32:00``, ``1979-05-27T07:32:00Z``,
``1979-05-27T07:32:00-07:00``), so that any message quoting it shows what the file held. The
value stays a date or a time, refused by each key as before.
"""

from __future__ import annotations

import datetime as dt
from typing import Any

__all__ = ["as_written"]


class _Date(dt.date):
    __slots__ = ()

    def __repr__(self) -> str:
        return self.isoformat()

    __str__ = __repr__


class _Time(dt.time):
    __slots__ = ()

    def __repr__(self) -> str:
        return self.isoformat()

    __str__ = __repr__


class _DateTime(dt.datetime):
    __slots__ = ()

    def __repr__(self) -> str:
        text = self.isoformat()  # "T" between date and time, as RFC 3339; UTC as TOML's "Z"
        return text.removesuffix("+00:00") + "Z" if text.endswith("+00:00") else text

    __str__ = __repr__


def _one(v: dt.date | dt.time) -> Any:
    if isinstance(v, (_Date, _Time, _DateTime)):
        return v
    if isinstance(v, dt.datetime):
        return _DateTime(
            v.year, v.month, v.day, v.hour, v.minute, v.second, v.microsecond, v.tzinfo, fold=v.fold
        )
    if isinstance(v, dt.date):
        return _Date(v.year, v.month, v.day)
    return _Time(v.hour, v.minute, v.second, v.microsecond, v.tzinfo, fold=v.fold)


def as_written(doc: Any) -> Any:
    """``doc`` (a value, or tables and arrays as ``tomllib`` gives them, changed in place) with
    every date, time and date-time shown as TOML writes it; walked without recursion."""
    if isinstance(doc, (dt.date, dt.time)):
        return _one(doc)
    todo = [doc] if isinstance(doc, (dict, list)) else []
    while todo:
        c = todo.pop()
        for k, x in list(c.items() if isinstance(c, dict) else enumerate(c)):
            if isinstance(x, (dict, list)):
                todo.append(x)
            elif isinstance(x, (dt.date, dt.time)):
                c[k] = _one(x)
    return doc
