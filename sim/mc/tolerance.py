"""How closely a re-run must reproduce each column of a result table: its tolerance, declared
with the column by the kind of number it holds (issue 27).

A table written with :func:`sim.mc.storage.write_table` may declare, per column, one of these
kinds (stored as JSON in the Parquet schema metadata under ``sim.tolerances``; a column that
declares nothing gets :func:`default_for` its type):

``exact``
    labels, counts, flags and decisions: equal, value for value.
``arithmetic``
    a deterministic number (an adjustment, a covariance, an analytic sigma): rounding a
    different BLAS kernel, CPU or compiled path leaves, bounded from the conditioning of its
    computation: ``|a - b| <= cond * eps * max(|a|, |b|) + atol`` with ``eps`` the double
    precision machine epsilon and ``cond`` an estimate of the digits lost (the condition
    number of the system solved, or the cancellation in the formula). The default ``cond``
    (:data:`DEFAULT_COND`, 1e-7 relative) allows about 9 of 16 digits lost: normal equations
    square a design's condition number (up to about 1e4 in this suite) and a statistic over
    many trials adds a few more; the alternative-path runs of ``tests/test_verify.py`` show
    deviations of 1e-10 or less.
``mc``
    a Monte-Carlo statistic: beyond the arithmetic bound, a ``fraction`` of its own Monte-Carlo
    standard error, taken per row from a column (``se``) or from a 95 % interval's columns
    (``ci``: ``se = (high - low) / 3.92``). Comparing a run with fewer trials, the bound is
    ``MC_K`` combined standard errors of the two runs.
``chain``
    the output of a sampler chain (emcee): compared within its Monte-Carlo interval,
    ``rtol * max(|a|, |b|)`` (the interval's relative half-width) or ``k`` standard errors of a
    column ``se``/interval ``ci``.
``axial``, ``circular``
    an angle compared modulo its ``period`` (180 for an axis such as an ellipse's bearing, 360
    for a direction), then by the arithmetic bound relative to the period.

Any kind may name a text column ``null_reason``: the value is null where it is undefined (the
bearing of a circle, a ratio of zeros), and that column says why in that row. A null compares
equal to a null only.

``analytic: true`` marks a column that does not depend on the number of Monte-Carlo trials:
it is compared by its rule also against a run with fewer trials (``sim.report.verify
--trials``); other columns are compared at the Monte-Carlo level there, or not at all.
"""

from __future__ import annotations

import json
from typing import Any, Mapping

import numpy as np
import pyarrow as pa

__all__ = [
    "KINDS",
    "EPS",
    "DEFAULT_COND",
    "DEFAULT_ATOL",
    "MC_K",
    "exact",
    "arithmetic",
    "mc",
    "chain",
    "axial",
    "circular",
    "default_for",
    "validate",
    "encode",
    "decode",
    "TOLERANCE_KEY",
]

TOLERANCE_KEY = b"sim.tolerances"
EPS = float(np.finfo(float).eps)
#: the default conditioning bound: ``DEFAULT_COND * EPS`` is 1e-7 relative
DEFAULT_COND = 1e-7 / EPS
#: absolute floor of the arithmetic bound, in the column's own unit (a number at zero)
DEFAULT_ATOL = 1e-9
#: combined Monte-Carlo standard errors allowed between runs of different trial counts
MC_K = 4.0
#: a 95 % interval spans 2 x 1.96 standard errors
CI_SPAN_SE = 3.92

KINDS = ("exact", "arithmetic", "mc", "chain", "axial", "circular")
_KEYS = {
    "exact": set(),
    "arithmetic": {"cond", "atol"},
    "mc": {"cond", "atol", "se", "ci", "fraction"},
    "chain": {"cond", "atol", "rtol", "se", "ci", "k"},
    "axial": {"cond", "atol", "period"},
    "circular": {"cond", "atol", "period"},
}
_COMMON = {"kind", "null_reason", "analytic"}


def exact(**kw: Any) -> dict:
    """Equal value for value (labels, counts, flags, decisions)."""
    return {"kind": "exact", **kw}


def arithmetic(cond: float = DEFAULT_COND, atol: float = DEFAULT_ATOL, **kw: Any) -> dict:
    """A deterministic number that loses about ``log10(cond)`` digits to rounding."""
    return {"kind": "arithmetic", "cond": float(cond), "atol": float(atol), **kw}


