"""A paper's declaration of its unprinted inputs and printed statements (issue 21): the data
:mod:`sim.claims.inference` explores. A TOML file with an ``[inputs]`` table (one sub-table per
input: ``low``, ``high`` in the unit its name ends with, ``why``: the hardware or text that
bounds it) and a ``[statements]`` table (one sub-table per printed statement: ``paper`` (the
words), ``source``, ``form``, ``ref``, ``decimals``, ``tol``, ``decide``; the forms and decision
zones of :mod:`sim.claims.book`: a printed number stands for its rounding, widened by ``tol``).
Bad keys and out-of-range values raise :class:`~sim.mc.config.ConfigError` naming the key."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from sim.mc.config import ConfigError

__all__ = ["FORMS", "Input", "Statement", "parse_declaration", "load_declaration", "read_toml"]

FORMS = ("value", "share", "count", "upper", "lower", "range", "one-plate")
_INPUT_KEYS = {"low", "high", "why"}
_STATEMENT_KEYS = {"paper", "source", "form", "ref", "decimals", "tol", "decide"}
_UNITS = ("_mm", "_um", "_m", "_deg", "_pct", "_min", "_px", "_1")


@dataclass(frozen=True)
class Input:
    """One unprinted input: its name (ending in its unit) and its physically possible range."""

    name: str
    low: float
    high: float
    why: str = ""

    def __post_init__(self):
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise ConfigError(f"inputs.{self.name}", "low and high must be finite numbers")
        if self.high < self.low:
            raise ConfigError(f"inputs.{self.name}", f"high {self.high} < low {self.low}")


@dataclass(frozen=True)
class Statement:
    """One printed statement (or one prediction): the zone its printed number stands for.

    ``ref`` is the printed number (or ``(a, b)`` for "from a to b"); ``decimals`` its printed
    decimals (the zone is widened by half a unit of the last one, as in
    :mod:`sim.claims.book`) and by ``tol``; ``upper``/``lower`` are one-sided bounds.
    ``decide`` says what would decide it when nothing in the region does.
    """

    id: str
    ref: tuple[float, float]
    form: str = "value"
    decimals: int | None = None
    tol: float = 0.0
    paper: str = ""
    source: str = ""
    decide: str = ""

    def __post_init__(self):
        if self.form not in FORMS:
            raise ConfigError(f"statements.{self.id}.form", f"unknown form {self.form!r}")
        if not all(math.isfinite(r) for r in self.ref) or self.ref[1] < self.ref[0]:
            raise ConfigError(f"statements.{self.id}.ref", f"not a number or interval: {self.ref}")
        if self.tol < 0 or not math.isfinite(self.tol):
            raise ConfigError(f"statements.{self.id}.tol", "must be a finite number >= 0")

    @property
    def zone(self) -> tuple[float, float]:
        """The decision zone: the printed rounding widened by ``tol`` (half-open for bounds)."""
        half = 0.0 if self.decimals is None else 0.5 * 10.0 ** (-self.decimals)
        lo, hi = self.ref[0] - half - self.tol, self.ref[1] + half + self.tol
        if self.form == "upper":
            lo = -math.inf
        elif self.form == "lower":
            hi = math.inf
        return lo, hi


def _ref(key: str, v: Any) -> tuple[float, float]:
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v), float(v)
    if isinstance(v, list) and len(v) == 2 and all(isinstance(x, (int, float)) for x in v):
        return float(v[0]), float(v[1])
    raise ConfigError(key, f"must be a number or [low, high], got {v!r}")


def _number(key: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ConfigError(key, f"must be a number, got {v!r}")
    return float(v)


def _unknown(prefix: str, table: Mapping, allowed: set) -> None:
    for k in table:
        if k not in allowed:
            raise ConfigError(
                f"{prefix}.{k}", f"unknown key (allowed: {', '.join(sorted(allowed))})"
            )


def parse_declaration(doc: Mapping[str, Any]) -> tuple[list[Input], list[Statement]]:
    """Inputs and statements from a parsed declaration (see the module doc); bad keys and
    out-of-range values raise :class:`ConfigError` naming the key."""
    _unknown("declaration", doc, {"inputs", "statements"})
    inputs, statements = [], []
    for name, t in dict(doc.get("inputs", {})).items():
        if not isinstance(t, dict):
            raise ConfigError(f"inputs.{name}", "must be a table with low, high")
        if not name.endswith(_UNITS):
            raise ConfigError(f"inputs.{name}", f"name must end in its unit ({', '.join(_UNITS)})")
        _unknown(f"inputs.{name}", t, _INPUT_KEYS)
        for k in ("low", "high"):
            if k not in t:
                raise ConfigError(f"inputs.{name}.{k}", "missing")
        inputs.append(
            Input(
                name,
                _number(f"inputs.{name}.low", t["low"]),
                _number(f"inputs.{name}.high", t["high"]),
                str(t.get("why", "")),
            )
        )
    for sid, t in dict(doc.get("statements", {})).items():
        if not isinstance(t, dict):
            raise ConfigError(f"statements.{sid}", "must be a table with ref")
        _unknown(f"statements.{sid}", t, _STATEMENT_KEYS)
        if "ref" not in t:
            raise ConfigError(f"statements.{sid}.ref", "missing")
        dec = t.get("decimals")
        if dec is not None and (isinstance(dec, bool) or not isinstance(dec, int) or dec < 0):
            raise ConfigError(f"statements.{sid}.decimals", "must be an integer >= 0")
        statements.append(
            Statement(
                sid,
                _ref(f"statements.{sid}.ref", t["ref"]),
                str(t.get("form", "value")),
                dec,
                _number(f"statements.{sid}.tol", t.get("tol", 0.0)),
                str(t.get("paper", "")),
                str(t.get("source", "")),
                str(t.get("decide", "")),
            )
        )
    if not inputs:
        raise ConfigError("inputs", "declares no input")
    return inputs, statements


def load_declaration(path: str | Path) -> tuple[list[Input], list[Statement]]:
    """Read a paper's declaration TOML (see the module doc)."""
    return parse_declaration(read_toml(path, "declaration"))


def read_toml(path: str | Path, what: str) -> dict:
    """A TOML file's table; an unreadable or invalid file is one ConfigError naming it."""
    p = Path(path)
    try:
        return tomllib.loads(toml_text(p))
    except OSError as e:
        raise ConfigError(str(p), f"cannot read the {what}: {e.strerror}") from None
    except UnicodeDecodeError:  # an editor that saved it in Latin-1 or UTF-16
        raise ConfigError(str(p), f"the {what} is not UTF-8 text") from None
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(str(p), f"not valid TOML: {e}") from None


def toml_text(p: Path) -> str:
    """The text of a data file (claim book, region declaration) as a user's editor may save
    it: UTF-8 with or without a Windows editor's signature (BOM), which is no part of the
    text (the study files are read the same way: :func:`sim.mc.config.read_toml`)."""
    return p.read_bytes().decode("utf-8").removeprefix("\ufeff")
