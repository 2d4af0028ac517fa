"""The overrides a run records (``run.json``'s ``overrides``) and their replay by ``make verify``.

A run made off its study file's values (``sim run --set KEY=VALUE``, ``--trials``, ``--seed``,
``--chunk``; ``sim.load(path, key=value)``, ``replace(...)`` and ``run(trials=, seed=)``; the
runs of ``python -m sim.batch -- --set ...``, which are ``sim run``'s) records each override as
one ``KEY=VALUE`` text, the value as given, written as TOML (:func:`sim.mc.toml_text.toml_value`,
which ``--set`` reads back as that very value), sorted by key: each key is given once, and
the same run by either door, or with its options in another order, writes the same record.
A run of the study file as written records none (no key).

``make verify`` re-ran a study file as written, so results made with overrides were "of
another config" after a full re-run: never verified. It now re-runs the file with exactly
the recorded overrides (:func:`replayable`) and compares; a study file edited since the run
still gives another config than the run's. A record is replayed only as ``--set KEY=VALUE``
of a key its own config holds, each as this module writes it: a ``run.json`` edited by hand
adds no other option (``--out``, ``--workers``, a second value) to the re-run.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from sim.mc.config import ConfigError, parse_override
from sim.mc.toml_text import toml_value

__all__ = ["recorded", "as_read", "command_values", "replayable", "keys_of", "without", "listed"]

#: a config key as a study names it: dotted words
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


def recorded(values: Mapping[str, Any]) -> list[str]:
    """The ``overrides`` of a run given ``values`` (``{dotted key: value as given}``)."""
    return [f"{k}={toml_value(v)}" for k, v in sorted(values.items())]


def as_read(values: Mapping[str, Any], config: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` with each float that ``config`` (the run's, validated) reads as an integer
    written as that integer, at any depth of a list: ``--trials 1e3`` recorded ``trials=1000``
    and ``--set trials=1e3`` (or the API's ``trials=1e3``) ``trials=1000.0``, two records of
    one input and one config (L37)."""
    return {k: _as_read(v, config.get(k)) for k, v in values.items()}


def _as_read(given: Any, read: Any) -> Any:
    if isinstance(given, float) and type(read) is int and given == read:
        return read
    if isinstance(given, list) and isinstance(read, list) and len(given) == len(read):
        return [_as_read(a, b) for a, b in zip(given, read)]
    return given


def command_values(sets: list[str], **flags: Any) -> dict[str, Any]:
    """The overrides of a ``sim run`` command line: each ``--set`` as it reads it, and the
    options ``flags`` that set a key (``trials=``, ``seed=``, ``chunk=``; None: not given)."""
    out = dict(parse_override(t) for t in sets)
    out.update((k, v) for k, v in flags.items() if v is not None)
    return out


#: the characters of an override shown in a line (a network's points run to megabytes)
SHOWN = 100


def listed(overrides: list[str]) -> str:
    """``overrides`` for a line of text, each cut to :data:`SHOWN` characters."""
    return ", ".join(
        t if len(t) <= SHOWN else f"{t[: SHOWN - 30]}... ({len(t):,} characters)" for t in overrides
    )


def keys_of(overrides: list[str]) -> list[str]:
    """The keys of ``KEY=VALUE`` texts."""
    return [t.split("=", 1)[0] for t in overrides]


def without(overrides: list[str], extra: list[str]) -> list[str]:
    """``overrides`` but those of a key the ``sim run`` arguments ``extra`` set (``make
    verify --trials N --set KEY=VALUE``: its own values win; ``--trials`` picks the chunk, as
    it does in ``sim run``)."""
    mine = set()
    for flag, value in zip(extra, extra[1:]):
        if flag == "--trials":
            mine |= {"trials", "chunk"}
        elif flag == "--set":
            mine.add(value.split("=", 1)[0].strip())
    return [t for t in overrides if t.split("=", 1)[0] not in mine]


def replayable(record: Mapping[str, Any]) -> tuple[list[str], str | None]:
    """The overrides of the run record ``record`` to re-run its study file with (none for a
    record without them: an older version's, or a run of the file as written), and why they
    cannot be, or None. Each must be a ``KEY=VALUE`` text as :func:`recorded` writes it, of a
    key of the record's own config (not ``study``), each key once."""
    given = record.get("overrides")
    if given is None:
        return [], None
    config = record.get("config")
    if not isinstance(given, list) or not isinstance(config, dict):
        return [], "its overrides are not a list of KEY=VALUE texts"
    seen: set[str] = set()
    for text in given:
        why = _problem(text, config, seen)
        if why:
            shown = repr(text) if len(repr(text)) <= 80 else repr(text)[:77] + "..."
            return [], f"its override {shown} {why}"
    return list(given), None


def _problem(text: Any, config: Mapping[str, Any], seen: set[str]) -> str | None:
    """Why ``text`` is no override :func:`replayable` passes on, or None."""
    if not isinstance(text, str) or "=" not in text:
        return "is not KEY=VALUE"
    if not _utf8(text):  # a lone surrogate ("\ud800" in JSON): no argument of a command line
        return "is not a value written as a run writes it (a character that is not UTF-8 text)"
    key = text.split("=", 1)[0]
    if not _KEY.fullmatch(key) or key not in config or key in ("study", "sweep"):
        return "does not set a key of its config"
    if key in seen:
        return "sets a key given before"
    seen.add(key)
    try:
        value = parse_override(text)[1]
        same = f"{key}={toml_value(value)}" == text
    except (ConfigError, TypeError, ValueError, RecursionError):
        same = False
    return None if same else "is not a value written as a run writes it"


def _utf8(text: str) -> bool:
    """Whether ``text`` is UTF-8 text (no lone surrogate, which a run never records: its
    re-run's command line, ``"\\ud800"`` of a ``run.json`` edited by hand, was a
    UnicodeEncodeError traceback of ``make verify``)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True
