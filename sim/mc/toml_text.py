"""A resolved config value written as TOML text (``sim check``'s listing, sweep notes).

``sim check`` prints every key of a study as ``key = value``; written with Python's ``repr`` a
flag read ``False`` and a network's points ``[{'name': 'A', ...}]``, which a user who copied
the line into a study file got back as a TOML error. Here: ``true``/``false``, strings in
double quotes (JSON escapes are TOML escapes), integers and floats as Python writes them
(``inf``, ``nan`` are TOML too), arrays ``[...]`` and inline tables ``{ key = value }`` with
keys quoted where they are not bare. ``tomllib.loads(f"k = {toml_value(v)}")["k"] == v``.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any

import numpy as np

__all__ = ["toml_value", "toml_key"]

_BARE = re.compile(r"[A-Za-z0-9_-]+")


def toml_key(key: str) -> str:
    """``key`` as one TOML key: bare when it can be, else a quoted string."""
    return key if _BARE.fullmatch(key) else json.dumps(key, ensure_ascii=False)


def toml_value(v: Any) -> str:
    """``v`` (a value of a resolved config: bool, int, float, str, list/tuple, dict) as TOML;
    ``TypeError`` for anything else (``None`` has no TOML form). A NumPy scalar is written as
    the Python number it holds (``repr`` of ``np.float64(1.5)`` is not TOML)."""
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, np.ndarray):
        v = v.tolist()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(int(v))
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return repr(float(v)) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    if isinstance(v, str):  # DEL must be escaped in TOML, not in JSON
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        if not v:
            return "{}"
        return (
            "{ " + ", ".join(f"{toml_key(str(k))} = {toml_value(x)}" for k, x in v.items()) + " }"
        )
    raise TypeError(f"no TOML form for {type(v).__name__}")
