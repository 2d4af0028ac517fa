"""The values one key of a ``[sweep]`` table takes (:mod:`sim.mc.sweep` makes its cells of
them): a list as written, or a range ``{start, stop, num}`` (``numpy.linspace``) or ``{start,
stop, step}`` (``start + step * i`` up to ``stop``; integers exactly), checked to be finite and
at most :data:`MAX_CELLS` values. A range's values are reckoned in decimal from the numbers as
written (:func:`_decimal_range`): ``{start = 0.1, stop = 0.3, step = 0.1}`` is 0.1, 0.2, 0.3,
the values asked (binary arithmetic made its last level 0.30000000000000004)."""

from __future__ import annotations

import math
from decimal import Context, Decimal
from typing import Any

import numpy as np

from sim.mc.config import ConfigError

__all__ = ["MAX_CELLS"]

MAX_CELLS = 10_000  # cells x replicates of one sweep (sim.mc.estimate uses the same bound)


def _is_range(v: Any) -> bool:
    """A range table, or one meant as a range that lacks ``start`` or ``stop`` (no study key
    ends in ``start`` or ``stop``): ``{start = 1, step = 1}`` was flattened into the keys
    ``sweep.k.start`` and ``sweep.k.step``, "unknown key" rather than the missing ``stop``."""
    return isinstance(v, dict) and ("start" in v or "stop" in v)


def _finite(key: str, name: str, x: Any) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        raise ConfigError(f"sweep.{key}", f"{name} must be a finite number (got {x!r})")
    return x


def _values(key: str, v: Any) -> list:
    if isinstance(v, list):
        if not v:
            raise ConfigError(f"sweep.{key}", "needs at least one value")
        if len(v) > MAX_CELLS:
            raise ConfigError(f"sweep.{key}", f"has {len(v)} values (at most {MAX_CELLS})")
        return v
    if isinstance(v, dict) and not {"start", "stop"} <= set(v):
        lack = " and ".join(sorted({"start", "stop"} - set(v), reverse=True))
        raise ConfigError(f"sweep.{key}", f"a range needs start and stop (it has no {lack})")
    if _is_range(v):
        extra = set(v) - {"start", "stop", "num", "step"}
        if extra:
            raise ConfigError(f"sweep.{key}", f"unknown range entries {sorted(extra)}")
        a, b = _finite(key, "start", v["start"]), _finite(key, "stop", v["stop"])
        h = 0.5 if isinstance(b - a, float) and math.isinf(b - a) else 1  # 1e308 to -1e308:
        if "num" in v and "step" in v:
            raise ConfigError(f"sweep.{key}", "give num or step, not both")
        if "num" in v:
            n = v["num"]
            if isinstance(n, float) and n.is_integer() and abs(n) <= MAX_CELLS:
                n = int(n)  # num = 1e3 or 3.0: the count, as trials = 1e3 is
            if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_CELLS:
                raise ConfigError(
                    f"sweep.{key}", f"num must be an integer from 1 to {MAX_CELLS} (got {n!r})"
                )
            out = _decimal_range(a, b, n - 1, None)
        elif "step" in v:
            s = _finite(key, "step", v["step"])
            if s == 0 or (b * h - a * h) / s < 0:
                raise ConfigError(
                    f"sweep.{key}", "step must be non-zero and point from start to stop"
                )
            count = (b * h - a * h) / s / h  # (s * h: 0.0 for a step of 5e-324, in halves)
            if not count < MAX_CELLS:
                raise ConfigError(
                    f"sweep.{key}",
                    f"step {s!r} gives more than {MAX_CELLS} values from {a!r} to {b!r}",
                )
            if all(isinstance(x, int) for x in (a, b, s)):  # exact (NumPy's int64 wrapped)
                return [a + s * i for i in range((b - a) // s + 1)]
            out = _decimal_range(a, b, int(math.floor(count + 1e-9)), s)
        else:
            raise ConfigError(f"sweep.{key}", "a range needs num or step")
        if not np.isfinite(out).all():
            raise ConfigError(f"sweep.{key}", "the range's values are not finite")
        return [float(x) for x in out]
    raise ConfigError(f"sweep.{key}", f"a sweep takes a list, e.g. {_example(key, v)} (got {v!r})")


#: decimal digits of a range's arithmetic: a value is rounded once, to the nearest float
_DECIMAL = Context(prec=40, Emax=999_999, Emin=-999_999)


def _decimal_range(a: float, b: float, steps: int, s: float | None) -> np.ndarray:
    """``steps + 1`` values from ``a``: by ``s`` each (``{start, stop, step}``), or ``steps``
    equal parts of ``a`` to ``b`` (``{start, stop, num}``, ``b`` exactly at the end), reckoned
    in decimal from the shortest text of each number (``0.1`` is 0.1 there, not its binary
    neighbour), then rounded to the nearest float: the levels asked, not ``0.1 + 2 * 0.1`` =
    0.30000000000000004 or linspace's 0.6000000000000001 of 0 to 1 in 11. A value beyond the
    floats' range is inf (refused by the caller)."""
    da, db, c = Decimal(repr(a)), Decimal(repr(b)), _DECIMAL
    if s is None:
        width = c.subtract(db, da)
        vals = [c.add(da, c.divide(c.multiply(width, i), steps)) for i in range(steps)] + [db]
        vals = vals if steps else [da]
    else:
        vals = [c.add(da, c.multiply(Decimal(repr(s)), i)) for i in range(steps + 1)]
    out = np.array([float(v) for v in vals], dtype=float)
    if s is not None and abs(out[-1] - b) <= 1e-9 * abs(s):  # the step falls on stop
        out[-1] = b
    return out


def _example(key: str, v: Any) -> str:
    """``key = [v, ...]`` in TOML, the way to sweep a key given one value (``trials = 40`` was
    read as a sweep of one cell)."""
    name = key if key.replace("_", "").isalnum() else f'"{key}"'
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) < 2**52:
        more = repr(2 * v or 1)
    elif isinstance(v, float) and math.isfinite(v):
        more = repr(2 * v or 1.0)
    else:
        more = "..."
    first = f'"{v}"' if isinstance(v, str) and len(v) < 40 and '"' not in v else repr(v)[:40]
    return f"{name} = [{str(v).lower() if isinstance(v, bool) else first}, {more}]"
