"""Whose a results directory's tables are, for :class:`sim.Results`: the study a table's
provenance names, the tables its run recorded (``run.json``), and the note ``sim show`` gives
on results made by another version of the suite's code, which the API gave none of (L37).

A table of the run rewritten without its provenance (by a tool) was left out of ``names()``
while ``table(name)`` refused it: it is listed, as the run recorded it, and ``table()`` says
it carries no provenance, in ``sim show``'s words."""

from __future__ import annotations

import sim.api_env  # noqa: F401 - the environment, before NumPy and Arrow load

# isort: split
import os
import sys
import warnings
from pathlib import Path
from typing import Any

import pyarrow as pa

from sim.api_paths import why_unread
from sim.mc.config import ConfigError
from sim.mc.file_kind import TABLES
from sim.mc.storage import read_provenance, read_record
from sim.mc.study_source import other_source
from sim.stale import other_code, remade

#: the suite's package directory: a warning points at the first line of the caller's outside it
_CODE = str(Path(__file__).resolve().parent) + "/"

__all__ = [
    "StaleResultsWarning",
    "a_run",
    "check_owner",
    "owner",
    "own_trials",
    "run_tables",
    "stale_warning",
]


class StaleResultsWarning(UserWarning):
    """Results made by another version of their study's code (``make reproduce`` re-runs),
    or another study's results copied or renamed by hand into a directory of this name."""


def owner(p: Path) -> Any:
    """The study a table's provenance (written with every table) names (None: none)."""
    try:
        prov = read_provenance(p)
    except OSError as e:  # EIO, EACCES: it was "not a table sim wrote; run the study again"
        raise ConfigError("table", f"{p} cannot be read ({why_unread(e)})") from None
    except (ValueError, pa.ArrowException):
        prov = None
    return prov.get("study") if isinstance(prov, dict) else None


def check_owner(p: Path, study: str) -> None:
    """A table is ``study``'s (:func:`owner`)."""
    who = owner(p)
    if who is None:  # sim show's words of a claims table without it
        raise ConfigError(
            "table",
            f"{p} is not a table sim wrote: it carries no provenance (schema metadata "
            "'sim.provenance': rewritten by a tool?); run the study again",
        )
    if who != study:
        whose = f"a table of {who!r}" if isinstance(who, str) else "not a table sim wrote"
        rec = read_record(p.parent)  # its run's too: the study named wrong, not a run to redo
        ran = rec.get("config") if isinstance(rec, dict) else None
        ran = ran.get("study") if isinstance(ran, dict) else None
        fix = (
            f"the directory holds its results: give study={who!r}"
            if who == ran
            else "run the study again"
        )
        raise ConfigError("table", f"{p} is {whose}, not of {study!r}; {fix}")


def run_tables(d: Path, study: str) -> set[str]:
    """The table files the run of ``study`` in ``d`` recorded in its ``run.json`` (none: no
    record, or another study's), and ``trials`` where it recorded chunks (the committed
    results hold none: ``table("trials")`` said the study "has no table 'trials'"). A sweep's
    cell (``cells/<label>``, no record of its own) has those its sweep's record lists under
    ``cells/<label>/`` (a copy beside them, ``claims_old.parquet``, was listed and read
    unchecked there, where a run's own is refused)."""
    rec, under = read_record(d), ""
    if rec is None and (cell := Path(os.path.realpath(d))).parent.name == "cells":
        rec, under = read_record(cell.parent.parent), f"cells/{cell.name}/"
    config = rec.get("config") if isinstance(rec, dict) else None
    tables = rec.get("table_sha256") if isinstance(config, dict) else None
    if not isinstance(config, dict) or config.get("study") != study or not isinstance(tables, dict):
        return set()
    sums = rec.get("chunk_sha256")  # a sweep's records none of its cells' chunks
    chunks = {"trials"} if not under and isinstance(sums, dict) and sums else set()
    names = (n.removeprefix(under) for n in tables if isinstance(n, str) and n.startswith(under))
    return {n for n in names if "/" not in n} | chunks


def a_run(d: Path) -> bool:
    """Whether ``d`` is a study run's results directory (it holds a claims or sweep table),
    whose ``run.json`` every version of the suite wrote: without one, deleted by hand. Tables
    written by ``sim.write_table`` alone, or ``make bench``'s ``results/bench``, have none:
    read as before (they were refused as "run.json is missing (deleted by hand?)")."""
    return any(os.path.lexists(Path(d) / name) for name in TABLES)


def own_trials(d: Path, study: str) -> bool:
    """Whether the run of ``study`` in ``d`` wrote a table ``trials.parquet``: there, or
    recorded by its run and removed since (``table("trials")`` took the name for the chunk
    dataset and said "the committed results/ hold no chunks" of wolf_polynomial's)."""
    return (d / "trials.parquet").exists() or "trials.parquet" in run_tables(d, study)


def stale_warning(d: Path) -> None:
    """Warn (:class:`StaleResultsWarning`, once per place in the caller's code) when ``d``
    was made by another version of its study's code, or holds another study's results than
    its name says (copied or renamed by hand: :func:`sim.mc.study_source.other_source`), in
    ``sim show``'s words."""
    words = [other_source(d)]  # (None: it is the study its name says)
    if older := other_code(d):
        words.insert(
            0,
            f"{older} was made by another version of the suite's code (its study's code "
            f"changed since): {remade(d)}",
        )
    level, f = 2, sys._getframe(1)  # the caller's line, not one of the suite's
    while f is not None and f.f_code.co_filename.startswith(_CODE):
        level, f = level + 1, f.f_back
    for w in filter(None, words):
        warnings.warn(w, StaleResultsWarning, stacklevel=level)
