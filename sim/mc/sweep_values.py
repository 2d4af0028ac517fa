"""The values one key of a ``[sweep]`` table takes (:mod:`sim.mc.sweep` makes its cells of
them): a list as written, or a range ``{start, stop, num}`` (``numpy.linspace``) or ``{start,
stop, step}`` (``start + step * i`` up to ``stop``; integers exactly), checked to be finite and
at most :data:`MAX_CELLS` values."""

from __future__ import annotations

import math
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
            with np.errstate(all="ignore"):  # reckoned in halves (its count was inf, "more
                out = np.linspace(a * h, b * h, n) / h  # than 10000 values", not finite)
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
            with np.errstate(all="ignore"):
                out = (a * h + s * h * np.arange(int(math.floor(count + 1e-9)) + 1)) / h
        else:
            raise ConfigError(f"sweep.{key}", "a range needs num or step")
        if not np.isfinite(out).all():
            raise ConfigError(f"sweep.{key}", "the range's values are not finite")
        return [float(x) for x in out]
    raise ConfigError(f"sweep.{key}", f"a sweep takes a list, e.g. {_example(key, v)} (got {v!r})")


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