def mc(
    se: str | None = None,
    ci: tuple[str, str] | None = None,
    fraction: float = 0.1,
    **kw: Any,
) -> dict:
    """A Monte-Carlo statistic whose standard error is column ``se`` or the 95 % interval
    ``ci`` = (low column, high column) of its own row."""
    spec = {"kind": "mc", "fraction": float(fraction), **kw}
    if se is not None:
        spec["se"] = se
    if ci is not None:
        spec["ci"] = list(ci)
    return spec


def chain(
    rtol: float | None = None,
    se: str | None = None,
    ci: tuple[str, str] | None = None,
    k: float = MC_K,
    **kw: Any,
) -> dict:
    """A sampler chain's output: within ``rtol`` relative (its Monte-Carlo interval), or
    ``k`` standard errors from column ``se`` / interval ``ci``."""
    spec: dict = {"kind": "chain", "k": float(k), **kw}
    if rtol is not None:
        spec["rtol"] = float(rtol)
    if se is not None:
        spec["se"] = se
    if ci is not None:
        spec["ci"] = list(ci)
    return spec


def axial(period: float = 180.0, **kw: Any) -> dict:
    """An axis (e.g. an ellipse's bearing in degrees): the same modulo ``period``."""
    return {"kind": "axial", "period": float(period), **kw}


def circular(period: float = 360.0, **kw: Any) -> dict:
    """A direction: the same modulo ``period``."""
    return {"kind": "circular", "period": float(period), **kw}


def default_for(t: pa.DataType) -> dict | None:
    """The rule of a column that declares none: floats and integers are arithmetic at the
    default bound, booleans exact; text has no rule (a difference is listed, not failed)."""
    if pa.types.is_floating(t) or pa.types.is_integer(t):
        return arithmetic()
    if pa.types.is_boolean(t):
        return exact()
    return None


def _number(name: str, key: str, v: Any, positive: bool = False) -> None:
    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
    if not ok or v < 0 or (positive and v == 0):
        raise ValueError(f"tolerance of {name}: {key} must be a finite number >= 0, not {v!r}")


def validate(specs: Mapping[str, Mapping[str, Any]], table: pa.Table) -> dict:
    """Check ``specs`` (column -> spec) against ``table``; return them as plain dicts.

    Raises ValueError naming the column for an unknown column, kind or key, a bad number, a
    missing ``se``/``ci``/``null_reason`` column, or a null value without its reason."""
    names = set(table.column_names)
    out = {}
    for col, spec in specs.items():
        if col not in names:
            raise ValueError(f"tolerance of {col}: no such column")
        spec = dict(spec)
        kind = spec.get("kind")
        if kind not in KINDS:
            raise ValueError(f"tolerance of {col}: kind must be one of {KINDS}, not {kind!r}")
        extra = set(spec) - _KEYS[kind] - _COMMON
        if extra:
            raise ValueError(f"tolerance of {col}: unknown key(s) {sorted(extra)} for {kind}")
        for key in ("cond", "atol", "fraction", "rtol", "k"):
            if key in spec:
                _number(col, key, spec[key])
        if "period" in spec:
            _number(col, "period", spec["period"], positive=True)
        if kind == "chain" and not ({"rtol", "se", "ci"} & set(spec)):
            raise ValueError(f"tolerance of {col}: a chain needs rtol, se or ci")
        if kind == "mc" and not ({"se", "ci"} & set(spec)):
            raise ValueError(f"tolerance of {col}: a Monte-Carlo statistic needs se or ci")
        refs = [spec[k] for k in ("se", "null_reason") if k in spec] + list(spec.get("ci", []))
        if "ci" in spec and len(spec["ci"]) != 2:
            raise ValueError(f"tolerance of {col}: ci names two columns (low, high)")
        for r in refs:
            if r not in names:
                raise ValueError(f"tolerance of {col}: column {r!r} is not in the table")
        if "null_reason" in spec:
            vals, why = table.column(col), table.column(spec["null_reason"]).to_pylist()
            v = vals.to_numpy(zero_copy_only=False) if pa.types.is_floating(vals.type) else None
            null = np.asarray(vals.is_null()) | (np.isnan(v) if v is not None else False)
            for i in np.flatnonzero(null):
                if not why[i]:
                    raise ValueError(f"{col}: row {int(i)} is null and {spec['null_reason']} empty")
        out[col] = spec
    return out


def encode(specs: Mapping[str, Mapping[str, Any]]) -> bytes:
    return json.dumps(specs, sort_keys=True).encode()


def decode(meta: Mapping[bytes, bytes] | None) -> dict:
    """The declared tolerances of a table's schema metadata ({} if none)."""
    raw = (meta or {}).get(TOLERANCE_KEY)
    return json.loads(raw) if raw else {}
