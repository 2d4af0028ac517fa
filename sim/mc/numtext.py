"""Readings of numbers in a config value, for :mod:`sim.mc.config`: the number a string spells
in a form TOML does not read (its message says how to write it); every -0.0 in a value made
0.0 (the sign of a zero means nothing in any key); and a TOML float whose digits no double
holds (``1e-400``, which tomllib reads as 0, ``1e400`` as inf) kept apart to be refused."""

from __future__ import annotations

import math
import re
from typing import Any

__all__ = [
    "number_text",
    "unsigned_zeros",
    "toml_float",
    "float_text",
    "unheld",
    "UnheldError",
    "shown",
    "shows_differently",
]


class UnheldError(ValueError):
    """A float of a study file or ``--set`` that no double holds (its message says which)."""


class _Unheld(float):
    """What tomllib read for digits no double holds (0.0 or inf), with the digits."""

    text = ""


def toml_float(text: str) -> float:
    """tomllib's ``parse_float``: ``float(text)``, but digits that are no zero read as 0 (an
    underflow, ``1e-400``) or that are finite read as inf (``1e400``) are kept apart
    (refused by :func:`unsigned_zeros`, naming the key): 1e-400 was a bias of 0, silently,
    and 1e400 "must be finite (got inf)" of a finite number."""
    x = float(text)
    if x != 0 and not math.isinf(x) or math.isnan(x) or "inf" in text.lower():
        return x
    if x == 0 and not any(c in "123456789" for c in re.split("[eE]", text)[0]):
        return x  # a zero written as one
    out = _Unheld(x)
    out.text = text.strip()
    return out


def float_text(text: str) -> float:
    """The number a text outside TOML spells (an environment variable, a command-line
    option), as :func:`toml_float` reads it: ValueError when it spells none,
    :class:`UnheldError` naming the digits when no double holds them (``1e-400`` was "must be
    a positive number (got 0.0)", of digits that are no zero)."""
    return unsigned_zeros(toml_float(text))


def unheld(shown: str, x: float) -> str:
    """The refusal of a number written ``shown`` that no double holds: ``x``, the double it
    would be read as, is infinite (beyond the range) or 0 (too small). One wording for a
    study file, ``--set``, a GNU Gama file and a Python value (:mod:`sim.mc.pyvalue`)."""
    if math.isinf(x):
        return f"{shown} is beyond a 64-bit float's range"
    return f"{shown} is too small for a 64-bit float (it would be read as 0)"


def number_text(text: str) -> str:
    """The number ``text`` spells in a form TOML does not read (``.5``, ``5.``, ``07``,
    ``0x1p3``, ``Infinity``) or as a quoted string (``"400"``), written as TOML writes it
    (``0.5``); "" when it spells no finite number (a hexadecimal float only with its ``0x``:
    ``--set trials=abc`` was told to "write 2748.0")."""
    t = text.strip()
    if not t or len(t) > 100:
        return ""
    hexa = t.lstrip("+-")[:2].lower() == "0x"  # fromhex reads "abc" (2748.0) or "add" too
    for read in (lambda s: int(s, 0), int, float, *([float.fromhex] if hexa else [])):
        try:
            x = read(t)
        except ValueError:
            continue
        return repr(x) if math.isfinite(x) else ""
    return ""


def unsigned_zeros(v: Any) -> Any:
    """``v`` with every -0.0 in it (in lists and tables too) made 0.0: a point at
    ``y_mm = -0.0`` gave a network other results than at ``0.0`` (in the 14th digit: atan2
    of -0.0), and its config another hash. RecursionError when nested too deeply;
    :class:`UnheldError` for digits no double holds (:func:`toml_float`)."""
    if isinstance(v, _Unheld):
        raise UnheldError(unheld(v.text, v))
    if isinstance(v, float):
        return v + 0.0  # -0.0 + 0.0 is 0.0
    if isinstance(v, list):
        return [unsigned_zeros(x) for x in v]
    if isinstance(v, tuple):
        return tuple(unsigned_zeros(x) for x in v)
    if isinstance(v, dict) and v:  # an empty one is kept as it is (config's _EmptyTable)
        return {k: unsigned_zeros(x) for k, x in v.items()}
    return v


def shown(v: Any) -> str:
    """A config value as 12 significant digits show it (a list or table element by element):
    the one rule by which a run's value is "another" than a study file's or the paper's, so a
    swept 1.1 + 0.6 = 1.7000000000000002 is the paper's 1.7, and a printed 12.700082809 and a
    change in its 7th digit are two values."""
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(shown(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k!r}: {shown(v[k])}" for k in sorted(v, key=str)) + "}"
    if isinstance(v, float):
        return f"{v:.12g}"
    return repr(v) if isinstance(v, str) else str(v)


def shows_differently(a: Any, b: Any) -> bool:
    """Whether ``a`` and ``b`` are other values as :func:`shown` shows them."""
    return shown(a) != shown(b)
