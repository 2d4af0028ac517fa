"""Results made by another version of the suite's code: a run record (``run.json``) whose
``code_hash`` is not its study's code hash now. ``sim show`` and ``sim report`` say so in a
note, and so does the Python API's :class:`sim.Results` (a warning) when it reads a table.
So they do of results copied or renamed by hand from another study's directory
(:func:`other_dirs`, :func:`sim.mc.study_source.other_source`)."""

from __future__ import annotations

from pathlib import Path

from sim.mc.codehash import study_code_hash
from sim.mc.outputs import results_dirs
from sim.mc.registry import MODULES
from sim.mc.storage import read_record
from sim.mc.study_source import other_source
from sim.places import base

__all__ = ["other_code", "other_dirs", "remade", "stale_dirs"]

#: how the project's stale results are made again
REPRODUCE = "make reproduce re-runs what is stale"


def remade(d: Path) -> str:
    """How stale results ``d`` are made current: ``make reproduce`` re-runs the project's
    ``results/`` only; of results elsewhere (a colleague's unpacked, a scratch run) the note
    sent their reader to a command that never touches them."""
    try:
        ours = Path(d).resolve().is_relative_to((base() / "results").resolve())
    except (OSError, RuntimeError, ValueError):  # a loop, a name too long: not ours
        ours = False
    if ours:
        return REPRODUCE
    return "sim run STUDY.toml --out DIR --overwrite makes them current (not make reproduce)"


def other_code(d: Path) -> str | None:
    """The first results directory at or under ``d`` whose run record names a study whose
    code has changed since (its ``code_hash`` is not this suite's), or None."""
    return next(iter(stale_dirs(d, first=True)), None)


def stale_dirs(d: Path, first: bool = False) -> list[str]:
    """The results directories at or under ``d`` made by another version of their study's
    code (``first``: stop at the first)."""
    found: list[str] = []
    for r in [d, *results_dirs(d)] if d.is_dir() else []:
        rec = read_record(r)
        config = rec.get("config") if rec else None  # a run.json edited into another
        study = config.get("study") if isinstance(config, dict) else None  # shape: not ours
        study = study if isinstance(study, str) else None
        try:
            # a study this version lacks (a newer version's results) is not "changed since"
            if study in MODULES and rec["code_hash"] != study_code_hash(study):
                found.append(str(r))
        except (KeyError, ValueError, OSError, ImportError):  # not ours either: no note
            continue
        if found and first:
            break
    return found


def other_dirs(d: Path) -> list[str]:
    """Why each results directory at or under ``d`` holds another study's results than its
    name says (:func:`sim.mc.study_source.other_source`), one line each."""
    found = []
    for r in [d, *results_dirs(d)] if d.is_dir() else []:
        if (why := other_source(r)) is not None:
            found.append(why)
    return found
