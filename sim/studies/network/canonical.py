"""One spelling of a network's tables in its resolved config: the same network, however its
records are written, is one config and one config hash.

A study file's flat keys are resolved by their :class:`~sim.mc.config.Field` (an integer for
a float key is the float, a key left out is its default); the records of ``network.points``,
``grids``, ``random``, ``observations``, ``generate`` and ``datum.constraints`` were kept as
written, so a field written at its default (``role = "free"``, ``settings = 1``, ``bias_mm =
0.0``, ``nearest = 0``, ``center_mm = [0, 0]``) or an integer for a float (``sigma_arcsec =
2``, ``x_mm = 400``) gave the same network another config: another hash, another scratch
directory, "results of a different config" (or, the values comparing equal in Python, the
other spelling's provenance written over results of the same hash). :func:`canonical` drops
such defaults and writes every number as its field's type. It runs after the records were
validated (:func:`sim.studies.network.definition.build`), so every value is one the field
takes.
"""

from __future__ import annotations

from typing import Any

__all__ = ["canonical", "RECORD_KEYS"]

#: the config keys whose values are lists of records
RECORD_KEYS = (
    "network.points",
    "network.grids",
    "network.random",
    "network.observations",
    "network.generate",
)
#: fields read as floats (lengths, sigmas, biases) and as pairs of floats
_FLOATS = {
    *(f"{f}_{u}" for f in ("x", "y", "spacing", "half_extent") for u in ("mm", "m")),
    "sigma_mm",
    "sigma_arcsec",
    "bias_mm",
    "bias_arcsec",
}
_PAIRS = {"origin_mm", "origin_m", "center_mm", "center_m"}
#: fields read as integers
_INTS = {"nx", "ny", "n", "settings", "nearest"}
#: a field's value when it is left out (:mod:`sim.studies.network.validate`, ``definition``)
_DEFAULTS = {
    "role": "free",
    "settings": 1,
    "bias_mm": 0.0,
    "bias_arcsec": 0.0,
    "nearest": 0,
    "center_mm": [0.0, 0.0],
    "center_m": [0.0, 0.0],
}


def _value(field: str, v: Any) -> Any:
    if isinstance(v, bool):  # refused by the validation; left as it is
        return v
    if field in _FLOATS and isinstance(v, (int, float)):
        return float(v)
    if field in _INTS and isinstance(v, (int, float)):
        return int(v)
    if field in _PAIRS and isinstance(v, list):
        return [
            float(c) if isinstance(c, (int, float)) and not isinstance(c, bool) else c for c in v
        ]
    return v


def _record(rec: dict) -> dict:
    out = {}
    for field, v in rec.items():
        v = _value(field, v)
        if field in _DEFAULTS and v == _DEFAULTS[field] and type(v) is type(_DEFAULTS[field]):
            continue
        out[field] = v
    return out


def _coefficients(rec: dict) -> dict:
    return {k: float(v) if type(v) is int else v for k, v in rec.items()}


def canonical(cfg: dict) -> None:
    """Rewrite ``cfg``'s network records in place (new lists and tables: the caller's are not
    changed) in their one spelling: defaults dropped, numbers of their field's type."""
    for key in RECORD_KEYS:
        if isinstance(cfg.get(key), list):
            cfg[key] = [_record(r) if isinstance(r, dict) else r for r in cfg[key]]
    if isinstance(cfg.get("datum.constraints"), list):
        cfg["datum.constraints"] = [
            _coefficients(r) if isinstance(r, dict) else r for r in cfg["datum.constraints"]
        ]
