"""Checks of a network's points once every one is placed (listed, on a grid, at random): at
least two, no name twice or two names alike, coordinates within a double, a plane network's
extent and distance from its origin. Each refusal names the key the point came from (its record
in ``network.points``, or the ``origin``/``center`` of its ``network.grids`` or
``network.random`` entry): a grid placed beyond the largest double was blamed on
``network.points``, a key the file did not have (L37)."""

from __future__ import annotations

import re
from collections import Counter

import numpy as np

from sim.mc.config import ConfigError
from sim.mc.lookalike import skeleton
from sim.studies.network.validate import distinct_looks

__all__ = ["COORDINATE_MAX_MM", "check_points", "placed_by"]

#: no plane coordinate on the earth is farther from its grid's origin (mm: 100,000 km)
COORDINATE_MAX_MM = 1e11


def placed_by(key: str, rec: dict, field: str) -> str:
    """The key that places a grid's or random set's points: its ``field`` (``origin``,
    ``center``) as written (``_mm`` or ``_m``), else the record ``key`` itself."""
    return next((f"{key}.{field}{u}" for u in ("_m", "_mm") if f"{field}{u}" in rec), key)


def _named_by(key: str) -> str:
    """The key that names a point placed by ``key``: a record's ``name``, a set's ``prefix``."""
    rec = re.sub(r"\.(origin|center)_mm?$", "", key)
    return rec + (".name" if rec.startswith("network.points") else ".prefix")


def check_points(names: list[str], xy: np.ndarray, keys: list[str]) -> None:
    """Refuse the points ``names`` at ``xy`` (mm), each placed by ``keys`` (one line)."""
    if len(names) < 2:  # named by the one of the three keys an override set (load_study)
        e = ConfigError(
            "network.points",
            "a network needs at least two points (network.points, network.grids and "
            f"network.random give {len(names)})",
        )
        e.also = ("network.grids", "network.random")
        raise e
    dup = sorted(x for x, c in Counter(names).items() if c > 1)
    if dup:
        last = max(i for i, nm in enumerate(names) if nm == dup[0])
        raise ConfigError(_named_by(keys[last]), f"duplicate point name {dup[0]!r}")
    seen: dict[str, str] = {}
    for i, nm in enumerate(names):  # two names alike: the key of the later one
        if (other := seen.setdefault(skeleton(nm), nm)) != nm:
            distinct_looks(_named_by(keys[i]), [other, nm])
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if bad.size:
        raise ConfigError(
            keys[bad[0]], f"point {names[bad[0]]!r} lies beyond the largest 64-bit float"
        )
    span = np.ptp(xy, axis=0)
    if float(span.max()) > 1e9:
        axis = int(np.argmax(span))
        ends = (int(np.argmin(xy[:, axis])), int(np.argmax(xy[:, axis])))
        at = max(ends, key=lambda i: abs(xy[i, axis] - np.median(xy[:, axis])))
        km = f"{float(span.max()) / 1e6:.4g}"  # 1000.2 km read "spans 1000 km: over 1000 km"
        km = km if float(km) > 1000 else f"{float(span.max()) / 1e6:.9f}".rstrip("0")
        raise ConfigError(
            keys[at],
            f"the network spans {km} km: over 1000 km, out of range for "
            "a plane network (the earth's curvature) and for double-precision adjustment at "
            "the um level",
        )
    far = int(np.argmax(np.abs(xy).max(axis=1)))
    if np.abs(xy[far]).max() > COORDINATE_MAX_MM:
        raise ConfigError(
            keys[far],
            f"point {names[far]!r} at {np.abs(xy[far]).max() / 1e6:.4g} km from the origin: "
            f"over {COORDINATE_MAX_MM / 1e6:,.0f} km, not a plane coordinate on the earth",
        )
