"""Two readings of numbers in a config value, for :func:`sim.mc.config.validate`: the number a
string spells in a form TOML does not read (its message says how to write it), and every -0.0
in a value made 0.0 (the sign of a zero means nothing in any key)."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["number_text", "unsigned_zeros"]


def number_text(text: str) -> str:
    """The number ``text`` spells in a form TOML does not read (``.5``, ``5.``, ``07``,
    ``0x1p3``, ``Infinity``) or as a quoted string (``"400"``), written as TOML writes it
    (``0.5``); "" when it spells no finite number."""
    t = text.strip()
    if not t or len(t) > 100:
        return ""
    for read in (lambda s: int(s, 0), int, float, float.fromhex):
        try:
            x = read(t)
        except ValueError:
            continue
        return repr(x) if math.isfinite(x) else ""
    return ""


def unsigned_zeros(v: Any) -> Any:
    """``v`` with every -0.0 in it (in lists and tables too) made 0.0: a point at
    ``y_mm = -0.0`` gave a network other results than at ``0.0`` (in the 14th digit: atan2
    of -0.0), and its config another hash. RecursionError when nested too deeply."""
    if isinstance(v, float):
        return v + 0.0  # -0.0 + 0.0 is 0.0
    if isinstance(v, list):
        return [unsigned_zeros(x) for x in v]
    if isinstance(v, tuple):
        return tuple(unsigned_zeros(x) for x in v)
    if isinstance(v, dict) and v:  # an empty one is kept as it is (config's _EmptyTable)
        return {k: unsigned_zeros(x) for k, x in v.items()}
    return v
